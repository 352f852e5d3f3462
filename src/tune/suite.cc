#include "frenetic/tune/suite.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "frenetic/commonroad/setup.h"

namespace frenetic::tune {
namespace {

namespace fs = std::filesystem;

double Clamp01(double x) { return std::clamp(std::isfinite(x) ? x : 0.0, 0.0, 1.0); }

// Walks the YAML tree and records the first error with the file and the dotted key. yaml-cpp
// throws on bad conversions; they are caught here, at the edge, and become a message.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  void Fail(const std::string& key, const std::string& what) {
    if (status_.ok()) status_ = Status::Error(source_ + ": '" + key + "' " + what);
  }

  // Every key of `node` (a map) must be in `known`.
  void CheckKeys(const YAML::Node& node, const std::string& prefix,
                 std::initializer_list<const char*> known) {
    if (!node.IsMap()) return Fail(prefix.empty() ? "<document>" : prefix, "must be a map");
    for (const auto& kv : node) {
      const std::string k = kv.first.Scalar();
      if (std::none_of(known.begin(), known.end(), [&](const char* n) { return k == n; })) {
        return Fail(prefix.empty() ? k : prefix + "." + k, "is an unknown key");
      }
    }
  }

  template <typename T>
  void Scalar(const YAML::Node& node, const std::string& key, T* out) {
    if (!ok() || !node) return;
    try {
      if (!node.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
      *out = node.as<T>();
      if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(*out)) throw YAML::Exception(YAML::Mark(), "not finite");
      }
    } catch (const YAML::Exception&) {
      Fail(key, "has a value of the wrong type");
    }
  }

  template <typename T>
  void List(const YAML::Node& node, const std::string& key, std::vector<T>* out) {
    if (!ok() || !node) return;
    if (!node.IsSequence()) return Fail(key, "must be a list");
    out->clear();
    for (std::size_t i = 0; i < node.size(); ++i) {
      T v{};
      Scalar(node[i], key + "[" + std::to_string(i) + "]", &v);
      out->push_back(v);
    }
  }

 private:
  std::string source_;
  Status status_;
};

std::string Resolve(const std::string& path, const std::string& base_dir) {
  if (path.empty() || base_dir.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(base_dir) / path).lexically_normal().string();
}

// A scenario is a bundled name unless it looks like a path.
bool IsScenarioName(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

}  // namespace

double TunedParam::FromUnit(double x) const {
  x = Clamp01(x);
  if (log_scale) return std::clamp(lo * std::pow(hi / lo, x), lo, hi);
  return std::clamp(lo + x * (hi - lo), lo, hi);
}

double TunedParam::ToUnit(double value) const {
  value = std::clamp(value, lo, hi);
  if (hi <= lo) return 0;
  if (log_scale) return Clamp01(std::log(value / lo) / std::log(hi / lo));
  return Clamp01((value - lo) / (hi - lo));
}

namespace {

// The keys of each kind of suite, and those both have.
constexpr std::initializer_list<const char*> kUdacityKeys = {
    "map",           "planner",         "scenarios",     "train_seeds",
    "holdout_seeds", "episode_seconds", "deterministic", "latency"};
constexpr std::initializer_list<const char*> kCommonRoadKeys = {
    "commonroad", "holdout", "prediction", "vehicle", "commonroad_config"};

bool IsOneOf(const std::string& key, std::initializer_list<const char*> keys) {
  return std::any_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; });
}

// A path or a list of paths, each resolved against base_dir.
void PathList(Reader& r, const YAML::Node& node, const std::string& key,
              const std::string& base_dir, std::vector<std::string>* out) {
  if (!r.ok() || !node) return;
  if (node.IsScalar()) {
    std::string one;
    r.Scalar(node, key, &one);
    out->assign(1, one);
  } else if (node.IsSequence()) {
    r.List(node, key, out);
  } else {
    return r.Fail(key, "must be a path or a list of paths");
  }
  for (std::string& p : *out) {
    if (p.empty()) return r.Fail(key, "has an empty path");
    p = Resolve(p, base_dir);
  }
}

// The keys both kinds of suite have: start_config, start_set, params, search.
void ParseCommon(Reader& r, const YAML::Node& root, const std::string& base_dir, Suite* suite) {
  r.Scalar(root["start_config"], "start_config", &suite->start_config);
  suite->start_config = Resolve(suite->start_config, base_dir);

  if (const YAML::Node set = root["start_set"]; set && r.ok()) {
    if (!set.IsMap()) {
      r.Fail("start_set", "must be a map of planner keys to values");
    } else {
      for (const auto& kv : set) {
        const std::string key = kv.first.Scalar();
        double v = 0;
        r.Scalar(kv.second, "start_set." + key, &v);
        suite->start_set.emplace_back(key, v);
      }
    }
  }

  if (const YAML::Node params = root["params"]; params && r.ok()) {
    if (!params.IsMap()) {
      r.Fail("params", "must be a map of planner keys to {lo, hi, scale}");
    } else {
      for (const auto& kv : params) {
        TunedParam p;
        p.key = kv.first.Scalar();
        const std::string prefix = "params." + p.key;
        r.CheckKeys(kv.second, prefix, {"lo", "hi", "scale"});
        if (!r.ok()) break;
        if (!kv.second["lo"] || !kv.second["hi"]) {
          r.Fail(prefix, "needs lo and hi");
          break;
        }
        r.Scalar(kv.second["lo"], prefix + ".lo", &p.lo);
        r.Scalar(kv.second["hi"], prefix + ".hi", &p.hi);
        std::string scale = "linear";
        r.Scalar(kv.second["scale"], prefix + ".scale", &scale);
        if (scale != "linear" && scale != "log") r.Fail(prefix + ".scale", "must be linear or log");
        p.log_scale = scale == "log";
        if (r.ok() && !(p.lo < p.hi)) r.Fail(prefix, "needs lo < hi");
        if (r.ok() && p.log_scale && p.lo <= 0) r.Fail(prefix, "on a log scale needs lo > 0");
        suite->params.push_back(p);
      }
    }
  }

  if (const YAML::Node s = root["search"]; s && r.ok()) {
    r.CheckKeys(s, "search",
                {"global", "local", "budget", "global_fraction", "initial_step", "seed"});
    SearchOptions& o = suite->search;
    r.Scalar(s["global"], "search.global", &o.global_algorithm);
    r.Scalar(s["local"], "search.local", &o.local_algorithm);
    r.Scalar(s["budget"], "search.budget", &o.budget);
    r.Scalar(s["global_fraction"], "search.global_fraction", &o.global_fraction);
    r.Scalar(s["initial_step"], "search.initial_step", &o.initial_step);
    r.Scalar(s["seed"], "search.seed", &o.seed);
  }
}

void ParseUdacity(Reader& r, const YAML::Node& root, const std::string& base_dir, Suite* suite) {
  r.Scalar(root["map"], "map", &suite->map_path);
  suite->map_path = Resolve(suite->map_path, base_dir);
  r.Scalar(root["planner"], "planner", &suite->planner);
  r.List(root["scenarios"], "scenarios", &suite->scenarios);
  for (std::string& s : suite->scenarios) {
    if (!IsScenarioName(s)) s = Resolve(s, base_dir);
  }
  r.List(root["train_seeds"], "train_seeds", &suite->train_seeds);
  r.List(root["holdout_seeds"], "holdout_seeds", &suite->holdout_seeds);
  r.Scalar(root["episode_seconds"], "episode_seconds", &suite->episode_seconds);
  r.Scalar(root["deterministic"], "deterministic", &suite->deterministic);
  r.Scalar(root["latency"], "latency", &suite->latency);
  if (r.ok() && !suite->latency.empty() && suite->latency != "lockstep" &&
      suite->latency != "fixed" && suite->latency != "random") {
    r.Fail("latency", "must be lockstep, fixed or random, not '" + suite->latency + "'");
  }

  if (const YAML::Node obj = root["objective"]; obj && r.ok()) {
    r.CheckKeys(obj, "objective",
                {"incidents_per_mile", "speed", "speed_target_mph", "comfort", "headway",
                 "headway_target_s"});
    if (const YAML::Node inc = obj["incidents_per_mile"]; inc && r.ok()) {
      r.CheckKeys(inc, "objective.incidents_per_mile",
                  {"collision", "speed", "acceleration", "jerk", "lane", "off_road"});
      for (int k = 0; k < sim::kIncidentKinds && r.ok(); ++k) {
        const char* name = sim::ToString(static_cast<sim::IncidentKind>(k));
        r.Scalar(inc[name], std::string("objective.incidents_per_mile.") + name,
                 &suite->objective.incidents_per_mile[k]);
      }
    }
    ObjectiveWeights& o = suite->objective;
    r.Scalar(obj["speed"], "objective.speed", &o.speed);
    r.Scalar(obj["speed_target_mph"], "objective.speed_target_mph", &o.speed_target_mph);
    r.Scalar(obj["comfort"], "objective.comfort", &o.comfort);
    r.Scalar(obj["headway"], "objective.headway", &o.headway);
    r.Scalar(obj["headway_target_s"], "objective.headway_target_s", &o.headway_target_s);
    if (r.ok()) {
      bool negative = o.speed < 0 || o.comfort < 0 || o.headway < 0;
      for (double w : o.incidents_per_mile) negative = negative || w < 0;
      if (negative) r.Fail("objective", "weights must be >= 0");
    }
  }
}

void ParseCommonRoad(Reader& r, const YAML::Node& root, const std::string& base_dir, Suite* suite) {
  CommonRoadSuite& c = suite->commonroad;
  PathList(r, root["commonroad"], "commonroad", base_dir, &c.train);
  PathList(r, root["holdout"], "holdout", base_dir, &c.holdout);
  r.Scalar(root["prediction"], "prediction", &c.prediction);
  if (r.ok() && c.prediction != "recorded" && c.prediction != "constant-velocity") {
    r.Fail("prediction", "must be recorded or constant-velocity, not '" + c.prediction + "'");
  }
  r.Scalar(root["vehicle"], "vehicle", &c.vehicle);
  if (r.ok() && (c.vehicle < 1 || c.vehicle > 3)) r.Fail("vehicle", "must be 1, 2 or 3");
  r.Scalar(root["commonroad_config"], "commonroad_config", &c.overlay);
  c.overlay = Resolve(c.overlay, base_dir);
  if (const YAML::Node obj = root["objective"]; obj && r.ok()) {
    r.CheckKeys(obj, "objective", {"cost", "cost_scale"});
    r.Scalar(obj["cost"], "objective.cost", &c.cost_function);
    if (r.ok() && c.cost_function != "WX1" && c.cost_function != "JB1") {
      r.Fail("objective.cost", "must be WX1 or JB1, not '" + c.cost_function + "'");
    }
    r.Scalar(obj["cost_scale"], "objective.cost_scale", &c.cost_scale);
    if (r.ok() && !(c.cost_scale > 0)) r.Fail("objective.cost_scale", "must be > 0");
  }
}

}  // namespace

StatusOr<Suite> ParseSuite(std::string_view yaml_text, std::string_view source,
                           const std::string& base_dir) {
  Suite suite;
  suite.source = std::string(source);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::Exception& e) {
    return Status::Error(suite.source + ": YAML error at line " + std::to_string(e.mark.line + 1) +
                         ": " + e.msg);
  }
  Reader r(suite.source);
  r.CheckKeys(root, "",
              {"map", "planner", "scenarios", "train_seeds", "holdout_seeds", "episode_seconds",
               "start_config", "start_set", "params", "objective", "search", "deterministic",
               "latency", "commonroad", "holdout", "prediction", "vehicle", "commonroad_config"});
  if (!r.ok()) return r.status();
  // The kind: a CommonRoad suite names its scenario files under `commonroad`; the other kind's
  // keys are errors, named with what they belong to.
  suite.kind = root["commonroad"] ? SuiteKind::kCommonRoad : SuiteKind::kUdacity;
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    if (suite.kind == SuiteKind::kCommonRoad && IsOneOf(key, kUdacityKeys)) {
      r.Fail(key, "does not apply to a CommonRoad suite (one with 'commonroad')");
    } else if (suite.kind == SuiteKind::kUdacity && IsOneOf(key, kCommonRoadKeys)) {
      r.Fail(key, "applies to a CommonRoad suite only (one with 'commonroad')");
    }
  }
  if (!r.ok()) return r.status();

  if (suite.kind == SuiteKind::kCommonRoad) {
    ParseCommonRoad(r, root, base_dir, &suite);
  } else {
    ParseUdacity(r, root, base_dir, &suite);
  }
  ParseCommon(r, root, base_dir, &suite);
  if (!r.ok()) return r.status();

  auto err = [&](const std::string& m) { return Status::Error(suite.source + ": " + m); };
  if (suite.kind == SuiteKind::kUdacity) {
    if (suite.scenarios.empty()) return err("'scenarios' must name at least one scenario");
    if (suite.train_seeds.empty()) return err("'train_seeds' must list at least one seed");
    if (suite.holdout_seeds.empty()) return err("'holdout_seeds' must list at least one seed");
    for (std::uint64_t s : suite.holdout_seeds) {
      if (std::find(suite.train_seeds.begin(), suite.train_seeds.end(), s) !=
          suite.train_seeds.end()) {
        return err("'holdout_seeds' must not repeat training seed " + std::to_string(s));
      }
    }
    if (!(suite.episode_seconds > 0)) return err("'episode_seconds' must be > 0");
  }
  if (suite.params.empty()) return err("'params' must name at least one parameter");
  std::set<std::string> seen;
  for (const TunedParam& p : suite.params) {
    if (!seen.insert(p.key).second) return err("'params." + p.key + "' is listed twice");
  }
  const SearchOptions& so = suite.search;
  if (so.budget < 2) return err("'search.budget' must be >= 2");
  if (!(so.global_fraction >= 0 && so.global_fraction <= 1)) {
    return err("'search.global_fraction' must be in [0, 1]");
  }
  if (!(so.initial_step > 0 && so.initial_step <= 1)) {
    return err("'search.initial_step' must be in (0, 1]");
  }
  if (so.global_algorithm.rfind("GN_", 0) != 0) {
    return err("'search.global' must be a global derivative-free NLopt algorithm (GN_*), not '" +
               so.global_algorithm + "'");
  }
  if (so.local_algorithm.rfind("LN_", 0) != 0) {
    return err("'search.local' must be a local derivative-free NLopt algorithm (LN_*), not '" +
               so.local_algorithm + "'");
  }
  return suite;
}

StatusOr<Suite> LoadSuite(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open the suite file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseSuite(ss.str(), path, fs::path(path).parent_path().string());
}

StatusOr<plan::PlannerConfig> LoadStartConfig(const Suite& suite) {
  auto config = suite.kind == SuiteKind::kCommonRoad
                    ? commonroad::LoadBaseConfig(suite.start_config, suite.commonroad.overlay)
                : suite.start_config.empty() ? plan::PlannerConfig::LoadDefault()
                                             : plan::PlannerConfig::Load(suite.start_config);
  if (!config.ok()) return Status::Error(suite.source + ": start config: " + config.message());
  for (const auto& [key, value] : suite.start_set) {
    if (Status s = config->Set(key, value); !s.ok()) {
      return Status::Error(suite.source + ": 'start_set." + key + "': " + s.message());
    }
  }
  const std::vector<plan::PlannerConfig::Param> declared = config->Params();
  for (const TunedParam& p : suite.params) {
    auto it = std::find_if(declared.begin(), declared.end(),
                           [&](const auto& d) { return d.key == p.key; });
    if (it == declared.end()) {
      return Status::Error(suite.source + ": 'params." + p.key +
                           "' is not a planner parameter (see PlannerConfig::Params)");
    }
    if (p.lo < it->lo || p.hi > it->hi) {
      std::ostringstream os;
      os << suite.source << ": 'params." << p.key << "' bounds [" << p.lo << ", " << p.hi
         << "] leave the declared range [" << it->lo << ", " << it->hi << "]";
      return Status::Error(os.str());
    }
  }
  return config;
}

}  // namespace frenetic::tune

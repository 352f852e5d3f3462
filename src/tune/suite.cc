#include "frenetic/tune/suite.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "frenetic/commonroad/setup.h"
#include "frenetic/yaml/strict_reader.h"

namespace frenetic::tune {
namespace {

namespace fs = std::filesystem;

double Clamp01(double x) { return std::clamp(std::isfinite(x) ? x : 0.0, 0.0, 1.0); }

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
void PathList(yaml::MapReader& r, const char* key, const std::string& base_dir,
              std::vector<std::string>* out) {
  const YAML::Node node = r.Child(key);
  if (!r.ok() || !node.IsDefined()) return;
  if (node.IsScalar()) {
    std::string one;
    r.Read(key, &one);
    out->assign(1, one);
  } else if (node.IsSequence()) {
    r.ReadList(key, out);
  } else {
    return r.Fail(key, "must be a path or a list of paths");
  }
  for (std::string& p : *out) {
    if (p.empty()) return r.Fail(key, "has an empty path");
    p = Resolve(p, base_dir);
  }
}

// The keys both kinds of suite have: start_config, start_set, params, search.
void ParseCommon(yaml::MapReader& r, const std::string& base_dir, Suite* suite) {
  r.Read("start_config", &suite->start_config);
  suite->start_config = Resolve(suite->start_config, base_dir);

  yaml::MapReader set = r.Sub("start_set");  // planner keys to values
  for (const std::string& key : set.Keys()) {
    double v = 0;
    if (set.Read(key, &v)) suite->start_set.emplace_back(key, v);
  }

  yaml::MapReader params = r.Sub("params");  // planner keys to {lo, hi, scale}
  for (const std::string& key : params.Keys()) {
    if (!r.ok()) break;
    TunedParam p;
    p.key = key;
    yaml::MapReader one = params.Sub(key);
    const bool bounded = one.Has("lo") && one.Has("hi");
    one.Read("lo", &p.lo);
    one.Read("hi", &p.hi);
    std::string scale = "linear";
    one.Read("scale", &scale);
    one.Finish();
    const std::string name = params.Name(key);
    if (r.ok() && !bounded) r.Fail(name, "needs lo and hi");
    if (r.ok() && scale != "linear" && scale != "log")
      r.Fail(name + ".scale", "must be linear or log");
    p.log_scale = scale == "log";
    if (r.ok() && !(p.lo < p.hi)) r.Fail(name, "needs lo < hi");
    if (r.ok() && p.log_scale && p.lo <= 0) r.Fail(name, "on a log scale needs lo > 0");
    suite->params.push_back(p);
  }

  yaml::MapReader s = r.Sub("search");
  SearchOptions& o = suite->search;
  s.Read("global", &o.global_algorithm);
  s.Read("local", &o.local_algorithm);
  s.Read("budget", &o.budget);
  s.Read("global_fraction", &o.global_fraction);
  s.Read("initial_step", &o.initial_step);
  s.Read("seed", &o.seed);
  s.Finish();
}

void ParseUdacity(yaml::MapReader& r, const std::string& base_dir, Suite* suite) {
  r.Read("map", &suite->map_path);
  suite->map_path = Resolve(suite->map_path, base_dir);
  r.Read("planner", &suite->planner);
  r.ReadList("scenarios", &suite->scenarios);
  for (std::string& s : suite->scenarios) {
    if (!IsScenarioName(s)) s = Resolve(s, base_dir);
  }
  r.ReadList("train_seeds", &suite->train_seeds);
  r.ReadList("holdout_seeds", &suite->holdout_seeds);
  r.Read("episode_seconds", &suite->episode_seconds);
  r.Read("deterministic", &suite->deterministic);
  r.Read("latency", &suite->latency);
  if (r.ok() && !suite->latency.empty() && suite->latency != "lockstep" &&
      suite->latency != "fixed" && suite->latency != "random") {
    r.Fail("latency", "must be lockstep, fixed or random, not '" + suite->latency + "'");
  }

  ObjectiveWeights& o = suite->objective;
  yaml::MapReader obj = r.Sub("objective");
  yaml::MapReader inc = obj.Sub("incidents_per_mile");
  for (int k = 0; k < sim::kIncidentKinds; ++k) {
    inc.Read(sim::ToString(static_cast<sim::IncidentKind>(k)), &o.incidents_per_mile[k]);
  }
  inc.Finish();
  obj.Read("speed", &o.speed);
  obj.Read("speed_target_mph", &o.speed_target_mph);
  obj.Read("comfort", &o.comfort);
  obj.Read("headway", &o.headway);
  obj.Read("headway_target_s", &o.headway_target_s);
  obj.Finish();
  if (r.ok()) {
    bool negative = o.speed < 0 || o.comfort < 0 || o.headway < 0;
    for (double w : o.incidents_per_mile) negative = negative || w < 0;
    if (negative) r.Fail("objective", "weights must be >= 0");
  }
}

void ParseCommonRoad(yaml::MapReader& r, const std::string& base_dir, Suite* suite) {
  CommonRoadSuite& c = suite->commonroad;
  PathList(r, "commonroad", base_dir, &c.train);
  PathList(r, "holdout", base_dir, &c.holdout);
  r.Read("prediction", &c.prediction);
  if (r.ok() && c.prediction != "recorded" && c.prediction != "constant-velocity") {
    r.Fail("prediction", "must be recorded or constant-velocity, not '" + c.prediction + "'");
  }
  r.Read("vehicle", &c.vehicle);
  if (r.ok() && (c.vehicle < 1 || c.vehicle > 3)) r.Fail("vehicle", "must be 1, 2 or 3");
  r.Read("commonroad_config", &c.overlay);
  c.overlay = Resolve(c.overlay, base_dir);
  yaml::MapReader obj = r.Sub("objective");
  obj.Read("cost", &c.cost_function);
  if (r.ok() && c.cost_function != "WX1" && c.cost_function != "JB1") {
    r.Fail("objective.cost", "must be WX1 or JB1, not '" + c.cost_function + "'");
  }
  obj.Read("cost_scale", &c.cost_scale);
  if (r.ok() && !(c.cost_scale > 0)) r.Fail("objective.cost_scale", "must be > 0");
  obj.Finish();
}

}  // namespace

StatusOr<Suite> ParseSuite(std::string_view yaml_text, std::string_view source,
                           const std::string& base_dir) {
  Suite suite;
  suite.source = std::string(source);
  auto root = yaml::Load(yaml_text, suite.source);
  if (!root.ok()) return root.status();
  yaml::MapReader r(*root, suite.source);
  // The kind: a CommonRoad suite names its scenario files under `commonroad`; the other kind's
  // keys are errors, named with what they belong to.
  suite.kind = r.Has("commonroad") ? SuiteKind::kCommonRoad : SuiteKind::kUdacity;
  for (const std::string& key : r.Keys()) {
    if (suite.kind == SuiteKind::kCommonRoad && IsOneOf(key, kUdacityKeys)) {
      r.Fail(key, "does not apply to a CommonRoad suite (one with 'commonroad')");
    } else if (suite.kind == SuiteKind::kUdacity && IsOneOf(key, kCommonRoadKeys)) {
      r.Fail(key, "applies to a CommonRoad suite only (one with 'commonroad')");
    }
  }
  if (suite.kind == SuiteKind::kCommonRoad) {
    ParseCommonRoad(r, base_dir, &suite);
  } else {
    ParseUdacity(r, base_dir, &suite);
  }
  ParseCommon(r, base_dir, &suite);
  r.Finish();
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

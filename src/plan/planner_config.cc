#include "frenetic/plan/planner_config.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

#include "frenetic/check.h"
#include "frenetic/cost/cost_registry.h"
#include "frenetic/yaml/strict_reader.h"

namespace frenetic::plan {
namespace {

struct Default {
  const char* key;
  double value, lo, hi;
  bool log_scale;
};

// Every numeric planner parameter with its default and its valid / tunable range.
constexpr Default kDefaults[] = {
    {"budget_ms", 15, 1, 200, true},
    {"limits.max_speed_mph", 49.5, 5, 115, false},
    {"limits.max_accel", 9, 1, 9.9, false},
    {"limits.max_jerk", 9, 1, 9.9, false},
    {"limits.d_min", 1.0, 0.8, 4, false},
    {"limits.d_max", 11.0, 8, 11.2, false},
    {"limits.edge_margin", 0.2, 0, 1, false},
    {"limits.backward_speed", 0, 0, 1, false},
    {"road.lane_width", 4, 2.5, 5, false},
    {"road.num_lanes", 3, 1, 8, false},
    {"road.outer_lane_inset", 0.2, 0, 1, false},
    {"continuity.keep_points", 6, 1, 40, false},
    {"continuity.output_points", 100, 50, 300, false},
    {"continuity.resync_tolerance", 0.5, 0.01, 5, true},
    {"continuity.replan_min_ticks", 4, 1, 20, false},
    {"continuity.replan_deviation", 0.5, 0.05, 5, true},
    {"grid.speeds", 16, 8, 64, false},
    {"grid.lane_limit_speeds", 1, 0, 1, false},
    {"grid.durations", 6, 4, 16, false},
    {"grid.min_duration", 1.5, 1, 6, false},
    {"grid.max_duration", 6, 1.5, 8, false},
    {"grid.follow_gaps", 3, 1, 8, false},
    {"grid.gap_targets", 0, 0, 8, false},
    {"grid.follow_d0", 8, 2, 30, false},
    {"grid.follow_tau", 1.0, 0.3, 3, false},
    {"grid.follow_tau_step", 0.5, 0.1, 2, false},
    {"grid.stop", 1, 0, 1, false},
    {"grid.brake_decels", 3, 0, 8, false},
    {"grid.brake_targets", 3, 1, 8, false},
    {"grid.brake_min_decel", 3, 0.5, 9.5, false},
    {"grid.brake_max_decel", 8, 0.5, 9.5, false},
    {"grid.accels", 0, 0, 8, false},
    {"grid.min_accel", 4, 0.5, 9.5, false},
    {"grid.max_accel", 8, 0.5, 9.5, false},
    {"grid.lat_durations", 3, 1, 8, false},
    {"grid.lat_min_duration", 2.0, 1, 6, false},
    {"grid.lat_max_duration", 4.0, 1, 8, false},
    {"grid.lat_offsets", 1, 1, 7, false},
    {"grid.lat_offset_step", 0.3, 0.05, 1, false},
    {"grid.escape_lat_offsets", 0, 0, 7, false},
    {"grid.escape_lat_offset_step", 1.0, 0.05, 2, false},
    {"grid.escape_lat_duration", 0, 0, 6, false},
    {"grid.escape_lat_least_harm", 0, 0, 1, false},
    {"grid.limit_ramps", 0, 0, 1, false},
    {"grid.lane_reach", 2.5, 1, 4, false},
    {"grid.lat_delays", 2, 0, 4, false},
    {"grid.lat_delay_step", 1.5, 0.5, 3, false},
    {"grid.passes", 1, 0, 1, false},
    {"score.dt", 0.25, 0.1, 0.5, false},
    {"score.horizon", 6, 3, 8, false},
    {"check.horizon", 5, 2, 8, false},
    {"check.collision_dt", 0.1, 0.02, 0.25, false},
    {"check.car_length", 4.8, 3, 7, false},
    {"check.car_width", 2.4, 1.5, 3.5, false},
    {"check.ego_length", 4.8, 3, 7, false},
    {"check.ego_width", 2.4, 1.5, 3.5, false},
    {"check.margin_s", 1.0, 0, 5, false},
    {"check.margin_d", 0.3, 0, 2, false},
    {"check.margin_behind", 8, 0, 30, false},
    {"check.headway_min", 0.5, 0, 2, false},
    {"check.behind_time", 1.0, 0, 4, false},
    {"check.clear_enough", 0, 0, 20, false},
    {"check.side_clear", 0, 0, 5, false},
    {"check.keep_side", 0.3, 0, 2, false},
    {"check.last_resort_ticks", 145, 0, 149, false},
    {"check.keep_lane", 0, 0, 3, false},
    {"check.curve_prefilter", 0, 0, 1, false},
    {"vehicle.wheelbase", 0, 0, 10, false},
    {"vehicle.max_steer", 0, 0, 1.5, false},
    {"vehicle.max_steer_rate", 0, 0, 5, false},
    {"vehicle.max_accel", 0, 0, 20, false},
    {"vehicle.switch_speed", 0, 0, 50, false},
    {"prediction.range", 200, 50, 400, false},
    {"prediction.d_min", -1, -5, 0, false},
    {"prediction.d_max", 13, 12, 20, false},
    {"prediction.max_speed", 30, 20, 150, false},
    {"prediction.spike_ratio", 1.8, 1.2, 3, false},
    {"prediction.manoeuvres", 1, 0, 1, false},
    {"prediction.brake_threshold", 2, 0.5, 9, false},
    {"prediction.brake_horizon", 2, 0, 6, false},
    {"prediction.lateral_threshold", 0.7, 0.2, 3, false},
    {"prediction.lane_change_ghosts", 1, 0, 1, false},
    {"prediction.follow_gap", 0, 0, 40, false},
    {"prediction.followers_react", 1, 0, 1, false},
    {"prediction.merge_time", 3, 0, 8, false},
    {"refine.enabled", 1, 0, 1, false},
    {"refine.max_iterations", 40, 1, 500, true},
    {"refine.budget_ms", 3, 0.1, 50, true},
    {"fallback.decel", 3, 0.5, 8, false},
    {"fallback.jerk", 4, 1, 9, false},
    {"fallback.lat_duration", 3, 1, 6, false},
    {"baseline.follow_distance", 30, 10, 80, false},
    {"baseline.ahead_free", 50, 10, 150, false},
    {"baseline.behind_free", 15, 5, 60, false},
    {"baseline.speed_step_mph", 0.224, 0.05, 1, false},
    {"baseline.max_speed_mph", 49.5, 20, 49.95, false},
    {"baseline.path_points", 50, 50, 200, false},
};

std::string Fmt(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

}  // namespace

PlannerConfig PlannerConfig::Defaults() {
  PlannerConfig c;
  for (const Default& d : kDefaults) c.params_.push_back({d.key, d.value, d.lo, d.hi, d.log_scale});
  for (const std::string& name : cost::CostRegistry::Global().Names()) {
    c.cost_order_.push_back(name);
    c.params_.push_back({"weights." + name, 1.0, 0.0, 100.0, false});
    auto term = cost::CostRegistry::Global().Make(name);
    FRENETIC_CHECK(term.ok());
    for (const auto& spec : term.value()->ParamSpecs()) {
      c.params_.push_back({"costs." + name + "." + spec.key, spec.default_value, spec.lo, spec.hi,
                           spec.log_scale});
    }
  }
  return c;
}

void PlannerConfig::PinDeadlines() {
  budget_pinned_ = true;
  refine_budget_pinned_ = true;
}

PlannerConfig::Param* PlannerConfig::Find(std::string_view key) {
  for (Param& p : params_) {
    if (p.key == key) return &p;
  }
  return nullptr;
}
const PlannerConfig::Param* PlannerConfig::Find(std::string_view key) const {
  for (const Param& p : params_) {
    if (p.key == key) return &p;
  }
  return nullptr;
}

Status PlannerConfig::Set(std::string_view key, double value) {
  Param* p = Find(key);
  if (p == nullptr) return Status::Error(source_ + ": unknown key '" + std::string(key) + "'");
  if (!std::isfinite(value) || value < p->lo || value > p->hi) {
    return Status::Error(source_ + ": '" + std::string(key) + "' = " + Fmt(value) + " outside [" +
                         Fmt(p->lo) + ", " + Fmt(p->hi) + "]");
  }
  const double old = p->value;
  p->value = value;
  Status s = Validate();
  if (!s.ok()) {
    p->value = old;
  } else if (key == "budget_ms") {
    budget_pinned_ = false;
  } else if (key == "refine.budget_ms") {
    refine_budget_pinned_ = false;
  }
  return s;
}

StatusOr<double> PlannerConfig::Get(std::string_view key) const {
  const Param* p = Find(key);
  if (p == nullptr) return Status::Error(source_ + ": unknown key '" + std::string(key) + "'");
  return p->value;
}

double PlannerConfig::value(std::string_view key) const {
  const Param* p = Find(key);
  FRENETIC_CHECK(p != nullptr);
  return p->value;
}

int PlannerConfig::int_value(std::string_view key) const {
  return static_cast<int>(std::lround(value(key)));
}

double PlannerConfig::budget_ms() const { return value("budget_ms"); }

std::vector<PlannerConfig::Param> PlannerConfig::Params() const { return params_; }

std::vector<cost::CostTermConfig> PlannerConfig::cost_terms() const {
  std::vector<cost::CostTermConfig> out;
  for (const std::string& name : cost_order_) {
    cost::CostTermConfig tc;
    tc.name = name;
    tc.weight = value("weights." + name);
    const std::string prefix = "costs." + name + ".";
    for (const Param& p : params_) {
      if (p.key.rfind(prefix, 0) == 0) tc.params.emplace_back(p.key.substr(prefix.size()), p.value);
    }
    out.push_back(std::move(tc));
  }
  return out;
}

Status PlannerConfig::Validate() const {
  auto err = [&](const std::string& m) { return Status::Error(source_ + ": " + m); };
  if (value("grid.min_duration") >= value("grid.max_duration")) {
    return err("grid.min_duration must be below grid.max_duration");
  }
  if (value("grid.lat_min_duration") > value("grid.lat_max_duration")) {
    return err("grid.lat_min_duration must not exceed grid.lat_max_duration");
  }
  if (value("limits.d_min") >= value("limits.d_max")) {
    return err("limits.d_min must be below limits.d_max");
  }
  if (int_value("continuity.keep_points") >= int_value("continuity.output_points") - 10) {
    return err("continuity.keep_points must leave room in continuity.output_points");
  }
  if (int_value("grid.lat_offsets") % 2 == 0) return err("grid.lat_offsets must be odd");
  // The last resort relaxes the checks' own lane-line limit (135 ticks, search/settings.h).
  if (const int t = int_value("check.last_resort_ticks"); t != 0 && t <= 135) {
    return err("check.last_resort_ticks must be 0 (off) or 136-149, above the checks' 135 ticks");
  }
  if (int_value("grid.escape_lat_offsets") > 0 && int_value("grid.escape_lat_offsets") % 2 == 0) {
    return err("grid.escape_lat_offsets must be odd (or 0: grid.lat_offsets)");
  }
  auto set = cost::CostSet::Build(cost_terms());
  if (!set.ok()) return err(set.message());
  return Status::Ok();
}

namespace {

// What a file laid out as planner.yaml sets, in document order.
struct Layout {
  std::vector<std::pair<std::string, double>> values;  // dotted keys, range-checked
  std::vector<std::string> terms;                      // the `costs` entries
  std::optional<std::string> refine_algorithm;
};

const PlannerConfig::Param* FindIn(const std::vector<PlannerConfig::Param>& declared,
                                   std::string_view key) {
  for (const PlannerConfig::Param& p : declared) {
    if (p.key == key) return &p;
  }
  return nullptr;
}

// Whether `name` is a section of plain keys (`weights.*` and `costs.*` are set under `costs`).
bool IsSection(const std::vector<PlannerConfig::Param>& declared, const std::string& name) {
  if (name == "weights" || name == "costs") return false;
  for (const PlannerConfig::Param& p : declared) {
    if (p.key.size() > name.size() && p.key.compare(0, name.size(), name) == 0 &&
        p.key[name.size()] == '.') {
      return true;
    }
  }
  return false;
}

// Reads the document: top-level keys (budget_ms), sections of keys, and `costs` of terms with
// their weight and parameters. A declared key is read as a number within its range; any other
// key is left unread, for Finish() to name.
void ReadLayout(yaml::MapReader& r, const std::vector<PlannerConfig::Param>& declared,
                Layout* out) {
  auto read = [&](yaml::MapReader& m, const std::string& k, const std::string& key) {
    const PlannerConfig::Param* p = FindIn(declared, key);
    if (p == nullptr) return;
    double v = 0;
    if (m.Read(k, &v, p->lo, p->hi)) out->values.emplace_back(key, v);
  };
  for (const std::string& name : r.Keys()) {
    if (!r.ok()) return;
    if (name == "costs") {
      yaml::MapReader costs = r.Sub(name);
      for (const std::string& term : costs.Keys()) {
        if (!cost::CostRegistry::Global().Contains(term)) {
          return r.Error("unknown cost term '" + term + "'");
        }
        out->terms.push_back(term);
        yaml::MapReader t = costs.Sub(term);
        for (const std::string& k : t.Keys()) {
          read(t, k, k == "weight" ? "weights." + term : "costs." + term + "." + k);
        }
        t.Finish();
      }
      costs.Finish();
    } else if (IsSection(declared, name)) {
      yaml::MapReader section = r.Sub(name);
      for (const std::string& k : section.Keys()) {
        const std::string key = name + "." + k;
        if (key == "refine.algorithm") {
          std::string algorithm;
          if (section.Read(k, &algorithm)) out->refine_algorithm = algorithm;
        } else {
          read(section, k, key);
        }
      }
      section.Finish();
    } else if (name.find('.') == std::string::npos) {
      read(r, name, name);
    }
  }
  r.Finish();
}

}  // namespace

StatusOr<PlannerConfig> PlannerConfig::Parse(std::string_view yaml, std::string_view source) {
  PlannerConfig c = Defaults();
  c.source_ = std::string(source);
  auto err = [&](const std::string& m) { return Status::Error(c.source_ + ": " + m); };
  auto root = yaml::Load(yaml, c.source_);
  if (!root.ok()) return root.status();
  yaml::MapReader r(*root, c.source_);
  Layout layout;
  ReadLayout(r, c.params_, &layout);
  if (!r.ok()) return r.status();
  if (!r.Has("costs")) return err("missing section 'costs' (every cost term needs a weight)");
  for (const auto& [key, v] : layout.values) c.Find(key)->value = v;
  if (layout.refine_algorithm) c.refine_algorithm_ = *layout.refine_algorithm;
  for (const std::string& name : layout.terms) {
    bool weighted = false;
    for (const auto& [key, v] : layout.values) weighted = weighted || key == "weights." + name;
    if (!weighted) {
      return err("cost term '" + name + "' has no weight (key 'costs." + name + ".weight')");
    }
  }
  for (const std::string& name : cost::CostRegistry::Global().Names()) {
    if (std::find(layout.terms.begin(), layout.terms.end(), name) == layout.terms.end()) {
      return err("missing weight of cost term '" + name + "' (key 'costs." + name + ".weight')");
    }
  }
  c.cost_order_ = layout.terms;
  Status s = c.Validate();
  if (!s.ok()) return s;
  return c;
}

Status PlannerConfig::Overlay(std::string_view yaml, std::string_view source) {
  const std::string src(source);
  auto root = yaml::Load(yaml, src);
  if (!root.ok()) return root.status();
  yaml::MapReader r(*root, src);
  Layout layout;
  ReadLayout(r, params_, &layout);
  if (!r.ok()) return r.status();
  // Set one by one in the file's order, on a copy, so that an error changes nothing.
  PlannerConfig next = *this;
  next.source_ = src;
  if (layout.refine_algorithm) next.refine_algorithm_ = *layout.refine_algorithm;
  for (const auto& [key, v] : layout.values) {
    if (Status st = next.Set(key, v); !st.ok()) return st;
  }
  next.source_ = source_;
  *this = std::move(next);
  return Status::Ok();
}

Status PlannerConfig::OverlayFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open configuration");
  std::stringstream ss;
  ss << in.rdbuf();
  return Overlay(ss.str(), path);
}

StatusOr<PlannerConfig> PlannerConfig::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open planner configuration");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path);
}

std::string PlannerConfig::DefaultPath() { return FRENETIC_SOURCE_DIR "/config/planner.yaml"; }

StatusOr<PlannerConfig> PlannerConfig::LoadDefault() { return Load(DefaultPath()); }

std::string PlannerConfig::ToYaml() const {
  std::ostringstream os;
  std::string section;
  for (const Param& p : params_) {
    if (p.key.rfind("weights.", 0) == 0 || p.key.rfind("costs.", 0) == 0) continue;
    const size_t dot = p.key.find('.');
    if (dot == std::string::npos) {
      os << p.key << ": " << Fmt(p.value) << "\n";
      continue;
    }
    const std::string sec = p.key.substr(0, dot);
    if (sec != section) {
      section = sec;
      os << sec << ":\n";
      if (sec == "refine") os << "  algorithm: " << refine_algorithm_ << "\n";
    }
    os << "  " << p.key.substr(dot + 1) << ": " << Fmt(p.value) << "\n";
  }
  os << "costs:\n";
  for (const auto& tc : cost_terms()) {
    os << "  " << tc.name << ":\n    weight: " << Fmt(tc.weight) << "\n";
    for (const auto& [k, v] : tc.params) os << "    " << k << ": " << Fmt(v) << "\n";
  }
  return os.str();
}

}  // namespace frenetic::plan

// A tuning suite (config/tune/*.yaml): the fixed, seeded scenario suite a weight search is scored
// on, the planner parameters to search with their bounds and scale, the starting configuration,
// the objective, and the NLopt search settings. Unknown keys are errors naming the key and file.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/plan/planner_config.h"
#include "frenetic/sim/incident_monitor.h"
#include "frenetic/status.h"

namespace frenetic::tune {

// One searched parameter: a key of plan::PlannerConfig::Params() with bounds inside the key's
// declared range. The search works on x in [0, 1]: value = lo + x (hi - lo), or on a log scale
// value = lo (hi / lo)^x (needs lo > 0).
struct TunedParam {
  std::string key;
  double lo = 0, hi = 1;
  bool log_scale = false;

  double FromUnit(double x) const;  // x is clamped to [0, 1]
  double ToUnit(double value) const;  // value is clamped to [lo, hi]
};

// The objective, lower is better, over the episodes of one evaluation:
//   J = sum_k incidents_per_mile[k] * (incidents of kind k / total miles)
//     + speed * max(0, speed_target_mph - mean episode average speed in mph)
//     + comfort * mean episode mean squared jerk (m^2/s^6)
//     + headway * mean episode max(0, headway_target_s - minimum time headway in s)
struct ObjectiveWeights {
  std::array<double, sim::kIncidentKinds> incidents_per_mile{};  // by sim::IncidentKind
  double speed = 0;
  double speed_target_mph = 50;
  double comfort = 0;
  double headway = 0;
  double headway_target_s = 1.0;
};

// The search: a global NLopt method for round(budget * global_fraction) evaluations, then a
// local one from the best point for the rest. `seed` seeds NLopt's random numbers.
struct SearchOptions {
  std::string global_algorithm = "GN_DIRECT_L";  // GN_DIRECT_L, GN_DIRECT, GN_CRS2_LM, GN_ISRES...
  std::string local_algorithm = "LN_BOBYQA";     // LN_BOBYQA, LN_NELDERMEAD, LN_SBPLX, LN_COBYLA
  int budget = 40;                               // evaluations of the search (>= 2)
  double global_fraction = 0.6;                  // in [0, 1]
  double initial_step = 0.15;                    // of the unit cube, for the local method
  std::uint64_t seed = 1;
};

// A CommonRoad suite (`commonroad:` in the file, instead of scenarios and seeds): every planning
// problem of the scenario files is run closed-loop as `frenetic commonroad` runs it
// (commonroad::RunScenario, planning times not measured), with the tuned planner keys applied on
// top of start_config (config/planner.yaml) + overlay (config/commonroad.yaml) + start_set, then
// the vehicle's limits (commonroad::CommonRoadConfig, which pins the deadlines). Objective, lower
// is better: the share of problems not solved, then the mean cost of the solved ones as a
// tie-break worth less than one problem (CommonRoadObjective in tuner.h).
struct CommonRoadSuite {
  std::vector<std::string> train;       // scenario files or directories of them (*.xml)
  std::vector<std::string> holdout;     // likewise; empty = no held-out set
  std::string prediction = "recorded";  // or "constant-velocity"
  int vehicle = 2;                      // CommonRoad vehicle type 1, 2 or 3 (KS model)
  std::string overlay;                  // "" = config/commonroad.yaml
  std::string cost_function = "WX1";    // the tie-break's cost: WX1 or JB1
  double cost_scale = 100;              // the mean cost at which the tie-break is half a problem
};

enum class SuiteKind { kUdacity, kCommonRoad };

struct Suite {
  std::string source;       // file it was read from (named in errors)
  SuiteKind kind = SuiteKind::kUdacity;
  CommonRoadSuite commonroad;  // kCommonRoad only
  std::string map_path;     // "" = map::DefaultTrackPath()
  std::string planner = "search";
  std::vector<std::string> scenarios;  // names (config/scenarios/NAME.yaml) or file paths
  // Overrides every scenario's timing mode: "lockstep", "fixed" or "random" ("" = keep). The
  // latency modes need fewer planning cycles per simulated second (faster tuning).
  std::string latency;
  std::vector<std::uint64_t> train_seeds, holdout_seeds;
  double episode_seconds = 60;  // simulated seconds per episode
  std::string start_config;     // planner config path; "" = plan::PlannerConfig::DefaultPath()
  std::vector<std::pair<std::string, double>> start_set;  // applied on top of start_config
  std::vector<TunedParam> params;
  ObjectiveWeights objective;
  SearchOptions search;
  // Make every episode independent of wall-clock time while evaluating: the planner's deadlines
  // (budget_ms, refine.budget_ms) are switched off (PlannerConfig::PinDeadlines), unless the
  // suite tunes those keys; the refinement runs its iteration budget. Then an evaluation does
  // not depend on machine load, threads or ranks, and a resumed run retraces the logged one.
  // The tuned config keeps the start config's values of these keys.
  bool deterministic = true;
};

// Parses suite YAML. Relative paths (start_config, map, scenario files, commonroad, holdout,
// commonroad_config) are resolved against `base_dir` ("" = as given). Errors name `source` and
// the key. A CommonRoad suite rejects the Udacity suite's keys (map, planner, scenarios, seeds,
// episode_seconds, latency, deterministic) and takes objective.cost and objective.cost_scale only.
StatusOr<Suite> ParseSuite(std::string_view yaml_text, std::string_view source,
                           const std::string& base_dir);
// Reads a suite file; relative paths inside resolve against the file's directory.
StatusOr<Suite> LoadSuite(const std::string& path);

// The start configuration of `suite` (start_config, on a CommonRoad suite with the overlay on top,
// plus start_set), with every tuned key checked
// against its declared parameters: unknown keys and bounds outside the declared range are errors
// naming the key and the suite file.
StatusOr<plan::PlannerConfig> LoadStartConfig(const Suite& suite);

}  // namespace frenetic::tune

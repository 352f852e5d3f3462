// Cost-weight tuning: an Evaluator scores a parameter vector by driving the suite's scenarios on
// a fixed seed set (common random numbers: every evaluation drives the same seeds), spread over
// threads and MPI ranks; Tune() searches the normalised box [0, 1]^n with an NLopt global method
// then a local one, logs every evaluation as a JSON line, can resume from such a log, and
// compares the start configuration with the tuned one on the training and held-out seeds.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/plan/planner_config.h"
#include "frenetic/sim/incident_monitor.h"
#include "frenetic/status.h"
#include "frenetic/tune/cluster.h"
#include "frenetic/tune/suite.h"

namespace frenetic::tune {

// What one evaluation measured over its episodes (scenario-major, seeds in suite order), or on a
// CommonRoad suite over its scenario files (the Udacity fields then stay 0).
struct Metrics {
  double objective = 0;             // see ObjectiveWeights or CommonRoadObjective; lower is better
  int episodes = 0;                 // Udacity: drives; CommonRoad: scenario files
  double miles = 0;                 // total over the episodes
  std::array<double, sim::kIncidentKinds> per_mile{};  // incidents of each kind / total miles
  double incidents_per_100_miles = 0;  // all kinds
  double avg_speed_mph = 0;         // mean over episodes
  double mean_squared_jerk = 0;     // m^2/s^6, mean over episodes (comfort)
  double min_headway_s = 0;         // mean over the episodes that had a car ahead (0 if none)
  double headway_deficit_s = 0;     // mean over episodes of max(0, target - min headway)
  // CommonRoad suites: planning problems, how many the verdict solved, and the mean cost
  // (CommonRoadSuite::cost_function) of the solved ones (0 when none is).
  int problems = 0, solved = 0;
  double mean_cost = 0;
  // Finite numbers only; with problems > 0 the CommonRoad fields (objective, episodes,
  // problems, solved, mean_cost) and no others.
  nlohmann::json ToJson() const;
  static StatusOr<Metrics> FromJson(const nlohmann::json& j);
};

// The objective of a CommonRoad suite, lower is better: the share of problems not solved, then
// the mean cost c of the solved ones as a tie-break worth less than one problem,
//   J = (problems - solved + c / (c + cost_scale)) / problems,
// so that one more solved problem always wins over any cost. 0 problems give 0.
double CommonRoadObjective(int problems, int solved, double mean_cost, double cost_scale);

// The training or the held-out part of a suite: seeds (Udacity), scenario files (CommonRoad).
enum class SeedSet { kTrain, kHoldout };

// Scores parameter vectors. Every rank of `cluster` builds one (same suite); rank 0 calls
// Evaluate() and finally Stop(), the other ranks call Serve(), which returns after Stop().
class Evaluator {
 public:
  // Loads the map, scenarios and start configuration (on a CommonRoad suite, reads every
  // scenario file: an unreadable one is an error naming it). `jobs` threads per rank (0 = all
  // cores).
  static StatusOr<std::unique_ptr<Evaluator>> Create(const Suite& suite, int jobs,
                                                     const Cluster& cluster);
  ~Evaluator();

  // The start configuration (start_config plus start_set) and its tuned-parameter values.
  const plan::PlannerConfig& start_config() const;
  std::vector<double> start_values() const;
  // The start configuration with `values` (one per suite parameter, in suite order) set.
  StatusOr<plan::PlannerConfig> ConfigFor(std::span<const double> values) const;

  // Rank 0: drives every (scenario, seed) episode of `set` with the start configuration plus
  // `values`, on all ranks and threads, and scores them. The result does not depend on the
  // number of ranks or threads. Fails on bad values or a failed episode.
  StatusOr<Metrics> Evaluate(std::span<const double> values, SeedSet set);
  // Ranks > 0: evaluates this rank's share of each evaluation until rank 0 calls Stop().
  Status Serve();
  // Rank 0: releases the other ranks from Serve() (no-op on one process; idempotent).
  void Stop();

  // Episodes (Udacity) or scenario files (CommonRoad) of a set; 0 for a CommonRoad suite
  // without a held-out set.
  int episodes(SeedSet set) const;

 private:
  struct Impl;
  explicit Evaluator(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct Progress {
  int done = 0;        // search evaluations so far (including ones answered from the log)
  int budget = 0;
  int replayed = 0;    // of `done`, answered from the resume log
  double best = 0;     // best objective so far
  double elapsed_s = 0;
  double remaining_s = 0;  // estimate from the pace of evaluations actually run
};

struct TuneOptions {
  int budget = 0;            // search evaluations; 0 = the suite's search.budget
  std::string log_path;      // JSON-lines log of every evaluation ("" = none)
  std::string resume_path;   // a previous run's log whose evaluations are replayed ("" = none)
  std::function<void(const Progress&)> progress;  // after every evaluation; may be empty
};

struct TunedValue {
  std::string key;
  double start = 0, tuned = 0;
};

struct TuneResult {
  std::vector<TunedValue> params;  // suite order
  std::vector<double> best_x;      // the best point in [0, 1]^n
  int evaluations = 0;             // search evaluations (budget)
  int replayed = 0;                // of them, answered from the resume log
  int best_evaluation = -1;        // index of the best search evaluation (0: the start's)
  // No search point beat the start configuration on the training set: the tuned values are the
  // start's (best_x its point in the box, tuned_train its metrics).
  bool start_kept = false;
  Metrics start_train, tuned_train, start_holdout, tuned_holdout;
  bool has_holdout = true;         // false: a CommonRoad suite without `holdout` (not evaluated)
  bool commonroad = false;         // the metrics are a CommonRoad suite's
  std::string cost_function;       // CommonRoad: the tie-break's cost (WX1, JB1)
  std::string tuned_yaml;          // PlannerConfig::ToYaml of the tuned configuration
  nlohmann::json ToJson() const;
  std::string ToTable() const;  // default vs tuned, training and held-out seeds (or files)
};

// Runs the search on rank 0 of the evaluator's cluster (stops the workers when done). The log
// has one object per line: {"i", "phase" ("search" | "start_train" | ...), "x", "params",
// "objective", "components"}. With resume_path, logged points are answered from the log (the
// search is deterministic, so it retraces the logged path) and the new log is rewritten in
// order; resume_path may equal log_path. A truncated last line is ignored.
StatusOr<TuneResult> Tune(const Suite& suite, const TuneOptions& options, Evaluator& evaluator);

}  // namespace frenetic::tune

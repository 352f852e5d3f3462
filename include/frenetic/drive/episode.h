// One drive: the exchange loop with the latency rules of udacity-sim.md §2, one exchange at a
// time (telemetry out, path in), so that an in-process planner and a network client run the
// same loop and get the same outcome; RunEpisode / RunEpisodes drive a plan::Planner through it.
// The record writer, the incident judge and the oracle look on as observers
// (episode_observer.h); RunOptions / EpisodesOptions turn them on.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/drive/drive_report.h"
#include "frenetic/drive/episode_observer.h"
#include "frenetic/eval/incident_judge.h"
#include "frenetic/eval/oracle.h"
#include "frenetic/plan/planner.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/status.h"

namespace frenetic::sim {

// When a drive ends: the first of distance (laps or miles; m driven), simulated time, or a
// stall (the ego moved less than 1 m in `stall_seconds`). 0 disables a limit; at least one of
// laps, miles, seconds must be > 0.
struct EpisodeLimits {
  double laps = 1;
  double miles = 0;
  double seconds = 0;
  double stall_seconds = 60;
  Status Validate() const;
};

class RecordWriter;  // drive/record.h

class Episode {
 public:
  Episode(std::unique_ptr<Simulator> sim, const EpisodeLimits& limits);
  ~Episode();

  // Attaches `observer` (not owned; it must outlive the episode) and calls its OnStart. Attach
  // before the first Submit; observers are called in the order attached.
  void Attach(EpisodeObserver* observer);

  // The telemetry to send now (valid until Submit).
  const plan::Telemetry& telemetry() const { return telemetry_; }
  // The reply to telemetry(): l_old ticks on the old path, the new path applied, l_new ticks,
  // new telemetry. A rejected path (non-finite, unequal lengths) is reported and skipped, as
  // the simulator would ignore it, and the ticks still run. `reply` tells the observers how the
  // path was made (EpisodeObserver::OnExchange).
  Status Submit(std::span<const double> x, std::span<const double> y,
                const ExchangeReply& reply = {});
  // The drive is over (or given up): every observer's OnEnd in turn adds to `report` (MakeReport's)
  // and may fail; all are called, the first failure is returned.
  Status Finish(DriveReport* report);

  bool done() const { return !stop_reason_.empty(); }
  const std::string& stop_reason() const { return stop_reason_; }  // "distance", "time", "stall"
  int exchanges() const { return exchanges_; }
  int last_l_old() const { return last_l_old_; }
  int last_l_new() const { return last_l_new_; }
  double target_distance() const { return target_distance_; }  // m, +inf without one
  Simulator& sim() { return *sim_; }
  const Simulator& sim() const { return *sim_; }

 private:
  void CheckDone();
  void Advance(int ticks);

  std::unique_ptr<Simulator> sim_;
  EpisodeLimits limits_;
  double target_distance_;
  std::mt19937_64 latency_rng_;
  plan::Telemetry telemetry_;
  std::string stop_reason_;
  int exchanges_ = 0, last_l_old_ = 0, last_l_new_ = 0;
  double stall_ref_distance_ = 0, stall_ref_time_ = 0;
  std::vector<EpisodeObserver*> observers_;
  std::vector<EpisodeObserver*> tick_observers_;  // those that want every tick
};

// The report of an episode driven so far; `plan_ms` are the per-exchange planning (or round-trip)
// times and `fallbacks` the exchanges whose plan status was not ok. What the observers add comes
// from Episode::Finish.
DriveReport MakeReport(const Episode& episode, std::string_view planner,
                       const std::vector<double>& plan_ms, int fallbacks);

// What looks on at RunEpisode's drive, attached in this order (so the record's footer has the
// judgements and the oracle): judge, oracle, record, progress.
struct RunOptions {
  RecordWriter* record = nullptr;  // one line per exchange when set
  bool timing = true;   // false: planning times are recorded and reported as 0 (byte-stable)
  int trace_candidates = 20;  // candidates per cycle in the record
  nlohmann::json planner_config;  // written into the record's header (object or text)
  // Called after every exchange (e.g. a progress line); may be empty.
  std::function<void(const Episode&)> progress;
  // Judge every incident (JudgeObserver, evaluators.h); unset: off.
  std::optional<JudgeOptions> judge;
  // After the drive, search how far any planner could have driven against its traffic
  // (OracleObserver, evaluators.h; DriveReport::oracle); unset: off. It never changes the drive.
  std::optional<OracleOptions> oracle;
  // s: > 0 hands the planner every car's future that long with each telemetry (Foresee,
  // foresee.h), as CommonRoad's recorded predictions are: what the planner drives with perfect
  // predictions (a diagnostic; it changes the drive). 0: off.
  double foresee = 0;
};

// Drives `planner` (Reset first) through one episode. The planner sees every telemetry number
// as a planner behind the wire would (wire::TelemetryAsReceived: float32, 7 significant digits,
// mph and degrees on the way) and its path reaches the simulator as over the wire
// (wire::ControlAsReceived: 10 digits, cut before a non-finite point), so the drive equals the
// same seed driven through `frenetic serve` + `frenetic drive --connect`. Fails only if the
// simulator cannot be built or the record cannot be written.
StatusOr<DriveReport> RunEpisode(std::shared_ptr<const World> world, const Scenario& scenario,
                                 std::uint64_t seed, const EpisodeLimits& limits,
                                 plan::Planner& planner, const RunOptions& options);

using PlannerFactory = std::function<StatusOr<std::unique_ptr<plan::Planner>>()>;

// How far RunEpisodes has got.
struct EpisodesProgress {
  int done = 0, total = 0;        // episodes finished, episodes asked for
  double miles = 0;               // driven by the finished episodes
  int incidents = 0;              // of the finished episodes
  double running_miles = 0;       // driven so far by the episodes still running
  bool episode_finished = false;  // this call follows the end of an episode
};

struct EpisodesOptions {
  bool timing = true;                 // RunOptions::timing
  std::optional<JudgeOptions> judge;  // RunOptions::judge
  std::optional<OracleOptions> oracle;  // RunOptions::oracle
  double foresee = 0;                   // RunOptions::foresee
  // Called after every finished episode and every 256 exchanges of a running one, one call at a
  // time (from the worker threads, under a lock); may be empty. It cannot change the results.
  std::function<void(const EpisodesProgress&)> progress;
};

// Runs `episodes` episodes with seeds first_seed, first_seed + 1, ... on `jobs` threads (0 =
// hardware concurrency), each with its own simulator and planner. Results are in seed order and
// do not depend on `jobs`. Fails with the first failing episode's message.
StatusOr<AggregateReport> RunEpisodes(std::shared_ptr<const World> world, const Scenario& scenario,
                                      std::uint64_t first_seed, int episodes, int jobs,
                                      const EpisodeLimits& limits, const PlannerFactory& factory,
                                      const EpisodesOptions& options);
StatusOr<AggregateReport> RunEpisodes(std::shared_ptr<const World> world,
                                      const Scenario& scenario, std::uint64_t first_seed,
                                      int episodes, int jobs, const EpisodeLimits& limits,
                                      const PlannerFactory& factory, bool timing = true);

}  // namespace frenetic::sim

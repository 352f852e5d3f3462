#include "frenetic/drive/episode.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#include "frenetic/cores.h"
#include "frenetic/drive/evaluators.h"
#include "frenetic/drive/foresee.h"
#include "frenetic/drive/record.h"
#include "frenetic/percentile.h"
#include "frenetic/units.h"
#include "frenetic/wire/precision.h"

namespace frenetic::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// RunOptions::progress as an observer: after every exchange.
class ProgressObserver final : public EpisodeObserver {
 public:
  explicit ProgressObserver(const std::function<void(const Episode&)>& progress)
      : progress_(progress) {}
  void OnExchange(const Episode& episode, const Exchange& /*exchange*/) override {
    progress_(episode);
  }

 private:
  const std::function<void(const Episode&)>& progress_;
};

}  // namespace

DriveReport MakeReport(const Episode& ep, std::string_view planner,
                       const std::vector<double>& plan_ms, int fallbacks) {
  const Simulator& sim = ep.sim();
  const IncidentMonitor& m = sim.monitor();
  DriveReport r;
  r.scenario = sim.scenario().name;
  r.planner = std::string(planner);
  r.map = sim.world().map_path;
  r.stop_reason = ep.stop_reason();
  r.seed = sim.seed();
  r.distance_m = m.distance();
  r.sim_seconds = sim.time();
  r.exchanges = ep.exchanges();
  r.avg_speed_mph = r.sim_seconds > 0 ? r.distance_m / r.sim_seconds * units::kSimMpsToMph : 0;
  r.miles_to_first_incident = m.distance_to_first_incident() / units::kMetersPerMile;
  r.best_miles_without_incident = m.best_miles();
  r.incidents_by_kind = m.counts();
  r.incidents = m.total();
  r.max_speed_mph = m.max_speed() * units::kSimMpsToMph;
  r.max_acc = m.max_acc();
  r.max_jerk = m.max_abs_jerk();
  r.mean_squared_jerk = m.jerk_samples() > 0 ? m.sum_sq_jerk() / m.jerk_samples() : 0;
  r.lane_changes = sim.lane_changes();
  r.min_gap_m = sim.min_gap();
  r.min_headway_s = sim.min_headway();
  r.plan_ms_p50 = Percentile(plan_ms, 0.5);
  r.plan_ms_p99 = Percentile(plan_ms, 0.99);
  r.plan_ms_max = plan_ms.empty() ? 0 : *std::max_element(plan_ms.begin(), plan_ms.end());
  r.plan_fallbacks = fallbacks;
  r.incident_log = m.log();
  r.laps = sim.breakdown().laps();
  r.breakdown = sim.breakdown().Total();
  return r;
}

Status EpisodeLimits::Validate() const {
  if (!(laps >= 0) || !(miles >= 0) || !(seconds >= 0) || !(stall_seconds >= 0) ||
      !std::isfinite(laps + miles + seconds + stall_seconds)) {
    return Status::Error("drive limits must be finite and >= 0");
  }
  if (laps <= 0 && miles <= 0 && seconds <= 0) {
    return Status::Error("drive limits: one of laps, miles, seconds must be > 0");
  }
  return Status::Ok();
}

Episode::Episode(std::unique_ptr<Simulator> sim, const EpisodeLimits& limits)
    : sim_(std::move(sim)),
      limits_(limits),
      target_distance_(kInf),
      // A stream of its own, so the latency draws do not shift the traffic's random numbers.
      latency_rng_(sim_->seed() ^ 0x9E3779B97F4A7C15ULL) {
  if (limits_.laps > 0) target_distance_ = limits_.laps * sim_->world().track.max_s;
  if (limits_.miles > 0)
    target_distance_ = std::min(target_distance_, limits_.miles * units::kMetersPerMile);
  telemetry_.previous_path_x.reserve(256);
  telemetry_.previous_path_y.reserve(256);
  sim_->GetTelemetry(&telemetry_);
}

Episode::~Episode() = default;

void Episode::Attach(EpisodeObserver* observer) {
  observers_.push_back(observer);
  if (observer->wants_ticks()) tick_observers_.push_back(observer);
  observer->OnStart(*this);
}

Status Episode::Finish(DriveReport* report) {
  Status first = Status::Ok();
  for (EpisodeObserver* o : observers_) {
    if (Status s = o->OnEnd(*this, report); !s.ok() && first.ok()) first = s;
  }
  return first;
}

void Episode::Advance(int ticks) {
  // Tick by tick only for an observer that asks (the judge): the same ticks either way.
  if (tick_observers_.empty()) {
    sim_->Advance(ticks);
    return;
  }
  for (int i = 0; i < ticks; ++i) {
    sim_->Advance(1);
    for (EpisodeObserver* o : tick_observers_) o->OnTick(*sim_);
  }
}

Status Episode::Submit(std::span<const double> x, std::span<const double> y,
                       const ExchangeReply& reply) {
  const Exchange exchange{exchanges_, sim_->time(), sim_->monitor().log().size(), &reply};
  const TimingOptions& t = sim_->scenario().timing;
  int l_old = 0, l_new = 1;
  auto draw = [&](int lo, int hi) {
    return lo + static_cast<int>(latency_rng_() % static_cast<std::uint64_t>(hi - lo + 1));
  };
  switch (t.mode) {
    case TimingOptions::Mode::kLockstep: break;
    case TimingOptions::Mode::kFixed:
      l_old = t.l_old;
      l_new = t.l_new;
      break;
    case TimingOptions::Mode::kRandom:
      l_old = draw(t.l_old_min, t.l_old_max);
      l_new = draw(t.l_new_min, t.l_new_max);
      break;
  }
  last_l_old_ = l_old;
  last_l_new_ = l_new;
  Advance(l_old);
  Status status = sim_->ApplyPath(x, y);
  Advance(l_new);
  ++exchanges_;
  CheckDone();
  sim_->GetTelemetry(&telemetry_);
  for (EpisodeObserver* o : observers_) o->OnExchange(*this, exchange);
  return status;
}

void Episode::CheckDone() {
  const double dist = sim_->monitor().distance();
  const double time = sim_->time();
  if (dist >= target_distance_) {
    stop_reason_ = "distance";
  } else if (limits_.seconds > 0 && time >= limits_.seconds - 1e-9) {
    stop_reason_ = "time";
  } else if (dist - stall_ref_distance_ >= 1.0) {
    stall_ref_distance_ = dist;
    stall_ref_time_ = time;
  } else if (limits_.stall_seconds > 0 && time - stall_ref_time_ >= limits_.stall_seconds) {
    stop_reason_ = "stall";
  }
}

StatusOr<DriveReport> RunEpisode(std::shared_ptr<const World> world, const Scenario& scenario,
                                 std::uint64_t seed, const EpisodeLimits& limits,
                                 plan::Planner& planner, const RunOptions& options) {
  if (Status s = limits.Validate(); !s.ok()) return s;
  if (options.judge) {
    if (Status s = options.judge->Validate(); !s.ok()) return s;
  }
  if (options.oracle) {
    if (Status s = options.oracle->Validate(); !s.ok()) return s;
  }
  auto sim = Simulator::Create(std::move(world), scenario, seed);
  if (!sim.ok()) return sim.status();
  Episode ep(std::move(*sim), limits);
  // The observers, in RunOptions' order: the record's footer has what the others add.
  std::optional<JudgeObserver> judge;
  std::optional<OracleObserver> oracle;
  if (options.judge) ep.Attach(&judge.emplace(*options.judge, options.timing));
  if (options.oracle) ep.Attach(&oracle.emplace(*options.oracle));
  planner.Reset();
  plan::CycleTrace trace;
  RecordWriter* record = options.record;
  if (record != nullptr) {
    record->set_timing(options.timing);
    planner.set_trace(&trace, options.trace_candidates);
    record->set_planner(std::string(planner.name()), options.planner_config);
    ep.Attach(record);
  }
  ProgressObserver progress(options.progress);
  if (options.progress) ep.Attach(&progress);
  std::vector<double> plan_ms;
  plan_ms.reserve(20000);
  int fallbacks = 0, bad_paths = 0;
  // The planner gets the telemetry as it arrives over the wire and the simulator the path as it
  // arrives back (wire/precision.h: float32 printed with 7 digits out, 10 digits back, a path
  // cut before its first unwritable point), so that this drive and the same seed through
  // `frenetic serve` + `drive --connect` are the same drive.
  plan::Telemetry received;
  received.previous_path_x.reserve(256);
  received.previous_path_y.reserve(256);
  std::vector<double> path_x, path_y;
  path_x.reserve(256);
  path_y.reserve(256);
  while (!ep.done()) {
    wire::TelemetryAsReceived(ep.telemetry(), &received);
    if (options.foresee > 0) Foresee(ep.sim(), options.foresee, &received.futures);
    trace.candidates.clear();
    const auto t0 = std::chrono::steady_clock::now();
    const plan::PlanResult& result = planner.Plan(received);
    const double ms =
        options.timing
            ? std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count()
            : 0.0;
    plan_ms.push_back(ms);
    if (result.status != plan::PlanStatus::kOk) ++fallbacks;
    wire::ControlAsReceived(result.x, result.y, &path_x, &path_y);
    if ((path_x.size() != result.x.size() || path_x.size() != result.y.size()) &&
        bad_paths++ == 0) {
      spdlog::warn("the planner returned {} x and {} y values; {} finite points sent, as frenetic "
                   "serve would (warned once)",
                   result.x.size(), result.y.size(), path_x.size());
    }
    ExchangeReply reply;
    reply.plan = &result;  // the record keeps the path as planned
    reply.trace = &trace;
    reply.ms = ms;
    (void)ep.Submit(path_x, path_y, reply);  // the wire's path is always one the simulator accepts
  }
  if (record != nullptr) planner.set_trace(nullptr, 0);
  DriveReport report = MakeReport(ep, planner.name(), plan_ms, fallbacks);
  if (Status s = ep.Finish(&report); !s.ok()) return s;
  return report;
}

StatusOr<AggregateReport> RunEpisodes(std::shared_ptr<const World> world, const Scenario& scenario,
                                      std::uint64_t first_seed, int episodes, int jobs,
                                      const EpisodeLimits& limits, const PlannerFactory& factory,
                                      const EpisodesOptions& options) {
  if (episodes < 1) return Status::Error("episodes must be >= 1");
  if (Status s = limits.Validate(); !s.ok()) return s;
  if (options.judge) {
    if (Status s = options.judge->Validate(); !s.ok()) return s;
  }
  if (options.oracle) {
    if (Status s = options.oracle->Validate(); !s.ok()) return s;
  }
  if (jobs <= 0) jobs = UsableCores();
  jobs = std::min(jobs, episodes);
  std::vector<std::optional<StatusOr<DriveReport>>> results(episodes);
  std::atomic<int> next{0};
  // Progress: the finished episodes' totals and each worker's running distance, under a lock.
  std::mutex progress_mutex;
  EpisodesProgress progress;
  progress.total = episodes;
  std::vector<double> running(jobs, 0.0);
  auto report_progress = [&](int worker, double worker_miles, const DriveReport* finished) {
    std::lock_guard<std::mutex> lock(progress_mutex);
    running[worker] = worker_miles;
    progress.episode_finished = finished != nullptr;
    if (finished != nullptr) {
      ++progress.done;
      progress.miles += finished->miles();
      progress.incidents += finished->incidents;
    }
    progress.running_miles = 0;
    for (double m : running) progress.running_miles += m;
    options.progress(progress);
  };
  auto worker = [&](int w) {
    for (int i = next++; i < episodes; i = next++) {
      auto planner = factory();
      if (!planner.ok()) {
        results[i] = planner.status();
        continue;
      }
      RunOptions run;
      run.timing = options.timing;
      run.judge = options.judge;
      run.oracle = options.oracle;
      run.foresee = options.foresee;
      if (options.progress) {
        run.progress = [&, w, exchanges = 0](const Episode& ep) mutable {
          if (++exchanges % 256 != 0) return;
          report_progress(w, ep.sim().monitor().distance() / units::kMetersPerMile, nullptr);
        };
      }
      results[i] = RunEpisode(world, scenario, first_seed + i, limits, **planner, run);
      if (options.progress && results[i]->ok()) report_progress(w, 0.0, &results[i]->value());
    }
  };
  std::vector<std::thread> pool;
  for (int j = 1; j < jobs; ++j) pool.emplace_back(worker, j);
  worker(0);
  for (auto& t : pool) t.join();
  std::vector<DriveReport> reports;
  reports.reserve(episodes);
  for (auto& r : results) {
    if (!r->ok()) return r->status();
    reports.push_back(std::move(r->value()));
  }
  return AggregateReport::From(std::move(reports));
}

StatusOr<AggregateReport> RunEpisodes(std::shared_ptr<const World> world, const Scenario& scenario,
                                      std::uint64_t first_seed, int episodes, int jobs,
                                      const EpisodeLimits& limits, const PlannerFactory& factory,
                                      bool timing) {
  EpisodesOptions options;
  options.timing = timing;
  return RunEpisodes(std::move(world), scenario, first_seed, episodes, jobs, limits, factory,
                     options);
}

}  // namespace frenetic::sim

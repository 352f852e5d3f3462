// The Evaluator: one evaluation = every (scenario, seed) episode of a seed set driven with one
// planner configuration. Episodes are dealt to ranks round-robin and, inside a rank, to threads
// from a shared counter; each episode's numbers land in its own slot of a fixed-layout buffer,
// and the objective is computed from the slots in episode order on rank 0, so the result is
// the same for any number of ranks or threads.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include "frenetic/map/track.h"
#include "frenetic/plan/planner.h"
#include "frenetic/sim/episode.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"
#include "frenetic/tune/tuner.h"

namespace frenetic::tune {
namespace {

// Per-episode slot layout in the exchanged buffer.
enum Slot : int {
  kDone,          // 1 when the episode ran
  kMiles,
  kAvgSpeedMph,
  kMeanSqJerk,
  kHasHeadway,    // 1 when a car was ever ahead in the ego lane
  kMinHeadway,    // s, 0 without a car ahead
  kIncidents,     // kIncidentKinds counts from here
  kSlots = kIncidents + sim::kIncidentKinds,
};

// Below this a drive counts as this long for incidents per mile, so that a car that barely
// moved does not divide by zero; the speed term already punishes it.
constexpr double kMinMiles = 0.01;

// The first number of a message from rank 0.
constexpr double kStop = 0, kEvaluate = 1;

}  // namespace

nlohmann::json Metrics::ToJson() const {
  nlohmann::json per = nlohmann::json::object();
  for (int k = 0; k < sim::kIncidentKinds; ++k) {
    per[sim::ToString(static_cast<sim::IncidentKind>(k))] = per_mile[k];
  }
  return {{"objective", objective},
          {"episodes", episodes},
          {"miles", miles},
          {"incidents_per_mile", per},
          {"incidents_per_100_miles", incidents_per_100_miles},
          {"avg_speed_mph", avg_speed_mph},
          {"mean_squared_jerk", mean_squared_jerk},
          {"min_headway_s", min_headway_s},
          {"headway_deficit_s", headway_deficit_s}};
}

StatusOr<Metrics> Metrics::FromJson(const nlohmann::json& j) {
  Metrics m;
  try {
    m.objective = j.at("objective").get<double>();
    m.episodes = j.at("episodes").get<int>();
    m.miles = j.at("miles").get<double>();
    for (int k = 0; k < sim::kIncidentKinds; ++k) {
      m.per_mile[k] =
          j.at("incidents_per_mile").at(sim::ToString(static_cast<sim::IncidentKind>(k)));
    }
    m.incidents_per_100_miles = j.at("incidents_per_100_miles").get<double>();
    m.avg_speed_mph = j.at("avg_speed_mph").get<double>();
    m.mean_squared_jerk = j.at("mean_squared_jerk").get<double>();
    m.min_headway_s = j.at("min_headway_s").get<double>();
    m.headway_deficit_s = j.at("headway_deficit_s").get<double>();
  } catch (const nlohmann::json::exception& e) {
    return Status::Error(std::string("bad metrics: ") + e.what());
  }
  return m;
}

struct Evaluator::Impl {
  Suite suite;
  int jobs = 1;
  const Cluster* cluster = nullptr;
  std::shared_ptr<const sim::World> world;
  std::vector<sim::Scenario> scenarios;
  plan::PlannerConfig start;
  sim::EpisodeLimits limits;
  bool stopped = false;

  const std::vector<std::uint64_t>& Seeds(SeedSet set) const {
    return set == SeedSet::kTrain ? suite.train_seeds : suite.holdout_seeds;
  }
  int Episodes(SeedSet set) const {
    return static_cast<int>(scenarios.size() * Seeds(set).size());
  }

  StatusOr<plan::PlannerConfig> ConfigFor(std::span<const double> values, bool pin) const {
    if (values.size() != suite.params.size()) {
      return Status::Error("expected " + std::to_string(suite.params.size()) +
                           " parameter values, got " + std::to_string(values.size()));
    }
    plan::PlannerConfig config = start;
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (Status s = config.Set(suite.params[i].key, values[i]); !s.ok()) return s;
    }
    if (pin) {
      // Deadlines are wall-clock: switched off, the search is never cut short and the
      // refinement runs its iterations, so an episode does not depend on load (rank and thread
      // counts included). A tuned budget keeps its tuned value.
      config.PinDeadlines();
      for (std::size_t i = 0; i < values.size(); ++i) {
        const std::string& key = suite.params[i].key;
        if (key == "budget_ms" || key == "refine.budget_ms") {
          if (Status s = config.Set(key, values[i]); !s.ok()) return s;
        }
      }
    }
    return config;
  }

  // A fresh planner per episode: an episode's outcome must not depend on which episodes the
  // same thread drove before it.
  StatusOr<sim::DriveReport> RunOne(const plan::PlannerConfig& config,
                                    const sim::Scenario& scenario, std::uint64_t seed) const {
    auto planner = plan::MakePlanner(suite.planner, config, world->line);
    if (!planner.ok()) return planner.status();
    sim::RunOptions options;
    options.timing = false;
    return sim::RunEpisode(world, scenario, seed, limits, **planner, options);
  }

  // Runs this rank's share of the episodes of `set` into `buffer` (Episodes(set) * kSlots,
  // zero elsewhere). The first failure message of this rank goes to `error`.
  void RunShare(const plan::PlannerConfig& config, SeedSet set, std::vector<double>* buffer,
                std::string* error) const {
    const std::vector<std::uint64_t>& seeds = Seeds(set);
    const int total = Episodes(set);
    buffer->assign(static_cast<std::size_t>(total) * kSlots, 0.0);
    std::vector<int> mine;
    for (int e = cluster->rank(); e < total; e += cluster->size()) mine.push_back(e);
    std::atomic<int> next{0};
    std::mutex error_mutex;
    auto worker = [&] {
      for (int i = next++; i < static_cast<int>(mine.size()); i = next++) {
        const int e = mine[i];
        const sim::Scenario& scenario = scenarios[e / seeds.size()];
        const std::uint64_t seed = seeds[e % seeds.size()];
        StatusOr<sim::DriveReport> report = RunOne(config, scenario, seed);
        if (!report.ok()) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (error->empty()) {
            *error = "scenario " + scenario.name + " seed " + std::to_string(seed) + ": " +
                     report.message();
          }
          continue;
        }
        double* slot = buffer->data() + static_cast<std::size_t>(e) * kSlots;
        slot[kDone] = 1;
        slot[kMiles] = report->miles();
        slot[kAvgSpeedMph] = report->avg_speed_mph;
        slot[kMeanSqJerk] = report->mean_squared_jerk;
        const bool has = std::isfinite(report->min_headway_s);
        slot[kHasHeadway] = has ? 1 : 0;
        slot[kMinHeadway] = has ? report->min_headway_s : 0;
        for (int k = 0; k < sim::kIncidentKinds; ++k) {
          slot[kIncidents + k] = report->incidents_by_kind[k];
        }
      }
    };
    const int threads = std::max(1, std::min<int>(jobs, static_cast<int>(mine.size())));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
  }

  Metrics Score(const std::vector<double>& buffer, int total) const {
    const ObjectiveWeights& w = suite.objective;
    Metrics m;
    m.episodes = total;
    std::array<double, sim::kIncidentKinds> incidents{};
    double speed_sum = 0, jerk_sum = 0, headway_sum = 0, deficit_sum = 0;
    int with_headway = 0;
    for (int e = 0; e < total; ++e) {
      const double* slot = buffer.data() + static_cast<std::size_t>(e) * kSlots;
      m.miles += slot[kMiles];
      speed_sum += slot[kAvgSpeedMph];
      jerk_sum += slot[kMeanSqJerk];
      if (slot[kHasHeadway] > 0) {
        ++with_headway;
        headway_sum += slot[kMinHeadway];
        deficit_sum += std::max(0.0, w.headway_target_s - slot[kMinHeadway]);
      }
      for (int k = 0; k < sim::kIncidentKinds; ++k) incidents[k] += slot[kIncidents + k];
    }
    const double miles = std::max(m.miles, kMinMiles * total);
    double all = 0;
    m.objective = 0;
    for (int k = 0; k < sim::kIncidentKinds; ++k) {
      m.per_mile[k] = incidents[k] / miles;
      all += incidents[k];
      m.objective += w.incidents_per_mile[k] * m.per_mile[k];
    }
    m.incidents_per_100_miles = 100 * all / miles;
    m.avg_speed_mph = speed_sum / total;
    m.mean_squared_jerk = jerk_sum / total;
    m.min_headway_s = with_headway > 0 ? headway_sum / with_headway : 0;
    m.headway_deficit_s = deficit_sum / total;
    m.objective += w.speed * std::max(0.0, w.speed_target_mph - m.avg_speed_mph) +
                   w.comfort * m.mean_squared_jerk + w.headway * m.headway_deficit_s;
    return m;
  }
};

Evaluator::Evaluator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Evaluator::~Evaluator() { Stop(); }

StatusOr<std::unique_ptr<Evaluator>> Evaluator::Create(const Suite& suite, int jobs,
                                                       const Cluster& cluster) {
  auto impl = std::make_unique<Impl>();
  impl->suite = suite;
  impl->cluster = &cluster;
  impl->jobs = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const std::vector<std::string> names = plan::PlannerNames();
  if (std::find(names.begin(), names.end(), suite.planner) == names.end()) {
    return Status::Error(suite.source + ": 'planner' '" + suite.planner + "' is not a planner");
  }
  auto start = LoadStartConfig(suite);
  if (!start.ok()) return start.status();
  impl->start = std::move(*start);
  const std::string map_path = suite.map_path.empty() ? map::DefaultTrackPath() : suite.map_path;
  auto world = sim::LoadWorld(map_path);
  if (!world.ok()) return Status::Error(suite.source + ": map: " + world.message());
  impl->world = std::move(*world);
  for (const std::string& name : suite.scenarios) {
    auto scenario = sim::LoadScenario(name);
    if (!scenario.ok()) {
      return Status::Error(suite.source + ": scenario '" + name + "': " + scenario.message());
    }
    if (!suite.latency.empty()) {
      auto mode = sim::ParseTimingMode(suite.latency);
      if (!mode.ok()) return Status::Error(suite.source + ": 'latency': " + mode.message());
      scenario->timing.mode = *mode;
    }
    impl->scenarios.push_back(std::move(*scenario));
  }
  impl->limits.laps = 0;
  impl->limits.miles = 0;
  impl->limits.seconds = suite.episode_seconds;
  impl->limits.stall_seconds = 0;  // a stall is scored (slow), not cut short
  if (Status s = impl->limits.Validate(); !s.ok()) return Status::Error(suite.source + ": " + s.message());
  return std::unique_ptr<Evaluator>(new Evaluator(std::move(impl)));
}

const plan::PlannerConfig& Evaluator::start_config() const { return impl_->start; }

std::vector<double> Evaluator::start_values() const {
  std::vector<double> v;
  for (const TunedParam& p : impl_->suite.params) v.push_back(impl_->start.value(p.key));
  return v;
}

StatusOr<plan::PlannerConfig> Evaluator::ConfigFor(std::span<const double> values) const {
  return impl_->ConfigFor(values, false);
}

int Evaluator::episodes(SeedSet set) const { return impl_->Episodes(set); }

StatusOr<Metrics> Evaluator::Evaluate(std::span<const double> values, SeedSet set) {
  const Cluster& cluster = *impl_->cluster;
  if (cluster.rank() != 0) return Status::Error("Evaluate runs on rank 0 only");
  if (impl_->stopped) return Status::Error("the evaluator was stopped");
  auto config = impl_->ConfigFor(values, impl_->suite.deterministic);
  if (!config.ok()) return config.status();
  if (cluster.distributed()) {
    std::vector<double> message{kEvaluate, set == SeedSet::kTrain ? 0.0 : 1.0};
    message.insert(message.end(), values.begin(), values.end());
    cluster.Broadcast(&message);
  }
  std::vector<double> buffer;
  std::string error;
  impl_->RunShare(*config, set, &buffer, &error);
  cluster.SumToRoot(&buffer);
  const int total = impl_->Episodes(set);
  if (!error.empty()) return Status::Error(error);
  for (int e = 0; e < total; ++e) {
    if (buffer[static_cast<std::size_t>(e) * kSlots + kDone] != 1) {
      const auto& seeds = impl_->Seeds(set);
      return Status::Error("scenario " + impl_->scenarios[e / seeds.size()].name + " seed " +
                           std::to_string(seeds[e % seeds.size()]) + " failed on rank " +
                           std::to_string(e % cluster.size()) + " (see its log)");
    }
  }
  return impl_->Score(buffer, total);
}

Status Evaluator::Serve() {
  const Cluster& cluster = *impl_->cluster;
  if (cluster.rank() == 0) return Status::Error("Serve runs on ranks > 0 only");
  const std::size_t n = impl_->suite.params.size();
  for (;;) {
    std::vector<double> message;
    cluster.Broadcast(&message);
    if (message.empty() || message[0] == kStop) return Status::Ok();
    const SeedSet set = message[1] == 0 ? SeedSet::kTrain : SeedSet::kHoldout;
    std::vector<double> buffer(static_cast<std::size_t>(impl_->Episodes(set)) * kSlots, 0.0);
    std::string error;
    if (message.size() != 2 + n) {
      error = "bad evaluation message from rank 0";
    } else {
      auto config = impl_->ConfigFor(std::span<const double>(message).subspan(2),
                                     impl_->suite.deterministic);
      if (config.ok()) {
        impl_->RunShare(*config, set, &buffer, &error);
      } else {
        error = config.message();
      }
    }
    // Always take part in the gather, or rank 0 would wait forever; a missing slot tells it.
    if (!error.empty()) spdlog::error("rank {}: {}", cluster.rank(), error);
    cluster.SumToRoot(&buffer);
  }
}

void Evaluator::Stop() {
  if (impl_ == nullptr || impl_->stopped) return;
  impl_->stopped = true;
  if (impl_->cluster->rank() == 0 && impl_->cluster->distributed()) {
    std::vector<double> message{kStop};
    impl_->cluster->Broadcast(&message);
  }
}

}  // namespace frenetic::tune

// The Evaluator: one evaluation = every (scenario, seed) episode of a seed set driven with one
// planner configuration, or on a CommonRoad suite every planning problem of the set's scenario
// files run closed-loop. Units of work (episodes, files) are dealt to ranks round-robin and,
// inside a rank, to threads from a shared counter; each episode's (or problem's) numbers land in
// its own slot of a fixed-layout buffer, and the objective is computed from the slots in order on
// rank 0, so the result is the same for any number of ranks or threads.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include "frenetic/commonroad/cost.h"
#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/setup.h"
#include "frenetic/commonroad/solution.h"
#include "frenetic/cores.h"
#include "frenetic/drive/episode.h"
#include "frenetic/map/track.h"
#include "frenetic/plan/planner.h"
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

// Per-problem slot layout of a CommonRoad suite.
enum CommonRoadSlot : int {
  kCrDone,     // 1 when the problem ran
  kCrSolved,   // 1 when the verdict solved it
  kCrHasCost,  // 1 when its cost was evaluated (solved problems)
  kCrCost,     // the suite's cost function
  kCrSlots,
};

// Below this a drive counts as this long for incidents per mile, so that a car that barely
// moved does not divide by zero; the speed term already punishes it.
constexpr double kMinMiles = 0.01;

// The first number of a message from rank 0.
constexpr double kStop = 0, kEvaluate = 1;

}  // namespace

nlohmann::json Metrics::ToJson() const {
  if (problems > 0) {  // a CommonRoad suite's: the drive fields mean nothing there
    return {{"objective", objective},
            {"episodes", episodes},
            {"problems", problems},
            {"solved", solved},
            {"mean_cost", mean_cost}};
  }
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

double CommonRoadObjective(int problems, int solved, double mean_cost, double cost_scale) {
  if (problems <= 0) return 0;
  const double c = std::max(0.0, mean_cost);
  const double tie = cost_scale > 0 ? c / (c + cost_scale) : 0.0;  // in [0, 1)
  return (problems - solved + tie) / problems;
}

StatusOr<Metrics> Metrics::FromJson(const nlohmann::json& j) {
  Metrics m;
  try {
    m.objective = j.at("objective").get<double>();
    m.episodes = j.at("episodes").get<int>();
    if (j.contains("problems")) {
      m.problems = j.at("problems").get<int>();
      m.solved = j.at("solved").get<int>();
      m.mean_cost = j.at("mean_cost").get<double>();
      return m;
    }
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
  plan::PlannerConfig start;
  bool stopped = false;
  // Udacity suites.
  std::shared_ptr<const sim::World> world;
  std::vector<sim::Scenario> scenarios;
  sim::EpisodeLimits limits;
  // CommonRoad suites, per set: the scenario files and the slot of each file's first problem
  // (one more entry: the set's problem count).
  struct CommonRoadSet {
    std::vector<commonroad::Scenario> files;
    std::vector<int> first_problem{0};
  };
  CommonRoadSet cr_sets[2];
  commonroad::RunOptions cr_options;
  commonroad::VehicleParams vehicle;

  bool commonroad() const { return suite.kind == SuiteKind::kCommonRoad; }
  const CommonRoadSet& CrSet(SeedSet set) const { return cr_sets[set == SeedSet::kTrain ? 0 : 1]; }

  const std::vector<std::uint64_t>& Seeds(SeedSet set) const {
    return set == SeedSet::kTrain ? suite.train_seeds : suite.holdout_seeds;
  }
  // Units of work of a set: episodes, or scenario files.
  int Episodes(SeedSet set) const {
    if (commonroad()) return static_cast<int>(CrSet(set).files.size());
    return static_cast<int>(scenarios.size() * Seeds(set).size());
  }
  std::size_t BufferSize(SeedSet set) const {
    if (commonroad()) return static_cast<std::size_t>(CrSet(set).first_problem.back()) * kCrSlots;
    return static_cast<std::size_t>(Episodes(set)) * kSlots;
  }
  // Whether unit e's slots were filled (a rank that failed leaves them 0).
  bool UnitDone(const std::vector<double>& buffer, SeedSet set, int e) const {
    if (!commonroad()) return buffer[static_cast<std::size_t>(e) * kSlots + kDone] == 1;
    const std::vector<int>& first = CrSet(set).first_problem;
    for (int i = first[e]; i < first[e + 1]; ++i) {
      if (buffer[static_cast<std::size_t>(i) * kCrSlots + kCrDone] != 1) return false;
    }
    return true;
  }
  std::string UnitName(SeedSet set, int e) const {
    if (commonroad()) return "scenario " + CrSet(set).files[e].source;
    const std::vector<std::uint64_t>& seeds = Seeds(set);
    return "scenario " + scenarios[e / seeds.size()].name + " seed " +
           std::to_string(seeds[e % seeds.size()]);
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

  // One scenario file of a CommonRoad suite, as `frenetic commonroad` runs it, into its
  // problems' slots. `config` has the vehicle applied (CommonRoadConfig).
  Status RunFile(const plan::PlannerConfig& config, SeedSet set, int e, double* slots) const {
    const commonroad::Scenario& sc = CrSet(set).files[e];
    const commonroad::ScenarioRun run = commonroad::RunScenario(sc, config, cr_options);
    if (run.problems.size() != sc.problems.size()) {
      return Status::Error("the run has " + std::to_string(run.problems.size()) +
                           " problems, the file " + std::to_string(sc.problems.size()));
    }
    for (std::size_t i = 0; i < run.problems.size(); ++i) {
      const commonroad::ProblemRun& p = run.problems[i];
      double* slot = slots + i * kCrSlots;
      slot[kCrDone] = 1;
      slot[kCrSolved] = p.verdict.solved ? 1 : 0;
      if (!p.verdict.solved) continue;
      auto cost = commonroad::EvaluateCost(suite.commonroad.cost_function, sc, sc.problems[i],
                                           vehicle, p.trajectory);
      if (!cost.ok()) {
        return Status::Error("problem " + std::to_string(p.problem_id) + ": " + cost.message());
      }
      slot[kCrHasCost] = 1;
      slot[kCrCost] = cost->total;
    }
    return Status::Ok();
  }

  // Runs this rank's share of the episodes (or files) of `set` into `buffer` (BufferSize(set),
  // zero elsewhere). The first failure message of this rank goes to `error`.
  void RunShare(const plan::PlannerConfig& config, SeedSet set, std::vector<double>* buffer,
                std::string* error) const {
    const std::vector<std::uint64_t>& seeds = Seeds(set);
    const int total = Episodes(set);
    buffer->assign(BufferSize(set), 0.0);
    std::vector<int> mine;
    for (int e = cluster->rank(); e < total; e += cluster->size()) mine.push_back(e);
    std::atomic<int> next{0};
    std::mutex error_mutex;
    auto fail = [&](int e, const std::string& message) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (error->empty()) *error = UnitName(set, e) + ": " + message;
    };
    StatusOr<plan::PlannerConfig> cr_config = config;
    if (commonroad()) {
      cr_config = commonroad::CommonRoadConfig(config, vehicle, cr_options.prediction);
      if (!cr_config.ok()) {
        *error = suite.source + ": " + cr_config.message();
        return;
      }
    }
    auto worker = [&] {
      for (int i = next++; i < static_cast<int>(mine.size()); i = next++) {
        const int e = mine[i];
        if (commonroad()) {
          double* slots =
              buffer->data() + static_cast<std::size_t>(CrSet(set).first_problem[e]) * kCrSlots;
          if (Status st = RunFile(*cr_config, set, e, slots); !st.ok()) fail(e, st.message());
          continue;
        }
        const sim::Scenario& scenario = scenarios[e / seeds.size()];
        const std::uint64_t seed = seeds[e % seeds.size()];
        StatusOr<sim::DriveReport> report = RunOne(config, scenario, seed);
        if (!report.ok()) {
          fail(e, report.message());
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

  Metrics ScoreCommonRoad(const std::vector<double>& buffer, SeedSet set) const {
    Metrics m;
    m.episodes = Episodes(set);
    m.problems = CrSet(set).first_problem.back();
    double cost_sum = 0;
    int costs = 0;
    for (int i = 0; i < m.problems; ++i) {
      const double* slot = buffer.data() + static_cast<std::size_t>(i) * kCrSlots;
      m.solved += slot[kCrSolved] > 0;
      if (slot[kCrHasCost] > 0) {
        cost_sum += slot[kCrCost];
        ++costs;
      }
    }
    m.mean_cost = costs > 0 ? cost_sum / costs : 0;
    m.objective =
        CommonRoadObjective(m.problems, m.solved, m.mean_cost, suite.commonroad.cost_scale);
    return m;
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
  impl->jobs = jobs > 0 ? jobs : UsableCores();
  if (suite.kind == SuiteKind::kCommonRoad) {
    auto start = LoadStartConfig(suite);
    if (!start.ok()) return start.status();
    impl->start = std::move(*start);
    const CommonRoadSuite& c = suite.commonroad;
    auto prediction = commonroad::ParsePredictionMode(c.prediction);
    if (!prediction.ok()) {
      return Status::Error(suite.source + ": 'prediction': " + prediction.message());
    }
    impl->cr_options.prediction = *prediction;
    impl->cr_options.vehicle_type = c.vehicle;
    impl->cr_options.timing = false;
    auto vehicle = commonroad::VehicleParamsForType(c.vehicle);
    if (!vehicle.ok()) return Status::Error(suite.source + ": 'vehicle': " + vehicle.message());
    impl->vehicle = *vehicle;
    // The evaluation configuration must build from the start one (a tuned key may be one the
    // vehicle sets: it is overridden, as the command overrides it).
    if (auto checked = commonroad::CommonRoadConfig(impl->start, impl->vehicle, *prediction);
        !checked.ok()) {
      return Status::Error(suite.source + ": " + checked.message());
    }
    const std::pair<const char*, const std::vector<std::string>*> sets[] = {
        {"commonroad", &c.train}, {"holdout", &c.holdout}};
    for (int k = 0; k < 2; ++k) {
      if (sets[k].second->empty()) continue;  // no held-out set
      auto files = commonroad::ScenarioFiles(*sets[k].second);
      if (!files.ok()) {
        return Status::Error(suite.source + ": '" + sets[k].first + "': " + files.message());
      }
      Impl::CommonRoadSet& set = impl->cr_sets[k];
      for (const std::string& f : *files) {
        // A solution file beside the scenarios (highD's recorded human) is no scenario.
        if (commonroad::PeekRootElement(f) == "CommonRoadSolution") continue;
        auto sc = commonroad::LoadScenario(f);
        if (!sc.ok()) {
          return Status::Error(suite.source + ": '" + sets[k].first + "': " + sc.message());
        }
        set.first_problem.push_back(set.first_problem.back() +
                                    static_cast<int>(sc->problems.size()));
        set.files.push_back(std::move(*sc));
      }
      if (set.first_problem.back() == 0) {
        return Status::Error(suite.source + ": '" + sets[k].first + "': no planning problem in " +
                             std::to_string(set.files.size()) + " scenario file(s)");
      }
    }
    return std::unique_ptr<Evaluator>(new Evaluator(std::move(impl)));
  }
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
  const int total = impl_->Episodes(set);
  if (total == 0) return Status::Error(impl_->suite.source + ": the set has nothing to run");
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
  if (!error.empty()) return Status::Error(error);
  for (int e = 0; e < total; ++e) {
    if (!impl_->UnitDone(buffer, set, e)) {
      return Status::Error(impl_->UnitName(set, e) + " failed on rank " +
                           std::to_string(e % cluster.size()) + " (see its log)");
    }
  }
  if (impl_->commonroad()) return impl_->ScoreCommonRoad(buffer, set);
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
    std::vector<double> buffer(impl_->BufferSize(set), 0.0);
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

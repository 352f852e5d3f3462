// The traffic runs of `frenetic fidelity`: the headless simulator driven by a planner or by a
// scripted ego that replays the recordings, with the traffic sampled from the telemetry of
// every exchange as the recordings are (eval/fidelity.h compares the two).
#include "frenetic/drive/traffic_runs.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <thread>

#include "eval/fidelity_traffic_internal.h"
#include "frenetic/drive/episode.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::sim {
namespace {

using fidelity::Interpolate;
using fidelity::LaneOf;
using fidelity::OnRoad;

using plan::kTickSeconds;  // the simulator's physics step

// A scripted ego that drives like a recorded one (EgoProfile): the recorded speed as a cap, the
// recorded lane. Cheap and independent of any planner's tuning, so the traffic comparison does
// not move when the planners change. Like the recorded planner it re-sends the start of its
// last path and extends it to kPathPoints points each exchange.
class ReplayEgo {
 public:
  ReplayEgo(const World& world, const EgoProfile& profile) : world_(world), profile_(profile) {
    // Distance the recorded ego had driven by each profile time (trapezoid rule).
    distance_.resize(profile_.t.size(), 0.0);
    for (std::size_t i = 1; i < distance_.size(); ++i) {
      distance_[i] = distance_[i - 1] + 0.5 * (profile_.speed[i] + profile_.speed[i - 1]) *
                                            (profile_.t[i] - profile_.t[i - 1]);
    }
  }

  void Plan(const plan::Telemetry& t, double time, std::vector<double>* x,
            std::vector<double>* y) {
    const auto& line = *world_.line;
    // Drop what the simulator consumed; keep a short head so that the reaction time is short.
    const std::size_t left = t.previous_path_x.size();
    while (sent_.size() > left) sent_.pop_front();
    if (sent_.size() > kKeep) sent_.resize(kKeep);
    const map::FrenetPoint ego = line.ToFrenet(t.x, t.y);
    if (has_last_) travelled_ += std::max(0.0, line.DiffS(ego.s, last_s_));
    has_last_ = true;
    last_s_ = ego.s;
    // Distance lost behind slower cars: the recorded planner made it up (it passed or sped up
    // afterwards), so the scripted ego may exceed the recorded speed, up to the recorded ego's
    // top speed, until it is back on the recorded distance. Without this it falls behind for
    // good and the traffic drifts ahead of it.
    const double deficit = Interpolate(profile_.t, distance_, time, 0.0) - travelled_;
    State st = sent_.empty() ? State{ego.s, ego.d, t.speed} : sent_.back();

    // Leader: the nearest car ahead in the lane the ego is in (reported chord s, d, as a planner
    // sees them); a reading above 30 m/s is the spawn-speed quirk (§8.6) and is capped.
    const int lane = LaneOf(st.d);
    double lead_gap = std::numeric_limits<double>::infinity(), lead_v = 0;
    const int target_lane = LaneOf(profile_.DAt(time + kLaneLookahead));
    bool target_free = true;
    for (const plan::SensorCar& c : t.sensor_fusion) {
      if (!OnRoad(c.d)) continue;
      const double ds = line.DiffS(c.s, t.s);
      if (LaneOf(c.d) == lane && ds > 0 && ds - kCarLength < lead_gap) {
        lead_gap = ds - kCarLength;
        lead_v = std::min(std::hypot(c.vx, c.vy), 30.0);
      }
      if (LaneOf(c.d) == target_lane && ds > -kChangeClearBehind && ds < kChangeClearAhead) {
        target_free = false;
      }
    }
    // Lane: the recorded one, once it is free beside the ego; else stay.
    double target_d = 2.0 + 4.0 * lane;
    if (target_lane != lane && target_free) target_d = 2.0 + 4.0 * target_lane;
    if (target_lane == lane) target_d = 2.0 + 4.0 * lane;

    const double ds_now = line.DiffS(st.s, ego.s);  // head of the path ahead of the ego
    const double tau0 = static_cast<double>(sent_.size()) * kTick;
    x->clear();
    y->clear();
    for (const State& p : sent_) {
      const map::CartesianPose pose = line.ToCartesian(p.s, p.d);
      x->push_back(pose.x);
      y->push_back(pose.y);
    }
    double travelled = ds_now;
    for (int k = 1; static_cast<int>(sent_.size()) < kPathPoints; ++k) {
      const double tau = tau0 + k * kTick;
      double v_cap = profile_.SpeedAt(time + tau);
      if (deficit > 0) {
        v_cap = std::max(v_cap, std::min(v_cap + kCatchUpGain * deficit, kCatchUpSpeed));
      }
      if (std::isfinite(lead_gap)) {
        // Time-gap law on the leader predicted at constant speed.
        const double gap = lead_gap + lead_v * tau - travelled;
        const double desired = kStandstill + kTimeGap * st.v;
        v_cap = std::min(v_cap, std::max(0.0, lead_v + kGapGain * (gap - desired)));
      }
      st.v = std::clamp(v_cap, st.v - kMaxDecel * kTick, st.v + kMaxAccel * kTick);
      st.v = std::max(0.0, st.v);
      const double step = std::clamp(target_d - st.d, -kLateralSpeed * kTick,
                                     kLateralSpeed * kTick);
      st.d += step;
      st.s = line.WrapS(st.s + st.v * kTick);
      travelled += st.v * kTick;
      sent_.push_back(st);
      const map::CartesianPose pose = line.ToCartesian(st.s, st.d);
      x->push_back(pose.x);
      y->push_back(pose.y);
    }
  }

 private:
  struct State {
    double s, d, v;  // smooth-line Frenet, m; speed m/s
  };
  static constexpr int kPathPoints = 50;
  static constexpr std::size_t kKeep = 5;
  static constexpr double kTick = 0.02;
  static constexpr double kCarLength = 4.6;
  static constexpr double kMaxAccel = 5.0, kMaxDecel = 6.0;  // m/s^2; the recorded ego
                                                            // reached 49 mph in ~7 s
  static constexpr double kStandstill = 8.0, kTimeGap = 1.2, kGapGain = 0.5;  // m, s, 1/s
  static constexpr double kLateralSpeed = 2.0;     // m/s: a lane change in ~2 s
  static constexpr double kLaneLookahead = 0.5;    // s
  static constexpr double kChangeClearBehind = 15, kChangeClearAhead = 20;  // m
  // Catch-up on lost distance: 1/s, and the recorded ego's top speed (49.4 mph), m/s.
  static constexpr double kCatchUpGain = 0.2, kCatchUpSpeed = 22.0;
  std::vector<double> distance_;  // recorded distance at profile_.t, m
  double travelled_ = 0, last_s_ = 0;
  bool has_last_ = false;
  const World& world_;
  const EgoProfile& profile_;
  std::deque<State> sent_;
};

}  // namespace

int TrafficEpisodes(const TrafficRunOptions& options) {
  const double total = options.minutes * 60.0;
  if (options.ego_profiles.empty()) {
    return std::max(1, static_cast<int>(std::ceil(total / options.episode_seconds - 1e-9)));
  }
  double covered = 0;
  int n = 0;
  const std::size_t count = options.ego_profiles.size();
  while (covered < total - 1e-9 && n < 100000) {
    const double d = options.ego_profiles[static_cast<std::size_t>(n) % count].duration();
    if (!(d > 0)) break;  // rejected by SimulateTraffic
    covered += d;
    ++n;
  }
  return std::max(1, n);
}

StatusOr<TrafficFigures> SimulateTraffic(std::shared_ptr<const World> world,
                                         const TrafficRunOptions& options,
                                         const std::string& planner_config_path) {
  if (!world) return Status::Error("fidelity: no world");
  const bool replay = !options.ego_profiles.empty();
  if (!(options.minutes > 0) || !(options.episode_seconds > 0) ||
      !std::isfinite(options.minutes + options.episode_seconds)) {
    return Status::Error("fidelity: simulated minutes and episode seconds must be > 0");
  }
  for (const EgoProfile& p : options.ego_profiles) {
    bool ok = !p.t.empty() && p.t.size() == p.speed.size() && p.t.size() == p.d.size() &&
              p.duration() > 0;
    for (std::size_t i = 1; ok && i < p.t.size(); ++i) ok = p.t[i] > p.t[i - 1];
    for (std::size_t i = 0; ok && i < p.t.size(); ++i) {
      ok = std::isfinite(p.speed[i]) && std::isfinite(p.d[i]) && p.speed[i] >= 0;
    }
    if (!ok) {
      return Status::Error("fidelity: ego profile '" + p.name +
                           "' is empty, not increasing in time or not finite");
    }
  }
  std::optional<plan::PlannerConfig> config;
  if (!replay) {
    auto loaded = planner_config_path.empty() ? plan::PlannerConfig::LoadDefault()
                                              : plan::PlannerConfig::Load(planner_config_path);
    if (!loaded.ok()) return loaded.status();
    config = std::move(*loaded);
  }
  Scenario scenario = options.scenario;
  // The recordings were made with a planner answering within a few ms while the simulator ran
  // in real time: the latency mode, with the scenario's calibrated ranges.
  scenario.timing.mode = TimingOptions::Mode::kRandom;
  if (Status s = scenario.Validate(); !s.ok()) return s;
  const int episodes = TrafficEpisodes(options);

  std::vector<std::vector<TrafficSample>> runs(episodes);
  std::vector<std::optional<Status>> errors(episodes);
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < episodes; i = next++) {
      const EgoProfile* profile =
          replay ? &options.ego_profiles[static_cast<std::size_t>(i) %
                                         options.ego_profiles.size()]
                 : nullptr;
      std::unique_ptr<plan::Planner> planner;
      std::optional<ReplayEgo> scripted;
      if (replay) {
        scripted.emplace(*world, *profile);
      } else {
        auto made = plan::MakePlanner(options.planner, *config, world->line);
        if (!made.ok()) {
          errors[i] = made.status();
          continue;
        }
        planner = std::move(*made);
        planner->Reset();
      }
      auto sim = Simulator::Create(world, scenario, options.first_seed + i);
      if (!sim.ok()) {
        errors[i] = sim.status();
        continue;
      }
      EpisodeLimits limits;
      limits.laps = 0;
      limits.seconds = replay ? profile->duration() : options.episode_seconds;
      limits.stall_seconds = 0;
      Episode ep(std::move(*sim), limits);
      std::vector<TrafficSample>& run = runs[i];
      run.reserve(static_cast<std::size_t>(limits.seconds / kTickSeconds) + 1);
      int consumed = 0;
      double time = 0;
      std::vector<double> px, py;
      while (true) {
        const plan::Telemetry& t = ep.telemetry();
        TrafficSample sample;
        sample.ego_s = t.s;
        sample.ego_speed = t.speed;
        sample.consumed = consumed;
        sample.dt = consumed * kTickSeconds;
        time += sample.dt;
        sample.cars.reserve(t.sensor_fusion.size());
        for (const plan::SensorCar& c : t.sensor_fusion) {
          sample.cars.push_back({static_cast<double>(c.id), c.x, c.y, c.vx, c.vy, c.s, c.d});
        }
        run.push_back(std::move(sample));
        if (ep.done()) break;
        // A rejected path is the driver's problem, not the traffic's: the ticks still run.
        if (replay) {
          scripted->Plan(t, time, &px, &py);
          (void)ep.Submit(px, py);
        } else {
          const plan::PlanResult& result = planner->Plan(t);
          (void)ep.Submit(result.x, result.y);
        }
        consumed = ep.last_l_old() + ep.last_l_new();
      }
    }
  };
  const int jobs = std::clamp(options.jobs, 1, episodes);
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
  worker();
  for (auto& t : threads) t.join();
  for (const auto& e : errors) {
    if (e.has_value()) return *e;
  }
  TrafficStatsBuilder builder(world->track.max_s);
  for (const auto& run : runs) builder.AddRun(run);
  spdlog::debug("fidelity: {} episodes, {} messages simulated", episodes,
                builder.figures().messages);
  if (spdlog::should_log(spdlog::level::debug)) {
    // The shape of dv/dt and speed (STATS.md has the same bins for the recordings).
    const double dv_edges[] = {-11, -9, -7, -5, -3, -1, -0.25, 0.25, 1, 2, 3, 4, 5, 7};
    const double v_edges[] = {5, 10, 12, 14, 16, 18, 20, 22, 24, 26};
    auto histogram = [](const std::vector<double>& v, std::span<const double> edges) {
      std::string out;
      for (std::size_t i = 0; i <= edges.size(); ++i) {
        const double lo = i == 0 ? -INFINITY : edges[i - 1];
        const double hi = i == edges.size() ? INFINITY : edges[i];
        const auto n = std::count_if(v.begin(), v.end(),
                                     [&](double x) { return x >= lo && x < hi; });
        out += fmt::format(" <{}:{:.1f}%", hi, v.empty() ? 0.0 : 100.0 * n / v.size());
      }
      return out;
    };
    spdlog::debug("fidelity: sim dv/dt{}", histogram(builder.figures().dvdt, dv_edges));
    spdlog::debug("fidelity: sim speed{}", histogram(builder.figures().speeds, v_edges));
  }
  return builder.figures();
}

}  // namespace frenetic::sim

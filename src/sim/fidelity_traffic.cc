// Traffic statistics of `frenetic fidelity`: the same figures from the real recordings and from
// the headless simulator, computed by one builder from per-message sensor_fusion samples (as
// shared/realdata/telemetry/STATS.md computes them), so that the comparison is like for like.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <thread>

#include "frenetic/plan/planner_config.h"
#include "frenetic/sim/episode.h"
#include "frenetic/sim/fidelity.h"
#include "frenetic/units.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::sim {
namespace {

constexpr double kTickSeconds = 0.02;
constexpr double kRespawnJump = 15;  // m off the constant-velocity prediction (STATS.md)
constexpr double kHardBrake = -7;    // m/s^2

bool OnRoad(double d) { return d >= 0 && d <= 12; }
int LaneOf(double d) { return d < 4 ? 0 : (d < 8 ? 1 : 2); }

// Linear interpolation between order statistics (numpy's default, as STATS.md).
double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(pos);
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (v[i + 1] - v[i]) * (pos - static_cast<double>(i));
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return std::nan("");
  double sum = 0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

double Share(const std::vector<double>& v, double below) {
  if (v.empty()) return std::nan("");
  const auto n = std::count_if(v.begin(), v.end(), [below](double x) { return x < below; });
  return static_cast<double>(n) / static_cast<double>(v.size());
}

double Interpolate(const std::vector<double>& t, const std::vector<double>& v, double time,
                   double empty) {
  if (t.empty() || v.size() != t.size()) return empty;
  if (time <= t.front()) return v.front();
  if (time >= t.back()) return v.back();
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
  const double span = t[i] - t[i - 1];
  const double w = span > 0 ? (time - t[i - 1]) / span : 1.0;
  return v[i - 1] + (v[i] - v[i - 1]) * w;
}

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

double EgoProfile::SpeedAt(double time) const { return Interpolate(t, speed, time, 0.0); }
double EgoProfile::DAt(double time) const { return Interpolate(t, d, time, 6.0); }

EgoProfile RecordingEgoProfile(const Recording& recording) {
  EgoProfile p;
  p.name = recording.name;
  const std::vector<TrafficSample> samples = RecordingTrafficSamples(recording);
  double time = 0;
  for (std::size_t k = 0; k < recording.messages.size(); ++k) {
    time += samples[k].dt;
    if (k > 0 && !(time > p.t.back())) continue;  // keep t increasing
    p.t.push_back(time);
    p.speed.push_back(recording.messages[k].speed_mph * units::kMphToMps);
    p.d.push_back(recording.messages[k].d);
  }
  return p;
}

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

void TrafficStatsBuilder::AddRun(std::span<const TrafficSample> run) {
  struct Last {
    bool on_road = false;
    double x = 0, y = 0, vx = 0, vy = 0, d = 0;
  };
  std::vector<Last> last;
  auto wrap = [this](double ds) {
    if (max_s_ <= 0) return ds;
    return ds - max_s_ * std::floor(ds / max_s_ + 0.5);  // into [-max_s/2, max_s/2)
  };
  for (std::size_t k = 0; k < run.size(); ++k) {
    const TrafficSample& m = run[k];
    ++f_.messages;
    f_.ego_speeds.push_back(m.ego_speed);
    if (k > 0) f_.consumed.push_back(m.consumed);
    std::vector<bool> seen(last.size(), false);
    for (const auto& row : m.cars) {
      const double id_d = row[0];
      if (!(id_d >= 0 && id_d < 1000)) continue;  // ids are small integers
      const std::size_t id = static_cast<std::size_t>(id_d);
      if (id >= last.size()) {
        last.resize(id + 1);
        seen.resize(id + 1, false);
      }
      seen[id] = true;
      Last& p = last[id];
      const double x = row[1], y = row[2], vx = row[3], vy = row[4], s = row[5], d = row[6];
      const bool on_road = OnRoad(d);
      if (on_road) {
        const double v = std::hypot(vx, vy);
        ++f_.car_samples;
        f_.car_minutes += m.dt / 60.0;
        f_.speeds.push_back(v);
        f_.rel_s.push_back(wrap(s - m.ego_s));
        bool spawn = false;
        if (k > 0 && p.on_road) {
          const double ex = p.x + p.vx * m.dt, ey = p.y + p.vy * m.dt;
          if (std::hypot(x - ex, y - ey) > kRespawnJump) {
            spawn = true;  // teleported: a re-spawn, no rate across it
          } else if (m.dt > 0) {
            f_.dvdt.push_back((v - std::hypot(p.vx, p.vy)) / m.dt);
            if (LaneOf(d) != LaneOf(p.d)) ++f_.lane_crossings;
          }
        } else {
          spawn = true;  // first on-road sample of this id, or back on the road
        }
        if (spawn) {
          const double off = wrap(s - m.ego_s);
          (off >= 0 ? f_.spawn_ahead : f_.spawn_behind).push_back(off);
        }
      }
      p.on_road = on_road;
      p.x = x;
      p.y = y;
      p.vx = vx;
      p.vy = vy;
      p.d = d;
    }
    for (std::size_t id = 0; id < last.size(); ++id) {
      if (!seen[id]) last[id].on_road = false;  // a missing row breaks the sequence
    }
  }
}

std::vector<TrafficSample> RecordingTrafficSamples(const Recording& recording) {
  std::vector<TrafficSample> out(recording.messages.size());
  wire::ParsedReply reply;
  for (std::size_t k = 0; k < recording.messages.size(); ++k) {
    const RecordedMessage& m = recording.messages[k];
    TrafficSample& t = out[k];
    t.ego_s = m.s;
    t.ego_speed = m.speed_mph * units::kMphToMps;
    t.cars = m.sensor_fusion;
    if (k == 0) continue;
    // Points consumed since the previous message: the previous reply's length minus what is
    // left of it now (the planner re-sent its unconsumed points, so the tail is the same path).
    wire::ParseReply(recording.replies[k - 1], &reply);
    const long c = static_cast<long>(reply.x.size()) - static_cast<long>(m.path_x.size());
    t.consumed = static_cast<int>(std::max(0L, c));
    t.dt = t.consumed * kTickSeconds;
  }
  return out;
}

std::vector<StatRow> CompareTraffic(const TrafficFigures& real, const TrafficFigures& sim) {
  std::vector<StatRow> rows;
  auto add = [&rows](std::string name, std::string unit, double r, double s, long rn, long sn,
                     double lo = 0.8, double hi = 1.25) {
    StatRow row;
    row.name = std::move(name);
    row.unit = std::move(unit);
    row.real = r;
    row.sim = s;
    row.real_n = rn;
    row.sim_n = sn;
    row.lo = lo;
    row.hi = hi;
    if (r == 0) {
      row.ratio = s == 0 ? 1.0 : INFINITY;
    } else {
      row.ratio = s / r;
    }
    if (!std::isfinite(row.ratio)) row.ratio = INFINITY;  // NaN (no samples) fails the band
    rows.push_back(std::move(row));
  };
  const long rn = static_cast<long>(real.speeds.size()), sn = static_cast<long>(sim.speeds.size());
  add("car speed p5", "m/s", Percentile(real.speeds, 0.05), Percentile(sim.speeds, 0.05), rn, sn);
  add("car speed median", "m/s", Percentile(real.speeds, 0.5), Percentile(sim.speeds, 0.5), rn,
      sn);
  add("car speed p95", "m/s", Percentile(real.speeds, 0.95), Percentile(sim.speeds, 0.95), rn,
      sn);
  add("hard braking (dv/dt < -7 m/s^2)", "%", 100 * Share(real.dvdt, kHardBrake),
      100 * Share(sim.dvdt, kHardBrake), static_cast<long>(real.dvdt.size()),
      static_cast<long>(sim.dvdt.size()));
  const double real_rate = real.car_minutes > 0 ? real.lane_crossings / real.car_minutes : NAN;
  const double sim_rate = sim.car_minutes > 0 ? sim.lane_crossings / sim.car_minutes : NAN;
  add("lane-line crossings per car-minute", "1/min", real_rate, sim_rate, real.lane_crossings,
      sim.lane_crossings, 0.5, 2.0);
  add("spawn offset ahead, median", "m", Percentile(real.spawn_ahead, 0.5),
      Percentile(sim.spawn_ahead, 0.5), static_cast<long>(real.spawn_ahead.size()),
      static_cast<long>(sim.spawn_ahead.size()));
  add("spawn offset behind, median", "m", Percentile(real.spawn_behind, 0.5),
      Percentile(sim.spawn_behind, 0.5), static_cast<long>(real.spawn_behind.size()),
      static_cast<long>(sim.spawn_behind.size()));
  const long rr = static_cast<long>(real.rel_s.size()), sr = static_cast<long>(sim.rel_s.size());
  add("car s - ego s, p5", "m", Percentile(real.rel_s, 0.05), Percentile(sim.rel_s, 0.05), rr, sr);
  add("car s - ego s, p95", "m", Percentile(real.rel_s, 0.95), Percentile(sim.rel_s, 0.95), rr,
      sr);
  add("points consumed per message, mean", "points", Mean(real.consumed), Mean(sim.consumed),
      static_cast<long>(real.consumed.size()), static_cast<long>(sim.consumed.size()));
  // Not traffic, but what it depends on: the ego must drive like the recorded one.
  const long er = static_cast<long>(real.ego_speeds.size());
  const long es = static_cast<long>(sim.ego_speeds.size());
  add("ego speed median", "m/s", Percentile(real.ego_speeds, 0.5),
      Percentile(sim.ego_speeds, 0.5), er, es);
  add("ego speed mean", "m/s", Mean(real.ego_speeds), Mean(sim.ego_speeds), er, es);
  add("ego speed p95", "m/s", Percentile(real.ego_speeds, 0.95),
      Percentile(sim.ego_speeds, 0.95), er, es);
  return rows;
}

CheckReport TrafficReport(std::span<const StatRow> rows) {
  CheckReport report;
  for (const StatRow& s : rows) {
    CheckRow row;
    row.check = "traffic: " + s.name + " (sim/real)";
    row.cases = 1;
    row.passed = s.ok() ? 1 : 0;
    // Deviation of the ratio from 1, in the direction that matters for the band.
    row.worst = s.ratio;
    row.tolerance = s.ratio >= 1 ? s.hi : s.lo;
    row.unit = "ratio";
    if (!s.ok()) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "sim %.3g vs real %.3g %s: ratio %.3g outside [%.2f, %.2f]",
                    s.sim, s.real, s.unit.c_str(), s.ratio, s.lo, s.hi);
      row.failures.push_back(buf);
    }
    report.rows.push_back(std::move(row));
  }
  return report;
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

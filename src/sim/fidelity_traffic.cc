// Traffic statistics of `frenetic fidelity`: the same figures from the real recordings and from
// the headless simulator, computed by one builder from per-message sensor_fusion samples (as
// shared/realdata/telemetry/STATS.md computes them), so that the comparison is like for like.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <thread>

#include "frenetic/net/protocol.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/sim/episode.h"
#include "frenetic/sim/fidelity.h"

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

}  // namespace

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
  net::ParsedReply reply;
  for (std::size_t k = 0; k < recording.messages.size(); ++k) {
    const RecordedMessage& m = recording.messages[k];
    TrafficSample& t = out[k];
    t.ego_s = m.s;
    t.cars = m.sensor_fusion;
    if (k == 0) continue;
    // Points consumed since the previous message: the previous reply's length minus what is
    // left of it now (the planner re-sent its unconsumed points, so the tail is the same path).
    net::ParseReply(recording.replies[k - 1], &reply);
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
  if (!(options.minutes > 0) || !(options.episode_seconds > 0) ||
      !std::isfinite(options.minutes + options.episode_seconds)) {
    return Status::Error("fidelity: simulated minutes and episode seconds must be > 0");
  }
  auto config = planner_config_path.empty() ? plan::PlannerConfig::LoadDefault()
                                            : plan::PlannerConfig::Load(planner_config_path);
  if (!config.ok()) return config.status();
  Scenario scenario = options.scenario;
  // The recordings were made with a planner answering within a few ms while the simulator ran
  // in real time: the latency mode, with the scenario's calibrated ranges.
  scenario.timing.mode = TimingOptions::Mode::kRandom;
  if (Status s = scenario.Validate(); !s.ok()) return s;
  EpisodeLimits limits;
  limits.laps = 0;
  limits.seconds = options.episode_seconds;
  limits.stall_seconds = 0;
  const int episodes = std::max(
      1, static_cast<int>(std::ceil(options.minutes * 60.0 / options.episode_seconds - 1e-9)));

  std::vector<std::vector<TrafficSample>> runs(episodes);
  std::vector<std::optional<Status>> errors(episodes);
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < episodes; i = next++) {
      auto planner = plan::MakePlanner(options.planner, *config, world->line);
      if (!planner.ok()) {
        errors[i] = planner.status();
        continue;
      }
      auto sim = Simulator::Create(world, scenario, options.first_seed + i);
      if (!sim.ok()) {
        errors[i] = sim.status();
        continue;
      }
      Episode ep(std::move(*sim), limits);
      (*planner)->Reset();
      std::vector<TrafficSample>& run = runs[i];
      run.reserve(static_cast<std::size_t>(options.episode_seconds / kTickSeconds) + 1);
      int consumed = 0;
      while (true) {
        const plan::Telemetry& t = ep.telemetry();
        TrafficSample sample;
        sample.ego_s = t.s;
        sample.consumed = consumed;
        sample.dt = consumed * kTickSeconds;
        sample.cars.reserve(t.sensor_fusion.size());
        for (const plan::SensorCar& c : t.sensor_fusion) {
          sample.cars.push_back({static_cast<double>(c.id), c.x, c.y, c.vx, c.vy, c.s, c.d});
        }
        run.push_back(std::move(sample));
        if (ep.done()) break;
        const plan::PlanResult& result = (*planner)->Plan(t);
        // A rejected path is the planner's problem, not the traffic's: the ticks still run.
        (void)ep.Submit(result.x, result.y);
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
  return builder.figures();
}

}  // namespace frenetic::sim

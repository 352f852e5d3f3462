// Traffic statistics of `frenetic fidelity`: the same figures from the real recordings and from
// the headless simulator, computed by one builder from per-message sensor_fusion samples (as
// shared/realdata/telemetry/STATS.md computes them), so that the comparison is like for like.
#include <algorithm>
#include <cmath>

#include "eval/fidelity_traffic_internal.h"
#include "frenetic/eval/fidelity.h"
#include "frenetic/plan/planner.h"
#include "frenetic/units.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::sim {
namespace {

using fidelity::Interpolate;
using fidelity::LaneOf;
using fidelity::OnRoad;

using plan::kTickSeconds;  // the simulator's physics step
constexpr double kRespawnJump = 15;  // m off the constant-velocity prediction (STATS.md)
constexpr double kHardBrake = -7;    // m/s^2

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

}  // namespace frenetic::sim

#include "frenetic/sim/drive_breakdown.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "frenetic/units.h"

namespace frenetic::sim {
namespace {

// m: a car that moves from ahead to behind (or back) by less than this in one tick was passed;
// a larger jump is a respawn or the s wrap.
constexpr double kPassReach = 50.0;

int LaneOfD(double d) { return d >= 0 && d < 12 ? static_cast<int>(d / 4.0) : -1; }

}  // namespace

double LapBreakdown::avg_speed_mph() const {
  return seconds > 0 ? distance_m / seconds * units::kSimMpsToMph : 0;
}

double LapBreakdown::at_limit_mph() const {
  return at_limit_s > 0 ? at_limit_m / at_limit_s * units::kSimMpsToMph : 0;
}

void LapBreakdown::Add(const LapBreakdown& o) {
  seconds += o.seconds;
  distance_m += o.distance_m;
  at_limit_s += o.at_limit_s;
  at_limit_m += o.at_limit_m;
  following_s += o.following_s;
  following_open_s += o.following_open_s;
  passes += o.passes;
  passed_by += o.passed_by;
  missed_passes += o.missed_passes;
  lane_changes += o.lane_changes;
}

nlohmann::json LapBreakdown::ToJson() const {
  return {{"lap", lap},
          {"seconds", seconds},
          {"distance_m", distance_m},
          {"avg_speed_mph", avg_speed_mph()},
          {"at_limit_s", at_limit_s},
          {"at_limit_mph", at_limit_mph()},
          {"following_s", following_s},
          {"following_open_lane_s", following_open_s},
          {"passes", passes},
          {"passed_by", passed_by},
          {"missed_passes", missed_passes},
          {"lane_changes", lane_changes}};
}

void DriveBreakdown::Update(double dt, const EgoView& ego, int ego_lane, bool lane_changed,
                            double distance_m, double leader_gap,
                            std::span<const TrafficCar> cars, const map::ReferenceLine& line) {
  const double lap_length = std::max(line.length(), 1.0);
  const int lap = std::max(0, static_cast<int>(std::floor(distance_m / lap_length)));
  while (static_cast<int>(laps_.size()) <= lap) {
    if (!laps_.empty()) laps_.back().distance_m = lap_length;  // a finished lap is whole
    laps_.emplace_back();
    laps_.back().lap = static_cast<int>(laps_.size()) - 1;
  }
  LapBreakdown& b = laps_[lap];
  b.seconds += dt;
  b.distance_m = distance_m - lap * lap_length;
  if (lane_changed) ++b.lane_changes;

  const bool at_limit = ego.speed * units::kSimMpsToMph >= opt_.at_limit_mph;
  if (at_limit) {
    b.at_limit_s += dt;
    b.at_limit_m += ego.speed * dt;
  }
  const double reach = std::max(opt_.follow_min_gap, opt_.follow_time * ego.speed);
  const bool following = !at_limit && ego_lane >= 0 && leader_gap <= reach;

  // Per lane: whether a car blocks moving in, and the nearest car ahead beyond that (its speed).
  bool occupied[3] = {false, false, false};
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double ahead_ds[3] = {kInf, kInf, kInf}, ahead_v[3] = {kInf, kInf, kInf};
  if (seen_.size() < cars.size()) seen_.resize(cars.size());
  for (size_t i = 0; i < cars.size(); ++i) {
    const TrafficCar& c = cars[i];
    Seen& seen = seen_[i];
    if (!c.spawned) {
      seen.id = -1;
      continue;
    }
    const double ds = line.DiffS(c.s, ego.s);
    const int lane = LaneOfD(c.d);
    if (lane >= 0 && ds > -opt_.open_behind && ds < opt_.open_room) occupied[lane] = true;
    if (lane >= 0 && ds > 0 && ds < opt_.open_ahead && ds < ahead_ds[lane]) {
      ahead_ds[lane] = ds;
      ahead_v[lane] = c.v;
    }
    if (seen.id == c.id && lane >= 0 && std::abs(ds - seen.ds) < kPassReach) {
      if (seen.ds > 0 && ds <= 0) ++b.passes;
      if (seen.ds <= 0 && ds > 0) ++b.passed_by;
    }
    seen.id = c.id;
    seen.ds = ds;
  }

  bool any_open = false;
  for (int l = 0; l < 3; ++l) {
    const bool neighbour = ego_lane >= 0 && std::abs(l - ego_lane) == 1;
    const bool quicker = ego_lane >= 0 && ahead_v[l] >= ahead_v[ego_lane] + opt_.open_gain;
    const bool open = following && neighbour && !occupied[l] && quicker && !lane_changed;
    any_open = any_open || open;
    if (!open) {
      open_for_[l] = 0;
      counted_[l] = false;
      continue;
    }
    open_for_[l] += dt;
    if (open_for_[l] >= opt_.missed_open_seconds && !counted_[l]) {
      ++b.missed_passes;
      counted_[l] = true;
    }
  }
  if (following) b.following_s += dt;
  if (following && any_open) b.following_open_s += dt;
}

LapBreakdown DriveBreakdown::Total() const {
  LapBreakdown t;
  for (const LapBreakdown& b : laps_) t.Add(b);
  t.lap = static_cast<int>(laps_.size());
  return t;
}

}  // namespace frenetic::sim

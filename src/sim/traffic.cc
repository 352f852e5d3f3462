#include "frenetic/sim/traffic.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "frenetic/units.h"

namespace frenetic::sim {
namespace {

constexpr double kDt = 0.02;
constexpr double kLookahead = 150.0;  // m, how far a car looks for a leader
constexpr std::size_t kMaxSamples = 2'000'000;

// Where the real simulator parks its 12 cars before they first spawn (first message of every
// real recording, udacity-sim.md §8.1): two columns of six.
constexpr double kParkedX[2] = {775.8, 762.1};
constexpr double kParkedY[6] = {1421.6, 1425.2, 1429.0, 1432.9, 1436.3, 1441.7};

// The car's lateral wander at its own clock (TrafficCar::wander_t).
double Wander(const TrafficCar& c) {
  const double t = c.wander_t;
  return c.wander_amp * (0.6 * std::sin(c.wander_w1 * t + c.wander_p1) +
                         0.4 * std::sin(c.wander_w2 * t + c.wander_p2));
}

double LaneCentre(int lane) { return 2.0 + 4.0 * lane; }

}  // namespace

Traffic::Traffic(std::shared_ptr<const World> world, const TrafficOptions& options,
                 double car_length, double car_width, std::uint64_t seed, const EgoView& ego)
    : world_(std::move(world)),
      o_(options),
      car_length_(car_length),
      car_width_(car_width),
      rng_(seed) {
  wp_s_sorted_ = world_->waypoint_line_s;
  std::sort(wp_s_sorted_.begin(), wp_s_sorted_.end());
  cars_.resize(o_.cars);
  double min_x = std::numeric_limits<double>::infinity(), min_y = min_x;
  for (const auto& wp : world_->track.waypoints) {
    min_x = std::min(min_x, wp.x);
    min_y = std::min(min_y, wp.y);
  }
  for (int i = 0; i < o_.cars; ++i) {
    TrafficCar& c = cars_[i];
    c.id = i;
    const int column = i / 6, row = i % 6;
    if (world_->is_udacity_map) {
      // Beyond the real 12, further columns continue the same grid.
      c.x = column < 2 ? kParkedX[column] : kParkedX[1] - 13.7 * (column - 1);
      c.y = kParkedY[row];
      if (i == 0) c.x = 775.99;  // as logged
    } else {
      // Any off-road spot far from the road: beyond the track's bounding box.
      c.x = min_x - 300.0 - 13.7 * column;
      c.y = min_y - 300.0 + 3.8 * row;
    }
    c.queued = false;
  }
  queue_.reserve(o_.cars);
  if (o_.blockade) {
    for (int lane = 0; lane < 3; ++lane) {
      TrafficCar& c = cars_[lane];
      c.spawned = true;
      c.lane = lane;
      c.s = world_->line->WrapS(ego.s + o_.blockade_distance);
      c.top_speed = (o_.ahead_speed_max_mph -
                     (o_.ahead_speed_max_mph - o_.ahead_speed_min_mph) * Uniform(0, 1)) /
                    units::kSimMpsToMph;
      c.slow_left = o_.blockade_seconds;
      c.slow_speed = o_.blockade_speed;
      c.v = std::min(c.top_speed, c.slow_speed);
      InitWander(c, 0.0);
      c.d = LaneCentre(lane) + Wander(c);
      c.last_change_tick = 0;
      c.spawns = 1;
      Place(c);
    }
  }
  Frame(ego);  // the scheduler runs once as the scene loads
}

double Traffic::Uniform(double lo, double hi) {
  const double u = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

int Traffic::UniformInt(int lo, int hi) {
  return lo + static_cast<int>(rng_() % static_cast<std::uint64_t>(hi - lo + 1));
}

void Traffic::InitWander(TrafficCar& c, double clock) {
  c.wander_t = clock;
  constexpr double kTwoPi = 2 * std::numbers::pi;
  c.wander_amp = Uniform(o_.wander_min, o_.wander_max);
  c.wander_w1 = kTwoPi / Uniform(o_.wander_period_min, o_.wander_period_max);
  c.wander_w2 = kTwoPi / Uniform(o_.wander_period_min, o_.wander_period_max) * 1.7;
  c.wander_p1 = Uniform(0, kTwoPi);
  c.wander_p2 = Uniform(0, kTwoPi);
  c.throttle_w = kTwoPi / Uniform(3, 10);
  c.throttle_p = Uniform(0, kTwoPi);
}

void Traffic::Place(TrafficCar& c) {
  const map::CartesianPose pose = world_->line->ToCartesian(c.s, c.d);
  const double ch = std::cos(pose.heading), sh = std::sin(pose.heading);
  c.x = pose.x;
  c.y = pose.y;
  // d is positive to the right: the right normal of heading h is (sin h, -cos h).
  c.vx = c.v * ch + c.d_rate * sh;
  c.vy = c.v * sh - c.d_rate * ch;
  c.heading = c.v > 0.1 ? std::atan2(c.vy, c.vx) : pose.heading;
}

Box Traffic::BoxOf(const TrafficCar& c) const {
  return Box{c.x, c.y, c.heading, car_length_, car_width_};
}

bool Traffic::Spawn(TrafficCar& car, const EgoView& ego) {
  const auto& wps = world_->track.waypoints;
  const int n = static_cast<int>(wps.size());
  int nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    const double dist = std::hypot(wps[i].x - ego.x, wps[i].y - ego.y);
    if (dist < best) {
      best = dist;
      nearest = i;
    }
  }
  for (int attempt = 0; attempt < o_.spawn_retries; ++attempt) {
    const int lane = UniformInt(0, 2);
    const bool behind = Uniform(0, 1) < 0.5;
    int offset;
    double top_mph;
    if (behind) {
      offset = UniformInt(o_.behind_offset_min, o_.behind_offset_max);
      top_mph = o_.behind_speed_min_mph +
                (o_.behind_speed_max_mph - o_.behind_speed_min_mph) * Uniform(0, 1);
    } else {
      offset = UniformInt(o_.ahead_offset_min, o_.ahead_offset_max);
      top_mph = o_.ahead_speed_max_mph -
                (o_.ahead_speed_max_mph - o_.ahead_speed_min_mph) * Uniform(0, 1);
    }
    const int wi = ((nearest + offset) % n + n) % n;
    const double s = world_->waypoint_line_s[wi];
    const map::CartesianPose pose = world_->line->ToCartesian(s, LaneCentre(lane));
    bool clear = true;
    for (const TrafficCar& other : cars_) {
      if (other.id == car.id) continue;
      if (std::hypot(other.x - pose.x, other.y - pose.y) < o_.spawn_clearance) {
        clear = false;
        break;
      }
    }
    if (!clear) continue;
    car.spawned = true;
    car.queued = false;
    car.lane = lane;
    car.s = s;
    car.top_speed = top_mph / units::kSimMpsToMph;
    car.v = car.top_speed;
    car.accel = 0;
    car.changing = false;
    car.clear_counts.fill(0);
    car.last_change_tick = tick_;
    car.hard_brake_left = 0;
    car.slow_left = 0;
    car.blocked = false;
    car.too_close = false;
    car.switch_wait = 0;
    car.leader_v = 0;
    InitWander(car, time_);
    car.d = LaneCentre(lane) + Wander(car);
    car.d_rate = 0;
    // §8.6: the initial velocity is top speed numerically in m/s until the next physics tick.
    car.spawn_quirk = o_.spawn_speed_quirk;
    ++car.spawns;
    Place(car);
    if (stats_.spawn_offsets.size() < kMaxSamples) {
      stats_.spawn_offsets.push_back(static_cast<float>(world_->line->DiffS(car.s, ego.s)));
    }
    return true;
  }
  return false;
}

void Traffic::Frame(const EgoView& ego) {
  if (--countdown_ > 0) return;
  // The source draws count_max and counts frames up to it after the run's frame, so the next
  // run is count_max + 1 frames later.
  countdown_ = UniformInt(o_.period_min_frames, o_.period_max_frames) + 1;
  for (TrafficCar& c : cars_) {
    if (c.queued) continue;
    if (std::hypot(c.x - ego.x, c.y - ego.y) > o_.respawn_distance) {
      c.queued = true;
      queue_.push_back(c.id);
    }
  }
  const int batch = UniformInt(o_.batch_min, o_.batch_max);
  for (int k = 0; k < batch && !queue_.empty(); ++k) {
    const int id = queue_.front();
    queue_.erase(queue_.begin());
    // A car that found no free spot waits at the end of the queue (it keeps driving).
    if (!Spawn(cars_[id], ego)) queue_.push_back(id);
  }
}

void Traffic::StartChange(TrafficCar& c, int lane, double duration, std::int64_t tick) {
  c.from_d = c.d - Wander(c);
  c.lane = lane;
  c.changing = true;
  c.change_elapsed = 0;
  c.change_duration = duration;
  c.last_change_tick = tick;
  c.clear_counts.fill(0);
  ++stats_.lane_changes;
}

bool Traffic::LaneClear(const TrafficCar& car, int lane, const EgoView& ego) const {
  const double centre = LaneCentre(lane);
  // Absolute difference of s, without wrap handling, as in the source.
  for (const TrafficCar& o : cars_) {
    if (o.id == car.id || !o.spawned) continue;
    if (std::abs(o.d - centre) < 2.0 && std::abs(o.s - car.s) <= o_.lane_change_gap) return false;
  }
  if (std::abs(ego.d - centre) < o_.lane_change_ego_band &&
      std::abs(ego.s - car.s) <= o_.lane_change_gap) {
    return false;
  }
  return true;
}

void Traffic::LaneChangeRule(TrafficCar& c, const EgoView& ego, std::int64_t tick) {
  if (c.v * units::kSimMpsToMph <= o_.lane_change_min_mph) return;
  if (tick - c.last_change_tick < o_.lane_change_spacing_ticks) return;
  const double length = world_->line->length();
  auto next = std::upper_bound(wp_s_sorted_.begin(), wp_s_sorted_.end(), c.s);
  const double to_next = next == wp_s_sorted_.end() ? wp_s_sorted_.front() + length - c.s
                                                    : *next - c.s;
  if (to_next > o_.waypoint_window) return;
  // From lane 0 or 2 only the middle lane; from the middle the left lane first. Any failure
  // resets every counter, so a middle-lane car can only ever reach the left lane's threshold.
  int candidates[2] = {1, -1};
  if (c.lane == 1) {
    candidates[0] = 0;
    candidates[1] = 2;
  }
  for (int target : candidates) {
    if (target < 0) break;
    if (LaneClear(c, target, ego)) {
      if (++c.clear_counts[target] > o_.lane_change_evaluations) {
        StartChange(c, target, o_.lane_change_duration, tick);
        return;
      }
    } else {
      c.clear_counts.fill(0);
    }
  }
}

void Traffic::HarderEvents(const EgoView& ego, std::int64_t tick) {
  if (o_.cut_in_rate <= 0 && o_.hard_brake_rate <= 0) return;
  if (time_ - last_event_t_ < o_.event_cooldown) return;
  const auto& line = *world_->line;
  if (o_.hard_brake_rate > 0) {
    TrafficCar* leader = nullptr;
    double best = o_.hard_brake_max_distance;
    for (TrafficCar& c : cars_) {
      if (!c.spawned || std::abs(c.d - ego.d) >= o_.follow_lateral) continue;
      const double ds = line.DiffS(c.s, ego.s);
      if (ds > 0 && ds < best) {
        best = ds;
        leader = &c;
      }
    }
    if (leader != nullptr && Uniform(0, 1) < o_.hard_brake_rate * kDt) {
      leader->hard_brake_left = o_.hard_brake_duration;
      last_event_t_ = time_;
      ++stats_.hard_brakes;
      return;
    }
  }
  if (o_.cut_in_rate > 0 && ego.d > 0 && ego.d < 12) {
    const int ego_lane = static_cast<int>(ego.d / 4.0);
    TrafficCar* best_car = nullptr;
    double best_gap = std::numeric_limits<double>::infinity();
    for (TrafficCar& c : cars_) {
      if (!c.spawned || c.changing || std::abs(c.lane - ego_lane) != 1) continue;
      if (c.v * units::kSimMpsToMph <= o_.lane_change_min_mph ||
          c.v < ego.speed - o_.cut_in_max_closing) {
        continue;
      }
      const double gap = line.DiffS(c.s, ego.s) - car_length_;
      if (gap >= o_.cut_in_min_gap && gap <= o_.cut_in_max_gap && gap < best_gap) {
        best_gap = gap;
        best_car = &c;
      }
    }
    if (best_car != nullptr && Uniform(0, 1) < o_.cut_in_rate * kDt) {
      StartChange(*best_car, ego_lane, o_.cut_in_duration, tick);
      --stats_.lane_changes;  // counted as a cut-in instead
      ++stats_.cut_ins;
      last_event_t_ = time_;
    }
  }
}

void Traffic::Tick(const EgoView& ego, std::int64_t tick) {
  tick_ = tick;
  time_ = (tick + 1) * kDt;
  const auto& line = *world_->line;
  for (TrafficCar& c : cars_) c.spawn_quirk = false;  // the tick caps the spawn velocity
  HarderEvents(ego, tick);

  // Pass 1: accelerations from the state at the start of the tick (order-independent).
  accel_.resize(cars_.size());
  for (std::size_t i = 0; i < cars_.size(); ++i) {
    TrafficCar& c = cars_[i];
    accel_[i] = 0;
    if (!c.spawned) continue;
    double gap = std::numeric_limits<double>::infinity(), leader_v = 0;
    for (const TrafficCar& o : cars_) {
      if (o.id == c.id || !o.spawned || std::abs(o.d - c.d) >= o_.follow_lateral) continue;
      const double ds = line.DiffS(o.s, c.s);
      if (ds > 0 && ds < kLookahead && ds - car_length_ < gap) {
        gap = ds - car_length_;
        leader_v = o.v;
      }
    }
    if (std::abs(ego.d - c.d) < o_.follow_lateral) {
      const double ds = line.DiffS(ego.s, c.s);
      if (ds > 0 && ds < kLookahead && ds - car_length_ < gap) {
        gap = ds - car_length_;
        leader_v = ego.speed;
      }
    }
    const double top_mph = c.top_speed * units::kSimMpsToMph;
    // The source's trigger distance mixes mph and m/s (§8.3); clamped to the observed 10-20 m.
    double h = std::clamp(10.0 * (top_mph - leader_v) / 20.0, o_.brake_gap_min, o_.brake_gap_max);
    // [GUESS] Unity's full brake plus handbrake stops in time behind a steady leader: never
    // trigger later than the stopping distance of the closing speed.
    const double closing = c.v - leader_v;
    if (closing > 0) h = std::max(h, closing * closing / (2 * o_.brake_decel) + 1.0);
    const bool too_close = gap < h;
    c.too_close = too_close;
    if (too_close) c.leader_v = leader_v;
    if (too_close == c.blocked) {
      c.switch_wait = 0;
    } else {
      // Unity reacts a little late both ways; the lag keeps a queued car's brake/throttle cycle
      // going at the amplitude the recordings show instead of decaying to tick-long pulses.
      c.switch_wait += kDt;
      const double delay = too_close || o_.brake_release_delay < 0 ? o_.brake_delay
                                                                   : o_.brake_release_delay;
      if (c.switch_wait >= delay - 1e-9) {
        c.blocked = too_close;
        c.switch_wait = 0;
      }
    }
    double desired = c.top_speed;
    if (c.slow_left > 0) desired = std::min(desired, c.slow_speed);
    double a;
    if (c.hard_brake_left > 0) {
      a = -o_.hard_brake_decel;
    } else if (c.blocked && !o_.brake_to_leader_mph) {
      a = -o_.brake_decel;
    } else if (c.blocked && c.v * units::kSimMpsToMph > c.leader_v) {
      // §8.3: the desired speed is the leader's m/s number read as mph, with a brake gain of 1
      // per mph: full brake more than 1 mph above it (brake_decel is the recorded total).
      a = -o_.brake_decel * std::min(c.v * units::kSimMpsToMph - c.leader_v, 1.0);
    } else {
      const double wander =
          1.0 - o_.throttle_wander * (0.5 + 0.5 * std::sin(c.throttle_w * time_ + c.throttle_p));
      // Free: toward the top speed. Blocked below the wrong-unit target: gently up to it.
      const double target_mph = c.blocked ? c.leader_v : desired * units::kSimMpsToMph;
      const double throttle =
          std::clamp(o_.throttle_gain * (target_mph - c.v * units::kSimMpsToMph), -1.0, 1.0) *
          wander;
      a = throttle >= 0 ? throttle * o_.max_accel : throttle * o_.brake_decel;
      a -= o_.drag * c.v * c.v + o_.linear_drag * c.v;
    }
    accel_[i] = a;
  }

  // Pass 2: integrate.
  for (std::size_t i = 0; i < cars_.size(); ++i) {
    TrafficCar& c = cars_[i];
    if (!c.spawned) continue;
    const double v_old = c.v;
    c.v = std::max(0.0, c.v + accel_[i] * kDt);
    c.v = std::min(c.v, std::max(c.top_speed, v_old));  // the speed cap at the top speed
    c.accel = (c.v - v_old) / kDt;
    c.hard_brake_left = std::max(0.0, c.hard_brake_left - kDt);
    c.slow_left = std::max(0.0, c.slow_left - kDt);

    double base = LaneCentre(c.lane);
    if (c.changing) {
      c.change_elapsed += kDt;
      const double tau = std::min(1.0, c.change_elapsed / c.change_duration);
      const double blend = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
      base = c.from_d + (base - c.from_d) * blend;
      if (tau >= 1) c.changing = false;
    }
    const double d_old = c.d;
    // The wander's clock runs with the car below wander_full_speed (a car that stands, stands).
    c.wander_t += o_.wander_full_speed > 0 ? kDt * std::min(1.0, c.v / o_.wander_full_speed) : kDt;
    const double d_new = base + Wander(c);
    c.d_rate = (d_new - d_old) / kDt;
    c.d = d_new;
    // Speed v is along the lane at offset d; the centre line advances by v / (1 + kappa d)
    // (d to the right, kappa positive turning left: the right side is the outer side).
    const double kappa = line.At(c.s).kappa;
    const double scale = std::max(0.2, 1.0 + kappa * c.d);
    c.s = line.WrapS(c.s + c.v / scale * kDt);
    Place(c);

    if (c.d >= 0 && c.d <= 12) {
      ++stats_.car_ticks;
      if (c.accel < -7) ++stats_.hard_brake_ticks;
      const bool crossed = (d_old < 4) != (c.d < 4) || (d_old < 8) != (c.d < 8);
      if (crossed && d_old >= 0 && d_old <= 12) ++stats_.lane_crossings;
      if (tick % 5 == 0 && stats_.speeds.size() < kMaxSamples) {
        stats_.speeds.push_back(static_cast<float>(std::hypot(c.vx, c.vy)));
      }
      if (tick % 25 == 0 && stats_.rel_s.size() < kMaxSamples) {
        stats_.rel_s.push_back(static_cast<float>(line.DiffS(c.s, ego.s)));
      }
    }
  }
  // Lane changes by the §8.5 rule, evaluated on the new state.
  if (o_.lane_changes) {
    for (TrafficCar& c : cars_) {
      // The source evaluates the rule in the same branch as the ray-cast test, not after the
      // reaction lag.
      if (c.spawned && c.too_close && !c.changing && c.slow_left <= 0 && c.hard_brake_left <= 0) {
        LaneChangeRule(c, ego, tick);
      }
    }
  }
}

void Traffic::FillSensorFusion(std::vector<plan::SensorCar>* rows) const {
  rows->resize(cars_.size());
  const map::ChordFrenet& chord = *world_->chord;
  for (std::size_t i = 0; i < cars_.size(); ++i) {
    const TrafficCar& c = cars_[i];
    plan::SensorCar& r = (*rows)[i];
    r.id = c.id;
    const float x = static_cast<float>(c.x), y = static_cast<float>(c.y);
    r.x = x;
    r.y = y;
    if (!c.spawned) {
      r.vx = r.vy = 0;
    } else if (c.spawn_quirk) {
      // §8.6: forward x top speed with the mph number taken as m/s.
      const double f = c.top_speed * units::kSimMpsToMph;
      r.vx = static_cast<float>(std::cos(c.heading) * f);
      r.vy = static_cast<float>(std::sin(c.heading) * f);
    } else {
      r.vx = static_cast<float>(c.vx);
      r.vy = static_cast<float>(c.vy);
    }
    const map::FrenetPoint f = chord.Convert(x, y);
    r.s = std::isnan(f.s) ? 0.0 : static_cast<float>(f.s);
    r.d = std::isnan(f.d) ? 0.0 : static_cast<float>(f.d);
    if (c.spawned && o_.seam_glitch && c.s < o_.seam_glitch_window) {
      r.s = 0;  // §8.6: the wrap-around glitch reports s = d = 0 for a while
      r.d = 0;
    }
  }
}

int Traffic::Collides(const Box& ego) const {
  for (const TrafficCar& c : cars_) {
    if (c.spawned && BoxesOverlap(ego, BoxOf(c))) return c.id;
  }
  return -1;
}

}  // namespace frenetic::sim

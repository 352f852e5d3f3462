// The simulator's forward traffic (udacity-sim.md §8): a fixed list of cars (sensor_fusion ids
// 0..n-1), parked off the road until the respawn scheduler places them 1-3 at a time near the
// ego; cruise below a random top speed, brake hard behind a leader (other cars and the ego),
// wander laterally, change lanes by the §8.5 rule. Cars move along the smooth reference line in
// Frenet (s, d) with their own longitudinal dynamics; x, y, vx, vy come from the line. Seeded:
// the same seed gives the same traffic bit for bit. Harder options (cut-ins, leader braking, a
// blockade of all lanes) are in TrafficOptions.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "frenetic/plan/telemetry.h"
#include "frenetic/sim/incident_monitor.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"

namespace frenetic::sim {

// The ego as traffic sees it (after the tick): map pose and its Frenet on the smooth line.
struct EgoView {
  double x = 0, y = 0, yaw = 0;  // m, rad
  double speed = 0;              // m/s
  double s = 0, d = 0;           // on the smooth line, m
};

struct TrafficCar {
  int id = 0;
  bool spawned = false;  // false: parked off the road, not moving
  double s = 0, d = 0;   // smooth-line Frenet (d positive right), m
  double v = 0;          // m/s along the lane
  double d_rate = 0;     // m/s, lateral
  double accel = 0;      // m/s^2 of the last tick
  double x = 0, y = 0, heading = 0, vx = 0, vy = 0;  // map frame
  double top_speed = 0;  // m/s
  int lane = 0;          // target lane 0..2
  // Lateral manoeuvre from lane centre `from_d` to the target lane over `change_duration` s.
  bool changing = false;
  double from_d = 0, change_elapsed = 0, change_duration = 2;
  std::int64_t last_change_tick = -1000000;
  std::array<int, 3> clear_counts{};
  double wander_amp = 0.4, wander_w1 = 0, wander_w2 = 0, wander_p1 = 0, wander_p2 = 0;
  double wander_t = 0;  // s: the wander's own clock (TrafficOptions::wander_full_speed)
  double throttle_w = 0, throttle_p = 0;
  bool queued = false;        // waiting for a respawn
  bool spawn_quirk = false;   // report speed in the wrong unit until the next tick
  bool blocked = false;       // braking for a leader (the "too close" test, after the delay)
  bool too_close = false;     // the "too close" test itself, this tick (§8.5 evaluates on it)
  double switch_wait = 0;     // s the test has disagreed with `blocked` (brake_delay)
  double leader_v = 0;        // m/s, speed of the leader when last seen too close
  double hard_brake_left = 0;  // s of forced braking left (hard-brake option)
  double slow_left = 0;        // s of blockade left
  double slow_speed = 0;
  int spawns = 0;
};

// Traffic statistics for comparison with the real recordings (STATS.md).
struct TrafficStats {
  std::vector<float> speeds;        // m/s, on-road spawned cars, sampled every 5 ticks
  std::vector<float> spawn_offsets;  // s of the spawn minus the ego's s, m
  std::vector<float> rel_s;         // car s minus ego s, sampled every 25 ticks
  std::int64_t hard_brake_ticks = 0;  // car-ticks with acceleration < -7 m/s^2
  std::int64_t car_ticks = 0;         // on-road car-ticks
  int lane_crossings = 0;             // d crossing 4 or 8
  int lane_changes = 0;               // §8.5 decisions (and forced cut-ins)
  int cut_ins = 0, hard_brakes = 0;
  double car_minutes() const { return car_ticks * 0.02 / 60.0; }
};

class Traffic {
 public:
  // `ego` is the ego at construction; the scheduler runs once immediately (as at scene load).
  Traffic(std::shared_ptr<const World> world, const TrafficOptions& options, double car_length,
          double car_width, std::uint64_t seed, const EgoView& ego);

  // One 0.02 s physics tick (tick = index of this tick, from 0).
  void Tick(const EgoView& ego, std::int64_t tick);
  // One rendered frame: the respawn scheduler's countdown.
  void Frame(const EgoView& ego);

  const std::vector<TrafficCar>& cars() const { return cars_; }
  // For tests and scripted set-ups: change a car's state (call Place() after moving it).
  std::vector<TrafficCar>& mutable_cars() { return cars_; }
  void Place(TrafficCar& car);
  // The sensor_fusion rows as the simulator reports them (id order, chord Frenet, quirks).
  void FillSensorFusion(std::vector<plan::SensorCar>* rows) const;
  // Id of a spawned car whose box overlaps `ego`, else -1.
  int Collides(const Box& ego) const;
  Box BoxOf(const TrafficCar& car) const;
  const TrafficStats& stats() const { return stats_; }

 private:
  bool Spawn(TrafficCar& car, const EgoView& ego);
  void InitWander(TrafficCar& car, double clock);  // its wander's draws, its clock at `clock`
  void StartChange(TrafficCar& car, int lane, double duration, std::int64_t tick);
  void LaneChangeRule(TrafficCar& car, const EgoView& ego, std::int64_t tick);
  bool LaneClear(const TrafficCar& car, int lane, const EgoView& ego) const;
  void HarderEvents(const EgoView& ego, std::int64_t tick);
  double Uniform(double lo, double hi);
  int UniformInt(int lo, int hi);  // inclusive

  std::shared_ptr<const World> world_;
  TrafficOptions o_;
  double car_length_, car_width_;
  std::mt19937_64 rng_;
  std::vector<TrafficCar> cars_;
  std::vector<int> queue_;
  std::vector<double> wp_s_sorted_;
  std::vector<double> accel_;
  std::int64_t tick_ = 0;
  int countdown_ = 0;
  double time_ = 0;
  double last_event_t_ = -1e9;
  TrafficStats stats_;
};

}  // namespace frenetic::sim

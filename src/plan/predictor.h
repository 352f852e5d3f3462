// Prediction of the surrounding traffic from sensor_fusion rows. Rows are converted to Frenet on
// the smooth reference line (from x, y: this also repairs the simulator's s = d = 0 glitch at the
// seam), rows off the carriageway (parked cars) are dropped, and the one-message speed spike of a
// just-spawned car is repaired. Two predictors: constant velocity along the lane, and the default
// manoeuvre-aware one, which also extrapolates a car that is braking (its deceleration, from its
// previous reading) and a car that is moving across lanes (its lateral velocity, from vx, vy),
// the two moves of the simulator's traffic that end in collisions (udacity-sim.md §8.3, §8.5).
#pragma once

#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/road.h"
#include "frenetic/plan/telemetry.h"

namespace frenetic::plan {

// One tracked car at the observation instant. s is relative to the ego reference passed to
// Observe (m, along the line, in [-L/2, L/2)), d its lateral offset (m, right positive), v_s its
// speed along the lane (m/s).
struct TrackedCar {
  int id = 0;
  double s = 0, d = 0, v_s = 0;
  double a_s = 0;        // m/s^2 along the lane, from the previous reading (0 when unknown)
  double v_d = 0;        // m/s across the lane, right positive (a predicted merge's, if any)
  double d_target = 0;   // m: where a lateral move is predicted to end (= d when none)
  bool ghost = false;    // a lane change the car may start (PredictorOptions::lane_change_ghosts)
  double lat_delay = 0;  // s before a predicted lateral move starts
  // s a braking car (a_s below -brake_threshold) is predicted to go on braking: brake_horizon,
  // or less behind a leader it is predicted to fall back from (PredictorOptions::follow_gap).
  double brake_time = 0;
  double length = 0, width = 0;  // footprint, m (the row's, else PredictorOptions' defaults)
  bool recorded = false;         // predicted from its CarFuture
  // s after the observation a car to come appears (CarFuture::start); 0 for a car there now.
  // Before it, Predict places the car kAbsentS behind the ego (out of every check's reach).
  double appears = 0;
};

// m: where a car not there yet is predicted (TrackedCar::appears), relative to the ego.
inline constexpr double kAbsentS = -1e6;

struct PredictorOptions {
  double range = 200;             // m: cars farther along s are ignored
  double d_min = -1, d_max = 13;  // m: the carriageway
  double max_speed = 30;          // m/s: faster readings are the spawn glitch
  double spike_ratio = 1.8;       // a reading this much above the id's last one is the spawn glitch
  int max_cars = 64;              // rows beyond this are ignored (keeps Observe allocation-free)
  // Manoeuvre-aware predictor only.
  double brake_threshold = 2.0;    // m/s^2: a car decelerating harder is predicted to keep braking
  double brake_horizon = 2.0;      // s: for at most this long (then constant speed, never < 0)
  double lateral_threshold = 0.5;  // m/s: a car moving across faster is changing lanes
  // A lane change ends at the next lane centre: of lanes [0, w), [w, 2w), ... on a uniform road
  // (the line-only factories build one from these two), else the road's lanes at the car's s.
  double lane_width = 4.0;  // m
  int num_lanes = 3;
  // The carriageway on a road that is not uniform: rows farther than this outside the road's
  // edges at their s are dropped (on a uniform road d_min and d_max above rule).
  double edge_slack = 1.0;                   // m
  double car_length = 4.8, car_width = 2.4;  // m: a row's footprint when it gives none
  double future_horizon = 8.0;               // s of a recorded future kept (past it: straight on)
  // The simulator's traffic changes lane only while braking behind a leader (udacity-sim.md
  // §8.5): left from the middle lane, to the middle from the outer ones, when no car (nor the
  // ego) within 20 m of it in s is in that lane. With this on, every such car faster than
  // 15 mph also appears as a second car (same id) that starts that move now, so a plan never
  // counts on the braking car staying in its lane; none is added within 20 m of the ego, where
  // the rule would not let the car move (the ego could be in the target lane), unless Observe's
  // ego_d is known and more than 3 m from the target lane's centre (the rule then ignores the
  // ego: a car alongside or just ahead may move in).
  bool lane_change_ghosts = false;
  // m: on a uniform road (the Udacity track), a braking car with a leader in its lane closer
  // than this (bumpers) is predicted to brake only until the gap has opened to it, as the
  // traffic's following rule brakes in full while its ray hits a car within 10-20 m (§8.3);
  // 0: brake_horizon for every braking car.
  double follow_gap = 0;
  double ghost_lateral_speed = 1.6;  // m/s across, about a lane in 2.5 s
  // Both predictors, on a road that is not uniform: a car (not recorded, not moving across
  // already) whose lane drops (map::Road::Drops: a lane drop, a zipper merge, an on-ramp's
  // acceleration lane) and that reaches the end within future_horizon at its speed moves into
  // the neighbouring lane that goes on, over the last merge_time s before the end (all of the
  // time left when less, but at least 1 s: a car at the end moves over, it does not jump), its
  // move ending at that lane's centre. 0: none (the car is predicted on along its lane's d,
  // through the end).
  double merge_time = 0;  // s
};

class Predictor {
 public:
  virtual ~Predictor() = default;
  // Replaces the tracked set with the valid rows of `rows`, relative to the ego's line
  // coordinate `ego_s` (wrapped or not). `now` is the simulated time of the readings (s, any
  // origin, increasing between calls; NaN when unknown, e.g. after a resynchronisation): it
  // dates the readings from which later calls estimate accelerations. A row with a CarFuture
  // in `futures` (same id) is predicted from it (its first kMaxFutureSamples samples) instead;
  // a future with start > 0 whose id has no row is a car to come, tracked from then on (its
  // first sample within `range`). Never fails: invalid rows and future samples are skipped (a
  // future with any non-finite sample is not used). `ego_d` is the ego's lateral offset (m; NaN:
  // unknown), which the traffic's lane-change rule looks at (PredictorOptions::lane_change_ghosts).
  virtual void Observe(std::span<const SensorCar> rows, double ego_s, double now,
                       std::span<const CarFuture> futures = {}, double ego_d = NAN) = 0;
  static constexpr int kMaxFutureSamples = 96;
  virtual std::span<const TrackedCar> cars() const = 0;
  // Predicted state of car i, t >= 0 seconds after the observation: s and d (m), speed along
  // the lane v (m/s) and lateral velocity v_d (m/s).
  struct Prediction {
    double s = 0, d = 0, v = 0, v_d = 0;
  };
  virtual Prediction Predict(int i, double t) const = 0;
  virtual void Reset() = 0;
};

// Constant speed along the lane, constant d (but for a lane drop's merge, merge_time).
std::unique_ptr<Predictor> MakeConstantVelocityPredictor(std::shared_ptr<const map::Road> road,
                                                         const PredictorOptions& options);
// Constant velocity, except a braking car keeps braking for up to brake_horizon and a car moving
// across lanes keeps its lateral velocity until it reaches the next lane centre.
std::unique_ptr<Predictor> MakeManoeuvrePredictor(std::shared_ptr<const map::Road> road,
                                                  const PredictorOptions& options);
// The same on a uniform road of options.num_lanes x options.lane_width along `line`.
std::unique_ptr<Predictor> MakeConstantVelocityPredictor(
    std::shared_ptr<const map::ReferenceLine> line, const PredictorOptions& options);
std::unique_ptr<Predictor> MakeManoeuvrePredictor(std::shared_ptr<const map::ReferenceLine> line,
                                                  const PredictorOptions& options);

}  // namespace frenetic::plan

// The simulator's telemetry, in SI units (the wire's mph and degrees are converted at the edges,
// in net/ and sim/). Map frame: x east, y north, heading counter-clockwise from +x.
#pragma once

#include <vector>

#include "frenetic/cost/goal_region.h"

namespace frenetic::plan {

// One sensor_fusion row. vx, vy in m/s in the map frame; s, d as the simulator reported them
// (its chord-based Frenet, NaN replaced by 0). Parked cars have d far below 0.
struct SensorCar {
  int id = 0;
  double x = 0, y = 0;
  double vx = 0, vy = 0;
  double s = 0, d = 0;
  // Footprint, m: 0 (the Udacity simulator's rows) means the planner's check.car_length /
  // check.car_width.
  double length = 0, width = 0;
};

// A car's known future (a CommonRoad scenario's recorded trajectory, for `--prediction
// recorded`): its centre, speed and heading every dt s from `start` s after the telemetry's
// instant (sample 0) on. The planner then uses it for that car instead of predicting it; past
// its last sample the car keeps its last speed and heading. A future with start > 0 is a car
// not there yet (no SensorCar row): it appears at `start` with its first sample, and is absent
// before.
struct CarFuture {
  int id = 0;       // the SensorCar it belongs to (start = 0), or a car to come (start > 0)
  double dt = 0.1;  // s
  double start = 0;  // s, >= 0
  double length = 0, width = 0;  // m: the footprint of a car to come (0: the default car's)
  std::vector<double> x, y, v, heading;  // m, m, m/s, rad (counter-clockwise from +x)
  // m: the footprint at each sample where it changes along the future (a set-based prediction's
  // occupancy grows with its uncertainty), else empty (the row's, or length and width above).
  std::vector<double> lengths, widths;
};

struct Telemetry {
  double x = 0, y = 0;  // ego position, m
  double yaw = 0;       // ego heading, rad, counter-clockwise from +x
  double speed = 0;     // m/s (the simulator's displacement per tick / 0.02 s)
  double s = 0, d = 0;  // the simulator's chord-based Frenet of the ego, m
  std::vector<double> previous_path_x;  // unvisited points of the path sent last, m
  std::vector<double> previous_path_y;
  double end_path_s = 0, end_path_d = 0;  // simulator's Frenet of the last unvisited point (quirky)
  std::vector<SensorCar> sensor_fusion;
  // Known futures of some sensor_fusion cars (empty from the Udacity simulator).
  std::vector<CarFuture> futures;
  // Goals to reach, times relative to this telemetry's instant, in the planner's line's Frenet
  // frame (the first cost::kMaxGoalRegions are used; none from the Udacity simulator).
  std::vector<cost::GoalRegion> goals;
};

}  // namespace frenetic::plan

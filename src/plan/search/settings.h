// The search planner's settings, read once from PlannerConfig (SI units: the configured mph
// speed limit is converted here), and the fixed constants its stages share. Private to
// src/plan/: the stages of the search planner (search/*.h) live in frenetic::plan::search.
#pragma once

#include <cmath>

#include "frenetic/map/road.h"
#include "frenetic/plan/feasibility.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::plan::search {

inline constexpr int kHistory = 110;  // driven points kept for the jerk windows (> 2 s of blocks)
inline constexpr int kMaxCars = 64;   // cars in a cycle's context (the broad-phase masks' width)
// m: a car behind within this lateral offset is following the ego (the simulator's traffic sees
// a leader within 2 m and brakes for it).
inline constexpr double kFollowerLateral = 1.0;
// The simulator times a car whose d is within 0.8 m of a lane line and flags it after 150 ticks
// (udacity-sim.md §7.4). Lane centres keep a little more room; the hard check allows a little
// less time.
inline constexpr double kStraddle = 0.8;       // m
inline constexpr double kLaneLineBand = 0.9;   // m
inline constexpr int kMaxStraddleTicks = 135;  // ticks

inline bool Finite(double v) { return std::isfinite(v); }

// Every key the search planner reads, by its config name (see config/planner.yaml), and what it
// takes from the road. A pinned deadline (PlannerConfig::PinDeadlines) reads as an infinite
// budget_ms / refine_budget_ms.
struct Settings {
  double max_speed, max_accel, max_jerk, d_min, d_max;  // m/s, m/s^2, m/s^3, m, m
  // The road's: its typical lane width and its lane count (clamped to [1, cost::kMaxLanes]), and
  // whether it is the Udacity layout (map::Road::uniform: d_min / d_max as the simulator reads
  // d, the lane-line timer, outer_inset); on any other road the ego stays edge_margin inside
  // its edges.
  double lane_width, outer_inset;
  int num_lanes;
  bool uniform_road;
  double edge_margin;  // m
  double ego_length, ego_width;  // m: the ego's footprint (check.car_* are the other cars')
  VehicleLimits vehicle;  // vehicle.*: a real vehicle's steering and forward limits (0: none)
  int keep_points, output_points;
  double resync_tolerance;
  int replan_min_ticks;
  double replan_deviation;
  int speeds, durations;
  bool lane_limit_speeds;
  double min_duration, max_duration;
  int follow_gaps;
  int gap_targets;  // gaps between a lane's cars the lattice aims into, per lane (0: none)
  double follow_d0, follow_tau, follow_tau_step;
  bool stop;
  int brake_decels, brake_targets;
  double brake_min_decel, brake_max_decel;
  int accels;
  double accel_min, accel_max;  // grid.min_accel, grid.max_accel
  int lat_durations;
  double lat_min_duration, lat_max_duration;
  int lat_offsets;
  double lat_offset_step;
  double lane_reach;          // lane widths: lanes whose centre is this near are targets
  int lat_delays;
  bool passes;  // passes on a two-way road's oncoming lane (Lattice::AddPasses)
  double lat_delay_step;
  double score_dt, score_horizon;
  double check_horizon, collision_dt, car_length, car_width, margin_s, margin_d, margin_behind;
  double headway_min, behind_time;
  double clear_enough;  // m (check.clear_enough; 0: off)
  // check.curve_prefilter: longitudinal trajectories whose v^2 kappa along the line clearly
  // exceeds limits.max_accel are not candidates (Lattice::AddLon).
  bool curve_prefilter;
  bool followers_react;  // a car right behind brakes for the ego (prediction.followers_react)
  bool refine;
  int refine_iterations;
  double refine_budget_ms;
  double fallback_decel, fallback_jerk, fallback_lat_duration;
  double budget_ms;

  // On the configured uniform road (road.num_lanes x road.lane_width).
  explicit Settings(const PlannerConfig& c);
  Settings(const PlannerConfig& c, const map::Road& road);
};

}  // namespace frenetic::plan::search

// The search planner's settings, read once from PlannerConfig (SI units: the configured mph
// speed limit is converted here), and the fixed constants its stages share. Private to
// src/plan/: the stages of the search planner (search/*.h) live in frenetic::plan::search.
#pragma once

#include <cmath>
#include <limits>

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
// Settings::curve_prefilter's tests (Lattice::TooFastForTheCurve, LimitChecker::CurveExcess)
// rule out a lateral acceleration this share above limits.max_accel: the XY check measures the
// total on 0.2 s means, which the tests' lower bounds leave a little room to.
inline constexpr double kCurveSlack = 0.15;

inline bool Finite(double v) { return std::isfinite(v); }

// Every key the search planner reads, grouped as in config/planner.yaml (the key in brackets),
// and what it takes from the road. SI units. A pinned deadline (PlannerConfig::PinDeadlines)
// reads as an infinite budget_ms / refine.budget_ms.
struct Settings {
  struct Limits {
    double max_speed = 0;    // m/s (limits.max_speed_mph, converted)
    double max_accel = 0;    // m/s^2, on the XY path (limits.max_accel)
    double max_jerk = 0;     // m/s^3, on the XY path (limits.max_jerk)
    double d_min = 0;        // m: the smallest d the simulator may read on a uniform road
    double d_max = 0;        // m: the largest
    double edge_margin = 0;  // m the ego stays inside the edges of any other road
    double backward_speed = 0;  // m/s: the most s' may fall below 0 (limits.backward_speed)
  };
  // The road's (map::Road), else road.* on the configured uniform road.
  struct Road {
    double lane_width = 0;   // m: its typical lane width
    double outer_inset = 0;  // m: the outer lanes' centres moved in (road.outer_lane_inset)
    int num_lanes = 1;       // clamped to [1, cost::kMaxLanes]
    bool uniform = true;     // the Udacity layout: d_min / d_max, the lane-line timer
  };
  struct Continuity {
    int keep_points = 0;          // points of the last path kept before a new plan
    int output_points = 0;        // points sent
    double resync_tolerance = 0;  // m: previous_path is ours when its ends are this near
    int replan_min_ticks = 0;     // fewer driven points than this: the last plan re-sent
    double replan_deviation = 0;  // m: ...unless a car moved this far from its prediction
  };
  // The longitudinal lattice (grid.*).
  struct Grid {
    int speeds = 0;                  // end speeds of velocity keeping
    bool lane_limit_speeds = false;  // and each lane's own limit
    int durations = 0;               // durations between min_duration and max_duration (s)
    double min_duration = 0, max_duration = 0;
    int follow_gaps = 0;    // following: extra gaps behind the leader
    int gap_targets = 0;    // gaps between a lane's cars aimed into, per lane (0: none)
    double follow_d0 = 0;   // m: following's standstill gap
    double follow_tau = 0;  // s: its time gap, follow_tau_step apart per extra gap
    double follow_tau_step = 0;
    bool stop = false;                    // stopping trajectories
    int accels = 0;                       // constant accelerations between accel_min and accel_max
    double accel_min = 0, accel_max = 0;  // m/s^2 (grid.min_accel, grid.max_accel)
    // With a vehicle's limits (vehicle.max_accel): constant accelerations at its limit at each end
    // speed of the grid, to that speed, in any traffic (grid.limit_ramps).
    bool limit_ramps = false;
    double lane_reach = 0;  // lane widths: lanes whose centre is this near are targets
    bool passes = false;    // passes on a two-way road's oncoming lane (AddPasses)
  };
  // Constant-deceleration braking (grid.brake_*).
  struct Brake {
    int decels = 0;   // decelerations between min_decel and max_decel (m/s^2)
    int targets = 0;  // end speeds braked to
    double min_decel = 0, max_decel = 0;
  };
  // The lateral moves (grid.lat_*).
  struct Lateral {
    int durations = 0;  // between min_duration and max_duration (s)
    double min_duration = 0, max_duration = 0;
    int offsets = 0;  // offsets from a lane's centre, offset_step (m) apart
    double offset_step = 0;
    // When the last search found no candidate passing (Workspace::none_passed_last): these offsets
    // instead (grid.escape_lat_offsets, 0: the same as above; grid.escape_lat_offset_step).
    int escape_offsets = 0;
    double escape_offset_step = 0;
    // And then also moves of this duration (s) to each lane (grid.escape_lat_duration, 0: none).
    double escape_duration = 0;
    // Those quicker moves for the least harm only, not the selection (grid.escape_lat_least_harm).
    bool escape_least_harm = false;
    int delays = 0;  // delayed starts, delay_step (s) apart
    double delay_step = 0;
  };
  struct Score {
    double dt = 0;       // s between scoring samples
    double horizon = 0;  // s scored
  };
  struct Check {
    double ego_length = 0, ego_width = 0;  // m: the ego's footprint
    double car_length = 0, car_width = 0;  // m: the other cars' (when a row has none)
    double horizon = 0;                    // s checked on the XY path
    double collision_dt = 0;               // s between collision-check steps
    double margin_s = 0, margin_d = 0;     // m added to every car's box
    double margin_behind = 0;              // m of room for a car behind in another lane...
    double behind_time = 0;                // ...plus this many s of its closing speed
    double headway_min = 0;                // s of headway to a car ahead
    double clear_enough = 0;               // m: least harm takes the cheapest this clear (0: off)
    // m: least harm counts a car this far to the side of the ego (bare boxes) as clear at that
    // step, whatever the gap along the road (infinite: off; check.side_clear 0).
    double side_clear = std::numeric_limits<double>::infinity();
    // s: astride a line with the timer running, the latest contact keeps the last winner's
    // side when a move there meets a car at most this much sooner (LeastHarm::KeepSide;
    // check.keep_side, 0: off).
    double keep_side = 0;
    // Ticks: astride a line, least harm's clear tests once more with this lane-line count
    // before it drops the timer (check.last_resort_ticks, 0: no second try).
    int last_resort_ticks = 0;
    // s: after a cycle in which no candidate passed, when every candidate meets a car, least
    // harm keeps the last winner's lane if a move there meets one at most this much sooner
    // (LeastHarm::KeepSide off the line too; check.keep_lane, 0: off).
    double keep_lane = 0;
    // Longitudinal trajectories whose v^2 kappa along the line clearly exceeds
    // limits.max_accel are not candidates (Lattice::AddLon).
    bool curve_prefilter = false;
  };
  struct Refine {
    bool enabled = false;  // NLopt on the winner (refine.enabled)
    int iterations = 0;    // refine.max_iterations
    double budget_ms = 0;  // ms (infinite when pinned)
  };
  // Keep-lane braking when nothing else is left.
  struct Fallback {
    double decel = 0;         // m/s^2
    double jerk = 0;          // m/s^3
    double lat_duration = 0;  // s back to the lane's centre
  };

  Limits limits;
  Road road;
  VehicleLimits vehicle;  // vehicle.*: a real vehicle's steering and forward limits (0: none)
  Continuity continuity;
  Grid grid;
  Brake brake;
  Lateral lat;
  Score score;
  Check check;
  bool followers_react = false;  // a car right behind brakes for the ego (prediction.*)
  Refine refine;
  Fallback fallback;
  double budget_ms = 0;  // ms per cycle (infinite when pinned)

  // On the configured uniform road (road.num_lanes x road.lane_width).
  explicit Settings(const PlannerConfig& c);
  Settings(const PlannerConfig& c, const map::Road& on);
};

}  // namespace frenetic::plan::search

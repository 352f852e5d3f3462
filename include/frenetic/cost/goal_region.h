// A goal the ego must reach (a CommonRoad planning problem's goal state), in the Frenet frame of
// the planner's reference line: a box in (s, d), a time window, a speed interval and a heading
// interval. Absent parts are infinite intervals. The planner is told its goals with each telemetry (plan::Telemetry::goals)
// and the `goal` cost term steers toward them.
#pragma once

#include <limits>

namespace frenetic::cost {

struct GoalRegion {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double s_lo = -kInf, s_hi = kInf;  // m along the line (unwrapped)
  // m, right positive: at s the region spans d in [d_lo, d_hi] + d_slope (s - s_ref) (a box
  // turned a little against the road: a goal rectangle along a lane that bends off the line).
  double d_lo = -kInf, d_hi = kInf;
  double s_ref = 0, d_slope = 0;
  double t_lo = -kInf, t_hi = kInf;  // s from the instant it is given for
  double v_lo = -kInf, v_hi = kInf;  // m/s
  // The heading relative to the line's, as its tangent d' / s' (right positive as d): the
  // tangents of a goal orientation interval less the road's heading there (headings within a
  // quarter turn of the road's).
  double h_lo = -kInf, h_hi = kInf;
  // Every lane of the road runs alongside from the ego's start to past the region (no lane
  // begins or ends on the way, no ramp or merge): a path may still move across into the region's
  // lane after its samples (the goal cost's lateral_pace). False: nothing is known of the way.
  bool across_open = false;
};

inline constexpr int kMaxGoalRegions = 8;

// A region crossed turned: its headings leave out the road's own by more than kTurnedHeading (as
// a tangent, ~6 degrees), to the right (+1: d grows) or the left (-1); 0 otherwise. Reached by a
// swerve from beside it (the search planner's lattice offers them), not by keeping a lane; a
// smaller offset is within what keeping a lane near the region's edge gives.
inline constexpr double kTurnedHeading = 0.1;
inline int CrossedTurned(const GoalRegion& r) {
  if (r.h_lo > kTurnedHeading) return 1;
  if (r.h_hi < -kTurnedHeading) return -1;
  return 0;
}

}  // namespace frenetic::cost

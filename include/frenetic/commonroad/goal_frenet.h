// A CommonRoad planning problem's goal states as regions of the planner's Frenet frame
// (cost::GoalRegion): each goal shape, or goal lanelet, along the road's reference line, with
// the goal's time, speed and orientation intervals. The closed loop (RunScenario) aims the
// planner and the rescue at them, a little inside (Inset).
#pragma once

#include <vector>

#include "frenetic/commonroad/lanelet.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/shape.h"
#include "frenetic/cost/goal_region.h"
#include "frenetic/map/road.h"
#include "frenetic/map/reference_line.h"

namespace frenetic::commonroad {

// Insets of the goal regions the planner aims at (Inset): m along, m across, m/s, rad, and
// steps of the time window.
inline constexpr double kInsetS = 1.0, kInsetD = 0.2, kInsetV = 0.5, kInsetH = 0.02, kTimeInset = 0.5;

// The goal states as regions of the road's Frenet frame (times in steps; shifted per cycle).
struct FrenetGoal {
  cost::GoalRegion region;  // times: steps (absolute), converted per cycle
  bool timed_lo = false, timed_hi = false;
};

// One region per goal state's shape and per goal lanelet (a goal without a position: one
// region of its intervals alone), in the problem's order. Times in steps (absolute).
//  - a rectangle: its long axis in the Frenet frame (centre s and d, the slope of d along s),
//    the s range of its ends and the d half-width across it (AddRectangle); turned more than
//    45 degrees across the road, the bounding box of its corners;
//  - a circle or a polygon: the Frenet bounding box of its vertices (a circle's 8 points);
//  - a lanelet: the s range of its polygon and, across it, the widest band of one slope that
//    lies between its projected borders at every station (ProjectLanelet), the slope the
//    least-squares line of its centre's d along s. A box of the polygon's corners' d would take
//    the borders as straight in the Frenet frame between the lanelet's points, and a reference
//    line bending between them put such a box's edge 0.3 m outside the lanelet
//    (zip/ZAM_Zip-1_1: the ego at d 2.02 was inside the box, 2 cm outside the lanelet). That
//    box is kept when the band is narrower than kMinGoalBand (a lanelet bending off the line).
inline constexpr double kMinGoalBand = 0.5;  // m
std::vector<FrenetGoal> FrenetGoals(const Scenario& sc, const PlanningProblem& p,
                                    const map::ReferenceLine& line);

// The inset of [lo, hi] by `margin`: a quarter of its width at most, 0 when unbounded.
double InsetBy(double lo, double hi, double margin);
// The region the planner aims at: a little inside the goal's intervals (a quarter of each, at
// most kInsetS, kInsetD, kInsetV, kInsetH), so that the ego's state at a whole step lies inside,
// not on the edge the plan touched between two steps. Times are left as they are.
cost::GoalRegion Inset(cost::GoalRegion r);

// m: the ego's centre this far past the far end (s) of every goal region has missed them all.
inline constexpr double kPassedMargin = 1.0;

// Whether the ego at s has driven past every goal region (all of them with a position): the
// planner never reverses, so none can be met any more.
bool PassedEveryGoal(const std::vector<FrenetGoal>& goals, double s);

// GoalRegion::across_open for a region on `road` and an ego starting at start_s: the region
// has a far end, every lane of the road runs from start_s (or before) to past it, and its
// middle at that end lies between the road's edges.
bool AcrossOpen(const map::Road& road, double start_s, const cost::GoalRegion& r);

}  // namespace frenetic::commonroad

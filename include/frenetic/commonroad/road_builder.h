// The road a CommonRoad planning problem is driven on: the lanelets joined along successors and
// adjacency into one map::Road (lanes side by side along a smooth reference line).
//
//  1. Start: the lanelet holding the initial position (of several, the one whose direction is
//     closest to the initial orientation; none holding it: the nearest within kMaxStartDistance).
//  2. Route: the cheapest path over the lanelet graph (successors cost their length, a move to an
//     adjacent lanelet of the same direction kLaneChangeCost) from the start to a goal lanelet
//     (one the goal lists, or one holding a goal shape's centre); without a goal position, the
//     longest chain of successors ahead.
//  3. Skeleton: one lanelet per cross-section along the route, successor to successor (it keeps
//     its lane while the route changes lanes, and moves over only where its lane ends), extended
//     by up to kExtendBehind m of predecessors and kExtendAhead m of successors. The reference
//     line is fitted (ReferenceLine::FitOpen) through the skeleton's centre lines.
//  4. Lanes: every lanelet beside a skeleton lanelet (adjacency, same direction, any number of
//     lanes over) at its lateral position; a lane is the lanelets at one lateral position, their
//     borders projected onto the reference line; a lane goes on RoadArea::kDefaultOpenEndMargin
//     (5 m) past an open end of the network (a lanelet without predecessor or successor), as the
//     verdict's road area does. A lanelet merging into the road (a successor of one of its
//     lanelets that leads into it without being part of it: the half of a zipper merge the
//     reference does not follow, drawn converging onto the other) goes on the lane it comes
//     from, clipped to the lanes beside, until narrower than 0.5 m. At the map's own ends
//     (where every lane ends) the lanes run on straight for 300 m, so that the planner does not
//     stop at the edge of the map (a run ends at its goal; the verdict holds the ego to the
//     lanelets up to there).
//  5. Oncoming lane: on a two-way road, the opposite-direction lanelet beside the leftmost
//     lanelet of each skeleton cross-section is one more lane on the left, marked
//     LaneProfile::oncoming (for passing only: the `oncoming` cost term); lanelets of the
//     opposite direction farther over are not part of the road (the verdict still counts
//     every lanelet as road surface).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "frenetic/commonroad/scenario.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/road.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

struct BuiltRoad {
  std::shared_ptr<const map::Road> road;
  std::vector<int> route;     // lanelet ids from the start to the goal (or the chain ahead)
  std::vector<int> skeleton;  // the lanelets the reference line follows
  // Per road lane (left to right), the lanelets it is made of.
  std::vector<std::vector<int>> lane_lanelets;
  int start_lanelet = 0;
  // m along the reference line: where the map's lanes end (before the lanes' run-on, which the
  // planner sees past a closed end that the verdict does not).
  double map_end = 0;
};

inline constexpr double kMaxStartDistance = 5.0;  // m
inline constexpr double kLaneChangeCost = 30.0;   // m of route
inline constexpr double kExtendBehind = 60.0;     // m
inline constexpr double kExtendAhead = 250.0;     // m

// Fails, naming the scenario and the problem, when no lanelet is near the start, when a goal
// position lies on no lanelet the start can reach, or when the geometry is degenerate.
// A lanelet's borders projected on `line`: stations (s increasing, the mid s of the left and the
// right border point) with the left and right d (right positive). The stations are the
// lanelet's border points, and between two of them as many evenly spaced ones as keep both
// borders' gaps at most kStationStep: a border is read linearly in d between stations, which is
// exact only where the line runs parallel to it, and the line is a smooth fit that bends where
// the border does not (it overshoots before a junction). A hand-crafted lanelet straight over
// 160 m in two points was 0.3 m off its real edge mid-way at its points alone (zip/ZAM_Zip-1_16:
// the ego left the road there). Stations narrower than kMinStationWidth (a pointed end), or not
// past the last one along s, are left out.
struct LaneletStations {
  std::vector<double> s, left, right;
};
inline constexpr double kStationStep = 2.0;       // m
inline constexpr double kMinStationWidth = 0.05;  // m
LaneletStations ProjectLanelet(const Lanelet& l, const map::ReferenceLine& line);

StatusOr<BuiltRoad> BuildRoad(const Scenario& scenario, const PlanningProblem& problem);

}  // namespace frenetic::commonroad

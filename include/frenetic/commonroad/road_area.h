// The drivable area of a lanelet network, for CommonRoad's road-compliance check ("the ego does
// not leave the lanelets").
//
// The area is built as CommonRoad's solution checker builds its road (commonroad_dc.feasibility.
// solution_checker._construct_boundary_checker: construction.construct with section_triangles
// and triangulation; lanelet_bounds.lane_sections and lane_hull): the union of the outlines of
// the lane sections, a section being a lanelet with every lanelet it reaches through adjacentLeft
// and adjacentRight, either driving direction (so an oncoming lane is road too). The lane lines
// inside a section do not count: where adjacent lanelets do not give their shared bound point for
// point (the US-101 examples), the slivers between them are road. Between lanelets that are not
// adjacent, they are not: the checker's triangulation keeps a sliver between two sections as
// road boundary, and so does this area (DEU_Muc-2's two lanelets, whose shared line differs by up
// to 9 mm, and which a lane change there crosses). A section whose outline is no simple polygon
// falls back to its lanelets' own polygons.
//
// Each outline is grown by `tolerance` before the union (Boost.Geometry buffer, mitred joins),
// 1 micrometre by default: shared points that differ only by rounding leave no gap; the checker
// has no tolerance. Holes smaller than 1e-9 m^2 (rounding) are dropped.
//
// Ends: by default the network's ends are closed, as in CommonRoad's solution checker, whose road
// boundary is the outline of the lanelet network (the triangulated boundary closes the ends): a
// box that sticks out past the last point of a lanelet without successors, or before the first
// of one without predecessors, is off the road. With `open_end_margin` > 0, such a lanelet is
// extended by that much along its bounds' end directions instead (the drivability checker's
// obb_rectangles boundary with open_lane_ends=True leaves the ends open).
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/lanelet.h"

namespace frenetic::commonroad {

class RoadArea {
 public:
  static constexpr double kDefaultTolerance = 1e-6;      // m
  static constexpr double kDefaultOpenEndMargin = 0.0;   // m: closed ends

  // An empty area (contains nothing).
  RoadArea();
  // The union of the lanelets' polygons as described above. Never fails: a lanelet whose polygon
  // Boost.Geometry cannot buffer (e.g. a bound that folds back on itself) is taken unbuffered, and
  // one it cannot unite at all is left out and listed in SkippedLanelets().
  static RoadArea Build(std::span<const Lanelet> lanelets, double tolerance = kDefaultTolerance,
                        double open_end_margin = kDefaultOpenEndMargin);

  // True when the convex polygon (e.g. BoxCorners of the ego) lies inside the area: no boundary
  // segment of the area touches it and its vertex mean is inside.
  bool ContainsConvex(std::span<const Vec2> convex) const;
  bool Contains(Vec2 point) const;
  // True when a boundary segment of the area touches the convex polygon: the polygon then sticks
  // out of the area (or into a hole). Cheaper than ContainsConvex (an R-tree query, no
  // point-in-area test): a polygon known to lie mostly on the road is off it exactly when this
  // holds.
  bool BoundaryTouches(std::span<const Vec2> convex) const;

  double Area() const;        // m^2
  int PolygonCount() const;   // separate pieces
  int HoleCount() const;
  // The holes' rings (closed, the first point repeated last): gaps of the network inside its
  // outline, such as a sliver between two lanelets that are not adjacent.
  std::vector<std::vector<Vec2>> HoleRings() const;
  // Every ring of the area's boundary, outlines and holes (closed).
  std::vector<std::vector<Vec2>> BoundaryRings() const;
  double tolerance() const { return tolerance_; }
  std::span<const int> SkippedLanelets() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  double tolerance_ = 0;
};

}  // namespace frenetic::commonroad

// The drivable area of a lanelet network, for CommonRoad's road-compliance check ("the ego does
// not leave the lanelets").
//
// The area is the union of every lanelet's polygon, both driving directions: CommonRoad's
// solution checker (commonroad_dc.feasibility.solution_checker.boundary_collision) builds its road
// boundary from the hull of all lanelets of the network (commonroad_dc.boundary.construction,
// lanelet_bounds.lateral_bounds follows adjacency either way), so an oncoming lane is road too.
//
// Each polygon is grown by `tolerance` before the union (Boost.Geometry buffer, mitred joins), and
// holes smaller than 1 m^2 are dropped from the union: adjacent lanelets whose shared bound is not
// given point for point leave slivers up to ~2 cm wide between them (the US-101 and DEU_Muc
// examples), and a car straddling the lane line there is on the road. So a box counts as on the
// road when it sticks out over the road's edge by at most `tolerance`.
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

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/lanelet.h"

namespace frenetic::commonroad {

class RoadArea {
 public:
  static constexpr double kDefaultTolerance = 0.02;      // m
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
  double tolerance() const { return tolerance_; }
  std::span<const int> SkippedLanelets() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  double tolerance_ = 0;
};

}  // namespace frenetic::commonroad

#include "frenetic/commonroad/road_area.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "commonroad/scenario_xml.h"

namespace frenetic::commonroad {
namespace {

using testing::Line;

Lanelet Make(int id, std::vector<Vec2> left, std::vector<Vec2> right) {
  Lanelet l;
  l.id = id;
  l.left = std::move(left);
  l.right = std::move(right);
  return l;
}

TEST(RoadAreaTest, AdjacentLanesWithASliverBetweenThemAreOneRoad) {
  // The left lane's right bound sits 1.5 cm above the right lane's left bound; the lanelets are
  // adjacent: one lane section, whose outline leaves the lane line out.
  std::vector<Lanelet> lanes = {Make(1, Line(0, 100, 0), Line(0, 100, -3.5)),
                                Make(2, Line(0, 100, 3.515), Line(0, 100, 0.015))};
  lanes[0].adjacent_left = Adjacent{2, true};
  lanes[1].adjacent_right = Adjacent{1, true};
  const RoadArea road = RoadArea::Build(lanes);
  EXPECT_EQ(road.PolygonCount(), 1);
  EXPECT_EQ(road.HoleCount(), 0);
  // A car straddling the lane line is on the road.
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({50, 0}, 0, 4.5, 1.8)));
  EXPECT_NEAR(road.Area(), 100 * 7.015, 0.01);
}

TEST(RoadAreaTest, ASliverBetweenLanesThatAreNotAdjacentIsNoRoad) {
  // The same lanes without adjacency: two sections, and the sliver between them is not road
  // (CommonRoad's solution checker keeps it as road boundary).
  const std::vector<Lanelet> lanes = {Make(1, Line(0, 100, 0), Line(0, 100, -3.5)),
                                      Make(2, Line(0, 100, 3.515), Line(0, 100, 0.015))};
  const RoadArea road = RoadArea::Build(lanes);
  EXPECT_EQ(road.PolygonCount(), 2);
  EXPECT_FALSE(road.ContainsConvex(BoxCorners({50, 0}, 0, 4.5, 1.8)));
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({50, -1.75}, 0, 4.5, 1.8)));
  // Closed at both ends, the sliver is a hole: a lane line shared up to x = 20 m and from 80 m,
  // 5 mm apart between.
  std::vector<Vec2> line = Line(0, 100, 0);
  for (Vec2& p : line) {
    if (p.x > 20 && p.x < 80) p.y = -0.005;
  }
  const std::vector<Lanelet> touching = {Make(1, line, Line(0, 100, -3.5)),
                                         Make(2, Line(0, 100, 3.5), Line(0, 100, 0))};
  const RoadArea holed = RoadArea::Build(touching);
  EXPECT_EQ(holed.PolygonCount(), 1);
  ASSERT_EQ(holed.HoleCount(), 1);
  EXPECT_FALSE(holed.ContainsConvex(BoxCorners({50, 0}, 0, 4.5, 1.8)));
  const std::vector<std::vector<Vec2>> holes = holed.HoleRings();
  ASSERT_EQ(holes.size(), 1u);
  double lo = 1e9, hi = -1e9;
  for (const Vec2& p : holes[0]) {
    lo = std::min(lo, p.x);
    hi = std::max(hi, p.x);
  }
  EXPECT_NEAR(lo, 20, 1e-6);
  EXPECT_NEAR(hi, 80, 1e-6);
  EXPECT_TRUE(holed.ContainsConvex(BoxCorners({95, 0}, 0, 4.5, 1.8)));  // where the lanes touch
  // A tolerance wider than the sliver closes it.
  EXPECT_EQ(RoadArea::Build(touching, 0.01).HoleCount(), 0);
}

TEST(RoadAreaTest, TheToleranceIsTheAllowedOverhang) {
  const std::vector<Lanelet> lane = {Make(1, Line(0, 100, 2), Line(0, 100, -2))};
  const RoadArea road = RoadArea::Build(lane, 0.02, 5.0);  // ends open by 5 m
  EXPECT_DOUBLE_EQ(road.tolerance(), 0.02);
  // A 2 m wide box whose left side is 1 cm beyond the bound: on the road; 3 cm: off.
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({50, 1.01}, 0, 4, 2)));
  EXPECT_FALSE(road.ContainsConvex(BoxCorners({50, 1.03}, 0, 4, 2)));
  // Across the lanelet's open end, up to the margin.
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({98.5, 0}, 0, 4, 2)));
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({103, 0}, 0, 4, 2)));
  EXPECT_FALSE(road.ContainsConvex(BoxCorners({103.1, 0}, 0, 4, 2)));
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({-2.5, 0}, 0, 4, 2)));  // across the start
  // Closed ends, the default (CommonRoad's solution checker): past the end by 1 cm is on the
  // road (the tolerance), by 3 cm off; likewise before the start.
  const RoadArea closed = RoadArea::Build(lane, 0.02);
  EXPECT_TRUE(closed.ContainsConvex(BoxCorners({97.5, 0}, 0, 4, 2)));
  EXPECT_TRUE(closed.ContainsConvex(BoxCorners({98.01, 0}, 0, 4, 2)));
  EXPECT_FALSE(closed.ContainsConvex(BoxCorners({98.03, 0}, 0, 4, 2)));
  EXPECT_FALSE(closed.ContainsConvex(BoxCorners({98.5, 0}, 0, 4, 2)));
  EXPECT_TRUE(closed.ContainsConvex(BoxCorners({1.99, 0}, 0, 4, 2)));
  EXPECT_FALSE(closed.ContainsConvex(BoxCorners({1.97, 0}, 0, 4, 2)));
  EXPECT_FALSE(closed.Contains({-0.5, 1}));
  // Entirely outside.
  EXPECT_FALSE(road.ContainsConvex(BoxCorners({50, 10}, 0, 4, 2)));
  EXPECT_TRUE(road.Contains({1, 1}));
  EXPECT_FALSE(road.Contains({-6, 1}));  // beyond the open start's margin
}

// BoundaryTouches is ContainsConvex without the point-in-area test: it tells a box across the
// outline from one inside it, and says nothing of a box wholly outside.
TEST(RoadAreaTest, TheBoundaryTouchesABoxAcrossTheOutlineOnly) {
  const std::vector<Lanelet> lane = {Make(1, Line(0, 100, 2), Line(0, 100, -2))};
  const RoadArea road = RoadArea::Build(lane, 0.02);
  const auto inside = BoxCorners({50, 0}, 0, 4, 2), across = BoxCorners({50, 1.03}, 0, 4, 2);
  const auto past_end = BoxCorners({98.5, 0}, 0, 4, 2), outside = BoxCorners({50, 10}, 0, 4, 2);
  EXPECT_FALSE(road.BoundaryTouches(inside));
  EXPECT_TRUE(road.BoundaryTouches(across));
  EXPECT_TRUE(road.BoundaryTouches(past_end));  // the closed end
  EXPECT_FALSE(road.BoundaryTouches(outside));
  for (const auto& box : {inside, across, past_end}) {
    EXPECT_EQ(road.BoundaryTouches(box), !road.ContainsConvex(box));
  }
  const std::vector<Vec2> broken = {{50, 0}, {std::nan(""), 0}, {52, 1}};
  EXPECT_TRUE(road.BoundaryTouches(broken));  // not finite: never taken for inside
}

TEST(RoadAreaTest, AnOncomingLaneIsRoad) {
  // Lanelet 2 runs the other way (its bounds from x = 100 to 0).
  std::vector<Vec2> left = Line(0, 100, -3.5), right = Line(0, 100, 0);
  std::reverse(left.begin(), left.end());
  std::reverse(right.begin(), right.end());
  const std::vector<Lanelet> lanes = {Make(1, Line(0, 100, 3.5), Line(0, 100, 0)),
                                      Make(2, left, right)};
  const RoadArea road = RoadArea::Build(lanes);
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({50, -1.75}, 0, 4.5, 1.8)));
  EXPECT_NEAR(RoadArea::Build(lanes, 0.02, 0).Area(), 700 + 214 * 0.02, 0.01);  // grown all round
}

TEST(RoadAreaTest, ALargeHoleIsKept) {
  // Four lanes around a 10 m x 10 m island (closed ends: the lanes end in each other).
  const std::vector<Lanelet> ring = {Make(1, Line(0, 20, 5), Line(0, 20, 0)),
                                     Make(2, Line(0, 20, 20), Line(0, 20, 15)),
                                     Make(3, {{5, 5}, {5, 15}}, {{0, 5}, {0, 15}}),
                                     Make(4, {{20, 5}, {20, 15}}, {{15, 5}, {15, 15}})};
  const RoadArea road = RoadArea::Build(ring, 0.02, 0.0);
  EXPECT_EQ(road.PolygonCount(), 1);
  EXPECT_EQ(road.HoleCount(), 1);
  EXPECT_FALSE(road.Contains({10, 10}));
  // A box that spans the island is not on the road, although its centre and corners are not
  // in it: the island's boundary runs through the box.
  EXPECT_FALSE(road.ContainsConvex(BoxCorners({10, 2.5}, 0, 4, 9)));
  EXPECT_TRUE(road.ContainsConvex(BoxCorners({10, 2.5}, 0, 4, 2)));
}

TEST(RoadAreaTest, DegenerateInputDoesNotBreakIt) {
  Lanelet nan = Make(7, {{0, 0}, {std::nan(""), 1}}, {{0, -1}, {1, -1}});
  const RoadArea road = RoadArea::Build(std::vector<Lanelet>{nan});
  EXPECT_EQ(road.SkippedLanelets().size(), 1u);
  EXPECT_FALSE(road.Contains({0.5, -0.5}));
  const RoadArea empty;
  EXPECT_FALSE(empty.ContainsConvex(BoxCorners({0, 0}, 0, 1, 1)));
  const std::vector<Lanelet> lane = {Make(1, Line(0, 100, 2), Line(0, 100, -2))};
  EXPECT_FALSE(RoadArea::Build(lane).ContainsConvex(BoxCorners({std::nan(""), 0}, 0, 4, 2)));
}

// Adjacency that loops, points at itself or at a lanelet that is not there, flips direction, or
// joins a lanelet whose bound is not finite: the walk over the sections ends, and the area is
// still the lanelets' (a section that cannot be outlined falls back to its lanelets' polygons).
TEST(RoadAreaTest, HostileAdjacencyEndsAndKeepsTheLanelets) {
  std::vector<Lanelet> lanes = {Make(1, Line(0, 100, 0), Line(0, 100, -3.5)),
                                Make(2, Line(0, 100, 3.5), Line(0, 100, 0)),
                                Make(3, Line(0, 100, 7), Line(0, 100, 3.5))};
  lanes[0].adjacent_left = Adjacent{2, true};
  lanes[1].adjacent_left = Adjacent{3, true};
  lanes[2].adjacent_left = Adjacent{1, true};  // a cycle
  lanes[0].adjacent_right = Adjacent{1, true};  // itself
  lanes[1].adjacent_right = Adjacent{99, false};  // not there
  const RoadArea looped = RoadArea::Build(lanes);
  EXPECT_TRUE(looped.SkippedLanelets().empty());
  for (const double y : {-1.75, 1.75, 5.25}) {
    EXPECT_TRUE(looped.ContainsConvex(BoxCorners({50, y}, 0, 4.5, 1.8))) << y;
  }
  EXPECT_FALSE(looped.Contains({50, 8}));
  // A lanelet with a point that is not finite, adjacent to a sound one.
  std::vector<Lanelet> broken = {Make(1, Line(0, 100, 0), Line(0, 100, -3.5)),
                                 Make(2, {{0, 3.5}, {50, std::nan("")}, {100, 3.5}},
                                      Line(0, 100, 0))};
  broken[0].adjacent_left = Adjacent{2, true};
  broken[1].adjacent_right = Adjacent{1, false};  // and its direction flipped
  const RoadArea area = RoadArea::Build(broken);
  EXPECT_TRUE(area.ContainsConvex(BoxCorners({50, -1.75}, 0, 4.5, 1.8)));
  EXPECT_EQ(area.SkippedLanelets().size(), 1u);
}

}  // namespace
}  // namespace frenetic::commonroad

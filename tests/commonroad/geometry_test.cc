#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/shape.h"

namespace frenetic::commonroad {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(GeometryTest, WrapAngleIntoMinusPiToPi) {
  EXPECT_NEAR(WrapAngle(0.5), 0.5, 1e-12);
  EXPECT_NEAR(WrapAngle(2 * kPi + 0.5), 0.5, 1e-12);
  EXPECT_NEAR(WrapAngle(-2 * kPi - 0.5), -0.5, 1e-12);
  EXPECT_NEAR(WrapAngle(3 * kPi / 2), -kPi / 2, 1e-12);
}

TEST(GeometryTest, AngleIntervalsAreComparedModuloTwoPi) {
  EXPECT_TRUE(AngleInInterval(0.1, -0.2, 0.2));
  EXPECT_TRUE(AngleInInterval(0.1 + 2 * kPi, -0.2, 0.2));
  EXPECT_TRUE(AngleInInterval(0.1 - 4 * kPi, -0.2, 0.2));
  EXPECT_FALSE(AngleInInterval(0.3, -0.2, 0.2));
  // DEU_Muc-2: initial orientation -3.351 against the goal interval [2.5394, 3.3248].
  EXPECT_TRUE(AngleInInterval(-3.351, 2.5394, 3.3248));
  EXPECT_FALSE(AngleInInterval(-2.0, 2.5394, 3.3248));
  // An interval across +-pi.
  EXPECT_TRUE(AngleInInterval(-kPi + 0.05, kPi - 0.1, kPi + 0.1));
  EXPECT_TRUE(AngleInInterval(1.0, 0, 7));  // 2 pi or more holds every angle
  EXPECT_FALSE(AngleInInterval(kNaN, -1, 1));
  EXPECT_FALSE(AngleInInterval(0, 1, -1));
}

TEST(GeometryTest, CleanPolylineDropsConsecutiveRepeatsOnly) {
  const std::vector<Vec2> raw{{0, 0}, {0, 0}, {1, 0}, {1, 0}, {1, 0}, {2, 0}, {0, 0}};
  const std::vector<Vec2> clean = CleanPolyline(raw);
  ASSERT_EQ(clean.size(), 4u);
  EXPECT_EQ(clean[3], (Vec2{0, 0}));
  EXPECT_DOUBLE_EQ(PolylineLength(raw), 4);
}

TEST(GeometryTest, ResampleAtEqualArcLengthFractions) {
  const std::vector<Vec2> line{{0, 0}, {10, 0}, {10, 10}};
  const std::vector<Vec2> r = ResamplePolyline(line, 5);
  ASSERT_EQ(r.size(), 5u);
  EXPECT_NEAR(r[1].x, 5, 1e-12);
  EXPECT_NEAR(r[2].x, 10, 1e-12);
  EXPECT_NEAR(r[2].y, 0, 1e-12);
  EXPECT_NEAR(r[3].y, 5, 1e-12);
  EXPECT_EQ(r[4], (Vec2{10, 10}));
  EXPECT_EQ(ResamplePolyline(std::vector<Vec2>{{1, 2}}, 3).size(), 3u);
}

TEST(GeometryTest, ProjectionGivesArcLengthSignedOffsetAndHeading) {
  const std::vector<Vec2> line{{0, 0}, {10, 0}, {10, 10}};
  PolylineProjection p = ProjectOntoPolyline(line, {4, 1});
  EXPECT_NEAR(p.s, 4, 1e-12);
  EXPECT_NEAR(p.d, 1, 1e-12);  // left of travel
  EXPECT_NEAR(p.heading, 0, 1e-12);
  p = ProjectOntoPolyline(line, {11, 5});
  EXPECT_NEAR(p.s, 15, 1e-12);
  EXPECT_NEAR(p.d, -1, 1e-12);  // right of travel (travelling +y)
  EXPECT_NEAR(p.heading, kPi / 2, 1e-12);
  p = ProjectOntoPolyline(line, {-3, -2});  // before the start: the first segment extended
  EXPECT_NEAR(p.s, -3, 1e-12);
  EXPECT_NEAR(p.d, -2, 1e-12);
  p = ProjectOntoPolyline(line, {10, 14});  // beyond the end
  EXPECT_NEAR(p.s, 24, 1e-12);
}

TEST(GeometryTest, BoxCornersAroundTheCentre) {
  const auto c = BoxCorners({1, 2}, kPi / 2, 4, 2);
  EXPECT_NEAR(c[0].x, 2, 1e-12);  // rear right: behind (-y) and right (+x)
  EXPECT_NEAR(c[0].y, 0, 1e-12);
  EXPECT_NEAR(c[2].x, 0, 1e-12);  // front left
  EXPECT_NEAR(c[2].y, 4, 1e-12);
}

// An L-shaped (non-convex) polygon: the notch at the top right is outside.
const std::vector<Vec2> kL{{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 4}, {0, 4}};

TEST(GeometryTest, NonConvexContainment) {
  EXPECT_TRUE(PolygonContains(kL, {0.5, 3}));
  EXPECT_TRUE(PolygonContains(kL, {3, 0.5}));
  EXPECT_FALSE(PolygonContains(kL, {3, 3}));   // in the notch
  EXPECT_TRUE(PolygonContains(kL, {4, 0.5}));  // on the boundary
  EXPECT_FALSE(PolygonContains(kL, {kNaN, 1}));
  std::vector<Vec2> reversed(kL.rbegin(), kL.rend());  // either winding
  EXPECT_FALSE(PolygonContains(reversed, {3, 3}));
  EXPECT_TRUE(PolygonContains(reversed, {0.5, 3}));
  EXPECT_NEAR(PolygonDistance(kL, {3, 3}), 2, 1e-12);
  EXPECT_DOUBLE_EQ(PolygonDistance(kL, {0.5, 0.5}), 0);
}

TEST(GeometryTest, NonConvexOverlapIsNotABoundingBoxTest) {
  // A box in the notch: inside the L's bounding box, yet no overlap.
  const auto notch = BoxCorners({3, 3}, 0.3, 1.5, 1.0);
  EXPECT_FALSE(PolygonsOverlap(kL, notch));
  const auto arm = BoxCorners({3, 1.2}, 0, 1.0, 1.0);
  EXPECT_TRUE(PolygonsOverlap(kL, arm));
  // One polygon inside the other overlaps.
  EXPECT_TRUE(PolygonsOverlap(kL, BoxCorners({0.5, 2}, 0, 0.2, 0.2)));
  // Touching counts.
  EXPECT_TRUE(PolygonsOverlap(BoxCorners({0, 0}, 0, 2, 2), BoxCorners({2, 0}, 0, 2, 2)));
  const std::vector<Vec2> bad{{0, 0}, {kNaN, 1}, {1, 1}};
  EXPECT_FALSE(PolygonsOverlap(kL, bad));
}

TEST(ShapeTest, RectangleCircleAndPolygonContainPoints) {
  const Shape r = Shape::Rectangle(4, 2, {10, 0}, kPi / 2);
  EXPECT_TRUE(r.Contains({10, 1.9}));
  EXPECT_FALSE(r.Contains({11.1, 0}));
  const Shape c = Shape::Circle(1, {0, 0});
  EXPECT_TRUE(c.Contains({0.6, 0.6}));
  EXPECT_FALSE(c.Contains({0.8, 0.8}));
  const Shape p = Shape::Polygon(kL);
  EXPECT_FALSE(p.Contains({3, 3}));
  EXPECT_NEAR(p.BoundingRadius(), std::hypot(4 - 10.0 / 6, 0 - 10.0 / 6), 1e-12);
}

TEST(ShapeTest, TransformedRotatesAboutTheOriginThenMoves) {
  const Shape car = Shape::Rectangle(4, 2);
  const Shape placed = car.Transformed({10, 5}, kPi / 2);
  EXPECT_NEAR(placed.orientation, kPi / 2, 1e-12);
  EXPECT_TRUE(placed.Contains({10, 6.9}));
  EXPECT_FALSE(placed.Contains({11.5, 5}));
  const Shape poly = Shape::Polygon({{1, 0}, {2, 0}, {2, 1}}).Transformed({0, 0}, kPi);
  EXPECT_NEAR(poly.points[1].x, -2, 1e-12);
}

TEST(ShapeTest, GroupOverlapsWithCirclesAndPolygons) {
  ShapeGroup g;
  g.shapes = {Shape::Circle(1, {0, 0}), Shape::Polygon(kL).Transformed({20, 0}, 0)};
  EXPECT_TRUE(g.Overlaps(BoxCorners({1.5, 0}, 0, 1.2, 1)));   // reaches the circle
  EXPECT_FALSE(g.Overlaps(BoxCorners({2.5, 0}, 0, 1.2, 1)));
  EXPECT_FALSE(g.Overlaps(BoxCorners({23, 3}, 0, 1, 1)));     // the L's notch
  EXPECT_TRUE(g.Overlaps(BoxCorners({20.5, 3}, 0, 1, 1)));
  EXPECT_TRUE(g.Contains({20.5, 0.5}));
}

}  // namespace
}  // namespace frenetic::commonroad

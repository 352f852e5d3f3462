#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

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

// The smallest-area rectangle over every edge direction of the hull, by brute force.
double BruteForceMinArea(const std::vector<Vec2>& points) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t j = 0; j < points.size(); ++j) {
      const Vec2 d = points[j] - points[i];
      if (!(Norm(d) > 1e-9)) continue;
      const Vec2 u = (1 / Norm(d)) * d, n{-u.y, u.x};
      double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
      for (const Vec2& p : points) {
        a0 = std::min(a0, u.x * p.x + u.y * p.y);
        a1 = std::max(a1, u.x * p.x + u.y * p.y);
        b0 = std::min(b0, n.x * p.x + n.y * p.y);
        b1 = std::max(b1, n.x * p.x + n.y * p.y);
      }
      best = std::min(best, (a1 - a0) * (b1 - b0));
    }
  }
  return best;
}

TEST(ShapeTest, BoundingBoxOfARectangleIsItself) {
  ShapeGroup g;
  g.shapes = {Shape::Rectangle(6, 2, {10, 5}, 0.4)};
  for (const double reference : {0.4, 0.3, -2.7}) {
    const OrientedBox b = g.BoundingBox(reference);
    EXPECT_NEAR(b.center.x, 10, 1e-9);
    EXPECT_NEAR(b.center.y, 5, 1e-9);
    EXPECT_NEAR(b.length, 6, 1e-9);
    EXPECT_NEAR(b.width, 2, 1e-9);
    EXPECT_NEAR(WrapAngle(b.heading - reference), 0, kPi / 4) << reference;
  }
  // Asked across it, the same rectangle turned a quarter: length 2 along 0.4 + pi / 2.
  const OrientedBox across = g.BoundingBox(0.4 + kPi / 2);
  EXPECT_NEAR(across.heading, 0.4 + kPi / 2, 1e-9);
  EXPECT_NEAR(across.length, 2, 1e-9);
  EXPECT_NEAR(across.width, 6, 1e-9);
}

TEST(ShapeTest, BoundingBoxIsTheSmallestOverRandomPointSets) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-10, 10);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vec2> points(3 + trial % 20);
    for (Vec2& p : points) p = {coord(rng), 0.3 * coord(rng)};
    ShapeGroup g;
    g.shapes = {Shape::Polygon(points)};
    const OrientedBox b = g.BoundingBox(0);
    EXPECT_NEAR(b.length * b.width, BruteForceMinArea(points), 1e-9) << trial;
    EXPECT_LE(std::abs(b.heading), kPi / 4 + 1e-12) << trial;
    // Every point inside (to rounding).
    const Shape box = Shape::Rectangle(b.length + 1e-9, b.width + 1e-9, b.center, b.heading);
    for (const Vec2& p : points) EXPECT_TRUE(box.Contains(p)) << trial;
  }
}

TEST(ShapeTest, BoundingBoxOfCirclesGroupsAndDegenerateSets) {
  ShapeGroup g;
  g.shapes = {Shape::Circle(1, {0, 0}), Shape::Circle(1, {10, 0})};
  const OrientedBox two = g.BoundingBox(0);
  const double r = 1 / std::cos(kPi / 16);  // the circumscribed 16-gon
  EXPECT_NEAR(two.center.x, 5, 1e-9);
  EXPECT_NEAR(two.length, 10 + 2 * r, 1e-9);
  EXPECT_NEAR(two.width, 2 * r, 1e-9);  // its vertices at +-pi / 2
  // Collinear points: width 0; one point: size 0 there; nothing (or only NaN): the origin.
  ShapeGroup flat;
  flat.shapes = {Shape::Polygon({{0, 0}, {1, 1}, {3, 3}})};
  const OrientedBox line = flat.BoundingBox(0.7);
  EXPECT_NEAR(line.length, 3 * std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(line.width, 0, 1e-9);
  EXPECT_NEAR(line.heading, kPi / 4, 1e-9);
  ShapeGroup point;
  point.shapes = {Shape::Polygon({{2, 3}, {2, 3}, {kNaN, 1}})};
  const OrientedBox dot = point.BoundingBox(0);
  EXPECT_EQ(dot.center, (Vec2{2, 3}));
  EXPECT_EQ(dot.length, 0);
  const OrientedBox none = ShapeGroup{}.BoundingBox(kNaN);
  EXPECT_EQ(none.center, (Vec2{0, 0}));
  EXPECT_EQ(none.length, 0);
  EXPECT_TRUE(std::isfinite(none.heading));
}

}  // namespace
}  // namespace frenetic::commonroad

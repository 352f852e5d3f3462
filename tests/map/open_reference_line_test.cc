// The open reference line (ReferenceLine::FitOpen): a road with two ends, straight beyond them.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "frenetic/map/reference_line.h"

namespace frenetic::map {
namespace {

using Point = ReferenceLine::Point;

std::shared_ptr<const ReferenceLine> FitOrDie(const std::vector<Point>& pts) {
  auto line = ReferenceLine::FitOpen(pts, ReferenceLine::Options(), "test");
  EXPECT_TRUE(line.ok()) << line.message();
  return line.ok() ? *line : nullptr;
}

// A quarter circle of radius r around (0, r), counter-clockwise from the origin (a left bend).
std::vector<Point> Arc(double r, int points) {
  std::vector<Point> pts;
  for (int i = 0; i < points; ++i) {
    const double a = 0.5 * std::numbers::pi * i / (points - 1);
    pts.push_back({r * std::sin(a), r - r * std::cos(a)});
  }
  return pts;
}

TEST(OpenReferenceLineTest, StraightLineIsTheLineItself) {
  const auto line = FitOrDie({{0, 0}, {40, 0}, {100, 0}});
  ASSERT_NE(line, nullptr);
  EXPECT_FALSE(line->closed());
  // s = 0 at the fit's foot point of the first point: within 0.1 mm of it.
  EXPECT_NEAR(line->length(), 100.0, 1e-4);
  const CartesianPose p = line->ToCartesian(50, 2);
  EXPECT_NEAR(p.x, 50, 1e-4);
  EXPECT_NEAR(p.y, -2, 1e-6);  // d is to the right of +x: -y
  EXPECT_NEAR(p.heading, 0, 1e-9);
  EXPECT_NEAR(p.kappa, 0, 1e-9);
  const FrenetPoint f = line->ToFrenet(70, 3);
  EXPECT_NEAR(f.s, 70, 1e-4);
  EXPECT_NEAR(f.d, -3, 1e-6);
}

TEST(OpenReferenceLineTest, ContinuesStraightBeyondBothEnds) {
  const auto line = FitOrDie(Arc(200, 40));
  ASSERT_NE(line, nullptr);
  const double L = line->length();
  // The end tangent of a quarter circle from the origin is +y at (200, 200); the fit eases
  // into the straight continuation, so the line's own end heading is close to it.
  const CartesianPose end = line->ToCartesian(L, 0);
  EXPECT_NEAR(end.x, 200, 0.15);
  EXPECT_NEAR(end.y, 200, 0.15);
  EXPECT_NEAR(end.heading, 0.5 * std::numbers::pi, 0.05);
  const double c = std::cos(end.heading), sn = std::sin(end.heading);
  const CartesianPose past = line->ToCartesian(L + 30, 1.5);
  EXPECT_NEAR(past.x, end.x + 30 * c + 1.5 * sn, 1e-9);
  EXPECT_NEAR(past.y, end.y + 30 * sn - 1.5 * c, 1e-9);
  EXPECT_NEAR(past.heading, end.heading, 1e-12);
  EXPECT_EQ(past.kappa, 0);
  const CartesianPose start = line->ToCartesian(0, 0);
  const CartesianPose before = line->ToCartesian(-25, 0);
  EXPECT_NEAR(before.x, start.x - 25 * std::cos(start.heading), 1e-9);
  EXPECT_NEAR(before.y, start.y - 25 * std::sin(start.heading), 1e-9);
  const FrenetPoint fb = line->ToFrenet(before.x, before.y);
  EXPECT_NEAR(fb.s, -25, 1e-6);
  EXPECT_NEAR(fb.d, 0, 1e-6);
  EXPECT_EQ(line->WrapS(L + 30), L + 30);  // no wrap
  EXPECT_EQ(line->DiffS(5, L - 5), 10 - L);
}

TEST(OpenReferenceLineTest, ArcKeepsItsRadiusAndLength) {
  const auto line = FitOrDie(Arc(200, 60));
  ASSERT_NE(line, nullptr);
  // The straight continuations pull the ends a little (the curvature eases in and out over a
  // few control spacings): within 15 cm of the polyline, 10% of its curvature.
  EXPECT_NEAR(line->length(), 0.5 * std::numbers::pi * 200, 0.5);
  EXPECT_LT(line->max_waypoint_distance(), 0.15);
  for (double s = 40; s < line->length() - 40; s += 10) {
    EXPECT_NEAR(line->At(s).kappa, 1.0 / 200, 5e-4) << "s " << s;  // positive: a left bend
  }
}

TEST(OpenReferenceLineTest, FrenetIsTheInverseOfCartesianOnAndBeyondTheLine) {
  const auto line = FitOrDie(Arc(150, 30));
  ASSERT_NE(line, nullptr);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> s_dist(-40, line->length() + 40), d_dist(-8, 8);
  for (int i = 0; i < 500; ++i) {
    const double s = s_dist(rng), d = d_dist(rng);
    const CartesianPose p = line->ToCartesian(s, d);
    const FrenetPoint f = line->ToFrenet(p.x, p.y);
    ASSERT_NEAR(f.s, s, 1e-6) << "s " << s << " d " << d;
    ASSERT_NEAR(f.d, d, 1e-6) << "s " << s << " d " << d;
    const FrenetPoint h = line->ToFrenet(p.x, p.y, s + 7);
    ASSERT_NEAR(h.s, s, 1e-6);
    ASSERT_NEAR(h.d, d, 1e-6);
  }
}

TEST(OpenReferenceLineTest, RepeatedPointsAreOnePoint) {
  const auto a = FitOrDie({{0, 0}, {0, 0}, {50, 5}, {50, 5}, {100, 0}});
  const auto b = FitOrDie({{0, 0}, {50, 5}, {100, 0}});
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->length(), b->length());
}

TEST(OpenReferenceLineTest, BadPolylinesFailNamingTheProblem) {
  const ReferenceLine::Options o;
  const std::vector<Point> one = {{1, 1}, {1, 1}};
  auto r = ReferenceLine::FitOpen(one, o, "lane 7");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("lane 7"), std::string::npos) << r.message();
  EXPECT_NE(r.message().find("2 distinct points"), std::string::npos) << r.message();
  const std::vector<Point> nan = {{0, 0}, {NAN, 1}, {5, 0}};
  r = ReferenceLine::FitOpen(nan, o, "lane 8");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("point 1 is not finite"), std::string::npos) << r.message();
  const std::vector<Point> empty;
  EXPECT_FALSE(ReferenceLine::FitOpen(empty, o, "x").ok());
  // One point off by orders of magnitude (a mangled lanelet): refused before any sample is
  // taken (the fit took gigabytes and minutes), and a long road still fits.
  const std::vector<Point> far = {{0, 0}, {50, 0}, {100, 6.2e7}, {150, 0}};
  r = ReferenceLine::FitOpen(far, o, "lane 9");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("lane 9: the line is 124000 km long, more than the 200 km"),
            std::string::npos)
      << r.message();
  EXPECT_TRUE(ReferenceLine::FitOpen(std::vector<Point>{{0, 0}, {20000, 0}}, o, "20 km").ok());
}

TEST(OpenReferenceLineTest, NonFiniteQueriesAreSafe) {
  const auto line = FitOrDie({{0, 0}, {100, 0}});
  ASSERT_NE(line, nullptr);
  const FrenetPoint f = line->ToFrenet(NAN, 1);
  EXPECT_EQ(f.s, 0);
  const CartesianPose p = line->ToCartesian(NAN, NAN);
  EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
  const FrenetPoint g = line->ToFrenet(50, 1, NAN);
  EXPECT_NEAR(g.s, 50, 1e-4);
}

}  // namespace
}  // namespace frenetic::map

// FrenetGoals: a planning problem's goal states as regions of the road's Frenet frame, on
// hand-made scenarios.
#include "frenetic/commonroad/goal_frenet.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/road_builder.h"

namespace frenetic::commonroad {
namespace {

using testing::AddStraightRoad;
using testing::AddZipperMerge;
using testing::GoalLaneletXml;
using testing::GoalRectangleXml;
using testing::ScenarioXml;

struct Built {
  Scenario sc;
  BuiltRoad road;
  std::vector<FrenetGoal> goals;
};

Built Build(const ScenarioXml& xml) {
  Built b;
  auto sc = ParseScenario(xml.Str(), "test.xml");
  EXPECT_TRUE(sc.ok()) << sc.message();
  if (!sc.ok()) return b;
  b.sc = *sc;
  auto road = BuildRoad(b.sc, b.sc.problems.at(0));
  EXPECT_TRUE(road.ok()) << road.message();
  if (!road.ok()) return b;
  b.road = *road;
  b.goals = FrenetGoals(b.sc, b.sc.problems.at(0), b.road.road->line());
  return b;
}

// Region r's d span at s.
std::pair<double, double> SpanAt(const cost::GoalRegion& r, double s) {
  const double off = r.d_slope * (s - r.s_ref);
  return {r.d_lo + off, r.d_hi + off};
}

TEST(GoalFrenetTest, AGoalLaneletIsABandInsideItsBordersWhereTheLineBendsOffThem) {
  // The ego starts in lanelet 25; lanelet 26 beside it (y in [3.5, 7], three points a border)
  // is the goal. The reference line follows 25 into the merge (28) and bends off the straight
  // borders before it. Its corners' box
  // would reach outside the lanelet mid-way; the band is inside it at every x.
  ScenarioXml xml;
  AddZipperMerge(xml).Problem(1, {-120, 8.75}, 0, 8, {GoalLaneletXml(26, 84, 85)});
  const Built b = Build(xml);
  ASSERT_NE(b.road.road, nullptr);
  ASSERT_EQ(b.goals.size(), 1u);
  const cost::GoalRegion& r = b.goals[0].region;
  EXPECT_DOUBLE_EQ(r.t_lo, 84);
  EXPECT_DOUBLE_EQ(r.t_hi, 85);
  const map::ReferenceLine& line = b.road.road->line();
  EXPECT_NEAR(r.s_lo, line.ToFrenet(-180, 5.25).s, 2.0);
  EXPECT_NEAR(r.s_hi, line.ToFrenet(-20, 5.25).s, 2.0);
  double narrowest = 1e9;
  for (double x = -178; x <= -22; x += 1.0) {
    const map::FrenetPoint left = line.ToFrenet(x, 7.0), right = line.ToFrenet(x, 3.5);
    const auto [lo, hi] = SpanAt(r, left.s);
    EXPECT_GE(lo, left.d - 0.005) << "x " << x;  // (the stations are 2 m apart)
    EXPECT_LE(SpanAt(r, right.s).second, right.d + 0.005) << "x " << x;
    narrowest = std::min(narrowest, hi - lo);
  }
  // Narrower than the lanelet by the line's bend (it rings +-0.4 m about the lanelet's centre
  // before the junction) at most.
  EXPECT_GT(narrowest, 2.5);
  EXPECT_LE(narrowest, 3.5 + 1e-6);
}

TEST(GoalFrenetTest, AGoalLaneletAlongTheLineIsItsWholeWidth) {
  // Lanelet 2 (y in [0, 3.5]) beside the reference (lanelet 1's centre, y = -1.75): d in
  // [-5.25, -1.75] along its whole length.
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, 0, 100)});
  const Built b = Build(xml);
  ASSERT_EQ(b.goals.size(), 1u);
  const cost::GoalRegion& r = b.goals[0].region;
  EXPECT_NEAR(r.d_slope, 0.0, 1e-3);
  EXPECT_NEAR(r.d_lo, -5.25, 0.01);
  EXPECT_NEAR(r.d_hi, -1.75, 0.01);
  EXPECT_NEAR(r.s_lo, 0, 0.5);
  EXPECT_NEAR(r.s_hi, 300, 0.5);
}

// A two-lane straight road, the ego starting in the right lane at x = 10, the goal a 10 m
// rectangle in the left lane at x = 200.
Built StraightRoadWithGoalAhead() {
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(1, {10, -1.75}, 0, 20,
                                    {GoalRectangleXml({200, 1.75}, 10, 3, 0, 0, 100)});
  return Build(xml);
}

TEST(GoalFrenetTest, ARectangleAlongTheRoadKeepsItsWidthAndInsetStaysInside) {
  const Built b = StraightRoadWithGoalAhead();
  ASSERT_EQ(b.goals.size(), 1u);
  const cost::GoalRegion& r = b.goals[0].region;
  EXPECT_NEAR(r.s_lo, 195, 0.1);
  EXPECT_NEAR(r.s_hi, 205, 0.1);
  EXPECT_NEAR(r.d_lo, -5.0, 0.01);
  EXPECT_NEAR(r.d_hi, -2.0, 0.01);
  const cost::GoalRegion in = Inset(r);
  EXPECT_NEAR(in.s_lo, 196, 0.1);   // kInsetS
  EXPECT_NEAR(in.d_lo, -4.8, 0.01);  // kInsetD
  EXPECT_NEAR(in.d_hi, -2.2, 0.01);
  EXPECT_FALSE(PassedEveryGoal(b.goals, 205));
  EXPECT_TRUE(PassedEveryGoal(b.goals, 205 + kPassedMargin + 0.1));
}

TEST(GoalFrenetTest, ARegionOnAPlainRoadIsOpenAcrossAndOnePastAMergeIsNot) {
  // Two lanes side by side from the start to past the region: a path in the other lane may
  // still move across to it after its samples.
  const Built a = StraightRoadWithGoalAhead();
  ASSERT_EQ(a.goals.size(), 1u);
  const double start_a = a.road.road->line().ToFrenet(10, -1.75).s;
  EXPECT_TRUE(AcrossOpen(*a.road.road, start_a, a.goals[0].region));
  cost::GoalRegion endless = a.goals[0].region;  // a region with no far end: nothing is known
  endless.s_hi = cost::GoalRegion::kInf;
  EXPECT_FALSE(AcrossOpen(*a.road.road, start_a, endless));

  // A zipper merge: the left lane ends before the region, which lies on the lane both join.
  ScenarioXml zip;
  AddZipperMerge(zip).Problem(1, {-120, 8.75}, 0, 8,
                              {GoalRectangleXml({100, 5.25}, 10, 3, 0, 0, 100)});
  const Built b = Build(zip);
  ASSERT_EQ(b.goals.size(), 1u);
  ASSERT_GT(b.road.road->num_lanes(), 1);
  const double start_b = b.road.road->line().ToFrenet(-120, 8.75).s;
  EXPECT_FALSE(AcrossOpen(*b.road.road, start_b, b.goals[0].region));
}

}  // namespace
}  // namespace frenetic::commonroad

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/cost.h"

namespace frenetic::commonroad {
namespace {

using ::testing::HasSubstr;
using testing::AddStraightRoad;
using testing::GoalTimeOnlyXml;
using testing::IntervalXml;
using testing::ScenarioXml;

TEST(SimpsonTest, MatchesScipySimpsWithEvenAvg) {
  // Odd sample counts: Simpson's rule, exact for cubics.
  std::vector<double> cube;
  for (int i = 0; i <= 10; ++i) cube.push_back(std::pow(0.3 * i, 3));
  EXPECT_NEAR(Simpson(cube, 0.3), std::pow(3.0, 4) / 4, 1e-12);
  // Even counts: scipy.integrate.simps([0, 1, 4, 9], dx=1) == 9.1666...
  EXPECT_NEAR(Simpson(std::vector<double>{0, 1, 4, 9}, 1), 55.0 / 6, 1e-12);
  EXPECT_NEAR(Simpson(std::vector<double>{1, 3}, 0.5), 1.0, 1e-12);  // a trapezoid
  EXPECT_EQ(Simpson(std::vector<double>{5}, 0.1), 0);
  EXPECT_EQ(Simpson({}, 0.1), 0);
}

Scenario Straight(const std::string& goal_extra = "", bool obstacles = false) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  if (obstacles) {
    xml.StaticObstacle(40, 4, 2, {150, -1.75}, 0);   // ahead in the ego's lane
    xml.StaticObstacle(41, 4, 2, {120, 1.75}, 0);    // the other lane: ignored
    xml.StaticObstacle(42, 4, 2, {5, -1.75}, 0);     // behind: ignored
  }
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 40, goal_extra)});
  StatusOr<Scenario> s = ParseScenario(xml.Str(), "cost.xml");
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(s).value();
}

std::vector<KsState> Cruise(int steps, double y, double v0, double a) {
  std::vector<KsState> out;
  double x = 10, v = v0;
  for (int k = 0; k <= steps; ++k) {
    KsState s;
    s.time_step = k;
    s.x = x;
    s.y = y;
    s.velocity = v;
    out.push_back(s);
    x += v * 0.1 + 0.5 * a * 0.01;
    v += a * 0.1;
  }
  return out;
}

TEST(CostTest, JB1IsTheDuration) {
  const Scenario s = Straight();
  const StatusOr<CostReport> c =
      EvaluateCost("JB1", s, s.problems[0], VehicleParams(), Cruise(30, -1.75, 20, 0));
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_EQ(c->cost_function, "JB1");
  EXPECT_NEAR(c->total, 3.0, 1e-12);
  ASSERT_EQ(c->terms.size(), 1u);
  EXPECT_EQ(c->terms[0].name, "T");
}

TEST(CostTest, WX1OfASteadyRunOnTheLaneCentreIsTenTimesItsDuration) {
  const Scenario s = Straight();
  const StatusOr<CostReport> c =
      EvaluateCost("WX1", s, s.problems[0], VehicleParams(), Cruise(30, -1.75, 20, 0));
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_NEAR(c->total, 30.0, 1e-9);
  std::vector<std::string> names;
  for (const CostTerm& t : c->terms) names.push_back(t.name);
  EXPECT_THAT(names, ::testing::ElementsAre("T", "V", "A", "J", "D", "L"));
  EXPECT_DOUBLE_EQ(c->terms[5].weight, 10.0);  // L: the lane-centre offset, weight 10
  EXPECT_NEAR(c->partials.path_length, 20 * 3.0, 1e-9);
}

TEST(CostTest, VelocityOffsetToTheLowestGoalVelocity) {
  const Scenario s = Straight(IntervalXml("velocity", 25, 30));
  const StatusOr<CostReport> c =
      EvaluateCost("WX1", s, s.problems[0], VehicleParams(), Cruise(30, -1.75, 20, 0));
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_NEAR(c->partials.velocity_offset, 25.0 * 3.0, 1e-9);  // (25 - 20)^2 over 3 s
  EXPECT_NEAR(c->total, 30 + 75, 1e-9);
}

TEST(CostTest, AccelerationAndJerk) {
  const Scenario s = Straight();
  const PartialCosts p =
      ComputePartialCosts(s, s.problems[0], VehicleParams(), Cruise(30, -1.75, 10, 2));
  // a = 2 at 30 differences: 4 over 29 intervals of 0.1 s.
  EXPECT_NEAR(p.acceleration, 4 * 2.9, 1e-9);
  EXPECT_NEAR(p.jerk, 0, 1e-9);
  EXPECT_NEAR(p.time, 3.0, 1e-12);
}

TEST(CostTest, LaneCentreOffset) {
  const Scenario s = Straight();
  const PartialCosts p =
      ComputePartialCosts(s, s.problems[0], VehicleParams(), Cruise(30, -1.25, 20, 0));
  EXPECT_NEAR(p.lane_center_offset, 0.25 * 3.0, 1e-9);  // 0.5 m left of the centre, 3 s
  EXPECT_NEAR(p.orientation_offset, 0, 1e-12);
}

TEST(CostTest, DistanceToTheObstacleAheadInTheLane) {
  const Scenario s = Straight("", /*obstacles=*/true);
  const std::vector<KsState> run = Cruise(60, -1.75, 20, 0);
  const PartialCosts p = ComputePartialCosts(s, s.problems[0], VehicleParams(), run);
  // Obstacle 40 counts once within 100 m in x (x >= 50); its centre is 150 - x ahead, less the
  // ego radius w / 2.5.
  std::vector<double> expected;
  for (const KsState& st : run) {
    const double gap = 150 - st.x - 1.61 / 2.5;
    expected.push_back(150 - st.x <= 100 ? std::exp(-0.1 * gap) : 0.0);
  }
  EXPECT_NEAR(p.distance_to_obstacles, Simpson(expected, 0.1), 1e-9);
  EXPECT_GT(p.distance_to_obstacles, 0.05);
}

TEST(CostTest, UnknownCostFunctionsAndEmptyTrajectoriesAreErrors) {
  const Scenario s = Straight();
  StatusOr<CostReport> c = EvaluateCost("SM1", s, s.problems[0], VehicleParams(), Cruise(3, -1.75, 20, 0));
  ASSERT_FALSE(c.ok());
  EXPECT_THAT(c.message(), HasSubstr("'SM1' is not implemented"));
  c = EvaluateCost("WX1", s, s.problems[0], VehicleParams(), {});
  EXPECT_FALSE(c.ok());
}

}  // namespace
}  // namespace frenetic::commonroad

#include "frenetic/commonroad/verdict.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <numbers>

#include "commonroad/scenario_xml.h"

namespace frenetic::commonroad {
namespace {

using ::testing::HasSubstr;
using testing::AddCurvedRoad;
using testing::AddStraightRoad;
using testing::GoalLaneletXml;
using testing::GoalRectangleXml;
using testing::GoalTimeOnlyXml;
using testing::IntervalXml;
using testing::Lane;
using testing::LaneletXml;
using testing::Line;
using testing::Parse;
using testing::ScenarioXml;

constexpr double kDt = 0.1;

// KS states from `start` under the inputs, one per step.
std::vector<KsState> Simulate(const KsState& start, const std::vector<KsInput>& inputs, double dt,
                              const VehicleParams& p) {
  std::vector<KsState> out{start};
  for (const KsInput& u : inputs) out.push_back(SimulateKs(out.back(), u, dt, p, 20));
  return out;
}

KsState Start(double x, double y, double v, double psi = 0, double delta = 0) {
  KsState s;
  s.x = x;
  s.y = y;
  s.velocity = v;
  s.orientation = psi;
  s.steering_angle = delta;
  return s;
}

// `steps` steps of constant input from `start`.
std::vector<KsState> Drive(const KsState& start, int steps, KsInput u = {},
                           const VehicleParams& p = {}) {
  return Simulate(start, std::vector<KsInput>(steps, u), kDt, p);
}

// Two lanes along +x; the ego in the right lane at x = 10, 20 m/s.
ScenarioXml StraightXml(const std::vector<std::string>& goals) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Problem(100, {10, -1.75}, 0, 20, goals);
  return xml;
}

TEST(VerdictTest, ACleanRunAlongTheLaneSolvesALaneletGoal) {
  const Scenario s = Parse(StraightXml({GoalLaneletXml(1, 20, 40)}));
  const std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 40);
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  EXPECT_TRUE(v.solved) << v.Summary();
  ASSERT_TRUE(v.goal_step.has_value());
  EXPECT_EQ(*v.goal_step, 20);  // on lanelet 1 all along; the window opens at 20
  EXPECT_TRUE(v.failures.empty());
  EXPECT_EQ(v.problem_id, 100);
  EXPECT_EQ(v.Summary(), "solved: goal at step 20");
}

TEST(VerdictTest, AGoalOnAnotherLaneletIsNotMet) {
  const Scenario s = Parse(StraightXml({GoalLaneletXml(2, 20, 40)}));
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 40));
  EXPECT_FALSE(v.solved);
  ASSERT_EQ(v.failures.size(), 1u) << v.Summary();
  EXPECT_EQ(v.failures[0].kind, FailureKind::kGoal);
  EXPECT_EQ(v.failures[0].step, 40);  // the last step
  EXPECT_THAT(v.failures[0].detail, HasSubstr("outside the region"));
}

TEST(VerdictTest, GoalByRectangleIsMetAtTheFirstStepInside) {
  const Scenario s = Parse(StraightXml({GoalRectangleXml({150, -1.75}, 10, 3.5, 0, 0, 100)}));
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 70));
  EXPECT_TRUE(v.solved) << v.Summary();
  EXPECT_EQ(v.goal_step, 68);  // x = 10 + 2 k reaches 145 at k = 67.5
}

TEST(VerdictTest, GoalByTimeOnly) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(30, 30)}));
  const std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 40);
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  EXPECT_TRUE(v.solved) << v.Summary();
  EXPECT_EQ(v.goal_step, 30);
  // A trajectory that ends before the window.
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), std::span(traj).first(25));
  EXPECT_FALSE(v.solved);
  ASSERT_NE(v.Find(FailureKind::kGoal), nullptr);
  EXPECT_THAT(v.Find(FailureKind::kGoal)->detail, HasSubstr("time not in [30, 30]"));
}

TEST(VerdictTest, GoalVelocityAndOrientationIntervals) {
  // Orientation compared modulo 2 pi: [2 pi - 0.1, 2 pi + 0.1] holds heading 0.
  const double two_pi = 2 * std::numbers::pi;
  Scenario s = Parse(StraightXml(
      {GoalTimeOnlyXml(10, 20, IntervalXml("orientation", two_pi - 0.1, two_pi + 0.1))}));
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 20));
  EXPECT_TRUE(v.solved) << v.Summary();
  EXPECT_EQ(v.goal_step, 10);

  s = Parse(StraightXml({GoalTimeOnlyXml(10, 20, IntervalXml("velocity", 25, 30))}));
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 20));
  EXPECT_FALSE(v.solved);
  ASSERT_NE(v.Find(FailureKind::kGoal), nullptr);
  EXPECT_THAT(v.Find(FailureKind::kGoal)->detail,
              HasSubstr("velocity 20.00 m/s not in [25.00, 30.00]"));

  // Any one goal state suffices.
  s = Parse(StraightXml({GoalTimeOnlyXml(10, 20, IntervalXml("velocity", 25, 30)),
                         GoalTimeOnlyXml(15, 20, IntervalXml("velocity", 19, 21))}));
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 20));
  EXPECT_TRUE(v.solved) << v.Summary();
  EXPECT_EQ(v.goal_step, 15);
}

TEST(VerdictTest, CollisionWithAStaticObstacleInTheLane) {
  ScenarioXml xml = StraightXml({GoalTimeOnlyXml(20, 60)});
  xml.StaticObstacle(30, 4, 2, {100, -1.75}, 0);
  const Scenario s = Parse(xml);
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 50));
  EXPECT_FALSE(v.solved);
  ASSERT_EQ(v.failures.size(), 1u) << v.Summary();
  EXPECT_EQ(v.failures[0].kind, FailureKind::kCollision);
  // The ego's front (x + 4.508 / 2) reaches the obstacle's rear (98) at x = 95.746: k = 43.
  EXPECT_EQ(v.failures[0].step, 43);
  EXPECT_EQ(v.failures[0].obstacle_id, 30);
  EXPECT_THAT(v.failures[0].detail, HasSubstr("obstacle 30 (parkedVehicle)"));
  // Where the ego first saw it: at its start, centre to centre along its heading.
  EXPECT_THAT(v.failures[0].detail,
              HasSubstr("in the scene from the start, 90.0 m ahead of the ego then"));
  EXPECT_TRUE(v.goal_step.has_value());  // reached, but the collision fails it
}

// The collision of the ego driving 20 m/s along the right lane from x = 10 for 25 steps with a
// car at x = x_at(k) from step `enter` on (none: no collision).
std::optional<Failure> HitByACarFrom(int enter, const std::function<double(int)>& x_at, double v) {
  std::vector<testing::StateXml> car;
  for (int k = enter; k <= 30; ++k) car.push_back({k, {x_at(k), -1.75}, 0.0, v});
  ScenarioXml xml;
  AddStraightRoad(xml, 300)
      .DynamicObstacle(9, 4.5, 1.8, car)
      .Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(20, 30)});
  const Scenario s = Parse(xml);
  const Verdict verdict =
      CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 25));
  const Failure* hit = verdict.Find(FailureKind::kCollision);
  if (hit == nullptr) return std::nullopt;
  return *hit;
}

TEST(VerdictTest, ACollisionNamesWhereTheCarCameIntoTheScene) {
  // A car that enters the scene (a recording's view) at step `enter`, 8 m behind the ego in its
  // lane, closing at 20 m/s: it hits the ego within half a second, whatever was seen before.
  for (const int enter : {0, 5}) {
    const std::optional<Failure> hit = HitByACarFrom(
        enter, [enter](int k) { return 10 + 2.0 * enter - 8 + 4.0 * (k - enter); }, 40);
    ASSERT_TRUE(hit.has_value()) << enter;
    EXPECT_EQ(hit->obstacle_id, 9);
    // Bumpers 8 - 4.5 / 2 - 4.508 / 2 = 3.5 m apart, closing at 20 m/s: contact within 0.2 s.
    EXPECT_LE(hit->step, enter + 2);
    EXPECT_THAT(hit->detail,
                HasSubstr(enter == 0 ? "in the scene from the start, 8.0 m behind the ego then"
                                     : "in the scene from step 5, 8.0 m behind the ego then"))
        << hit->detail;
    // How long before the hit it came in: none when it was there from the start.
    if (enter == 0) {
      EXPECT_FALSE(hit->entered_s.has_value());
    } else {
      ASSERT_TRUE(hit->entered_s.has_value());
      EXPECT_NEAR(*hit->entered_s, (hit->step - enter) * kDt, 1e-9);
    }
  }
  // A car that appears on the ego at step 5: it hits there, 0 s after it came in, beside it.
  const std::optional<Failure> hit = HitByACarFrom(
      5, [](int k) { return 10 + 2.0 * k; }, 20);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->step, 5);
  EXPECT_THAT(hit->detail, HasSubstr("in the scene from step 5, beside the ego then"));
  ASSERT_TRUE(hit->entered_s.has_value());
  EXPECT_EQ(*hit->entered_s, 0.0);
}

TEST(VerdictTest, PassingBesideAnObstacleIsNoCollision) {
  ScenarioXml xml = StraightXml({GoalTimeOnlyXml(20, 60)});
  xml.StaticObstacle(30, 4, 2, {100, 1.75}, 0);  // in the other lane
  const Scenario s = Parse(xml);
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 50));
  EXPECT_TRUE(v.solved) << v.Summary();
}

TEST(VerdictTest, ADynamicObstacleIsGoneAfterItsTrajectory) {
  // A car standing at x = 60 in the ego's lane until step `until`.
  const auto scenario = [](int until) {
    ScenarioXml xml = StraightXml({GoalTimeOnlyXml(20, 40)});
    std::vector<testing::StateXml> states;
    for (int t = 0; t <= until; ++t) states.push_back({t, {60, -1.75}, 0, 0});
    xml.DynamicObstacle(31, 4.5, 1.8, states);
    return Parse(xml);
  };
  const std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 40);
  // Front 10 + 2k + 2.254 reaches the car's rear 57.75 at k = 22.7.
  Scenario s = scenario(10);
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  EXPECT_TRUE(v.solved) << v.Summary();
  s = scenario(30);
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  ASSERT_NE(v.Find(FailureKind::kCollision), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kCollision)->step, 23);
}

// The first step at which the box's top edge is above y_max + tolerance.
int FirstStepAbove(const std::vector<KsState>& traj, double y_max, const VehicleParams& p) {
  for (const KsState& s : traj) {
    const auto c = BoxCorners({s.x, s.y}, s.orientation, p.length, p.width);
    const double top = std::max({c[0].y, c[1].y, c[2].y, c[3].y});
    if (top > y_max + RoadArea::kDefaultTolerance) return s.time_step;
  }
  return -1;
}

TEST(VerdictTest, LeavingTheRoadIsNamedWithItsStep) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(5, 60)}));
  const VehicleParams p;
  // Steer left for 0.5 s, then hold: across the left lane and off the road's left edge.
  std::vector<KsInput> inputs(5, KsInput{0.1, 0});
  inputs.resize(60, KsInput{0, 0});
  const std::vector<KsState> traj = Simulate(Start(10, -1.75, 20), inputs, kDt, p);
  const Verdict v = CheckTrajectory(s, s.problems[0], p, traj);
  EXPECT_FALSE(v.solved);
  ASSERT_EQ(v.failures.size(), 1u) << v.Summary();
  EXPECT_EQ(v.failures[0].kind, FailureKind::kOffRoad);
  const int expected = FirstStepAbove(traj, 3.5, p);
  ASSERT_GT(expected, 0);
  EXPECT_EQ(v.failures[0].step, expected);
}

TEST(VerdictTest, AnOncomingLaneletIsRoad) {
  ScenarioXml xml;
  LaneletXml right = Lane(1, Line(0, 300, 0), Line(0, 300, -3.5));
  right.adjacent_left = {{2, false}};
  std::vector<Vec2> left = Line(0, 300, 0), rightb = Line(0, 300, 3.5);
  std::reverse(left.begin(), left.end());
  std::reverse(rightb.begin(), rightb.end());
  LaneletXml oncoming = Lane(2, left, rightb);  // bounds run from x = 300 to 0
  oncoming.adjacent_left = {{1, false}};
  xml.Lanelet(right).Lanelet(oncoming);
  xml.Problem(100, {10, 1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  // Driving the wrong way in the oncoming lane: still on the road.
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, 1.75, 20), 20));
  EXPECT_TRUE(v.solved) << v.Summary();
}

TEST(VerdictTest, ALaneDropEndsTheRoad) {
  // The right lane narrows to nothing between x = 100 and 150; the left lane goes on.
  ScenarioXml xml;
  std::vector<Vec2> drop_right = Line(0, 100, -3.5);
  drop_right.push_back({125, -1.75});
  drop_right.push_back({150, 0});
  std::vector<Vec2> drop_left = Line(0, 100, 0);
  drop_left.push_back({125, 0});
  drop_left.push_back({150, 0});
  LaneletXml lane1 = Lane(1, drop_left, drop_right);
  lane1.adjacent_left = {{2, true}};
  LaneletXml lane2 = Lane(2, Line(0, 300, 3.5), Line(0, 300, 0));
  lane2.adjacent_right = {{1, true}};
  xml.Lanelet(lane1).Lanelet(lane2);
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 80)});
  const Scenario s = Parse(xml);
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 60));
  ASSERT_NE(v.Find(FailureKind::kOffRoad), nullptr) << v.Summary();
  // The box's bottom edge (y = -2.555) meets the narrowing bound (y = -3.5 + 3.5 (x - 100) / 50)
  // 2 cm deep at its front x + 2.254 = 113.79: x = 111.53, k = 51.
  EXPECT_EQ(v.Find(FailureKind::kOffRoad)->step, 51);
}

TEST(VerdictTest, FollowingACurvedLaneSolvesIt) {
  const VehicleParams p;
  const double radius = 100;
  ScenarioXml xml;
  AddCurvedRoad(xml, radius, 1.0);
  // Steady cornering keeps the centre (b ahead of the rear axle) on the lane's centre circle:
  // the rear axle runs on the circle of radius sqrt(R^2 - b^2) about the same point.
  const double r_rear = std::sqrt(radius * radius - p.b * p.b);
  const double psi0 = -std::atan(p.b / r_rear), delta = std::atan(p.Wheelbase() / r_rear);
  // From 5 m into the arc: the network's start is closed, the ego's rear must be on it.
  const double a = 5.0 / radius;
  const Vec2 at{radius * std::sin(a), radius - radius * std::cos(a)};
  xml.Problem(100, at, psi0 + a, 15, {GoalLaneletXml(1, 40, 50)});
  const Scenario s = Parse(xml);
  const std::vector<KsState> traj = Drive(Start(at.x, at.y, 15, psi0 + a, delta), 50);
  for (const KsState& st : traj) {
    EXPECT_NEAR(std::hypot(st.x, st.y - radius), radius, 1e-6);  // on the centre line
  }
  const Verdict v = CheckTrajectory(s, s.problems[0], p, traj);
  EXPECT_TRUE(v.solved) << v.Summary();
  EXPECT_EQ(v.goal_step, 40);
}

TEST(VerdictTest, AStartOnAnObstacleIsInfeasibleAtStart) {
  // The ego at 20 m/s, a parked car ahead in its lane, its centre `gap` m ahead of the ego's:
  //  - 3 m: the boxes overlap at step 0;
  //  - 6 m: 1.75 m between them; at full braking (11.5 m/s^2) the ego still moves 1.94 m in the
  //    0.1 s to step 1, and no steering moves it aside in that time: unavoidable at step 1;
  //  - 40 m: braking stops it in 17.4 m, so no collision is certain (the constant-speed run
  //    into it later is the trajectory's own collision).
  struct Case {
    double gap;
    int infeasible_step;  // -1: none
  };
  for (const Case& c : {Case{3.0, 0}, Case{6.0, 1}, Case{40.0, -1}}) {
    ScenarioXml xml;
    AddStraightRoad(xml, 300)
        .StaticObstacle(9, 4.0, 1.8, {10 + c.gap, -1.75}, 0)
        .Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
    const Scenario s = Parse(xml);
    const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 20));
    EXPECT_FALSE(v.solved);
    ASSERT_NE(v.Find(FailureKind::kCollision), nullptr) << v.Summary();
    if (c.infeasible_step >= 0) {
      ASSERT_TRUE(v.infeasible_at_start.has_value()) << c.gap << ": " << v.Summary();
      EXPECT_EQ(v.infeasible_at_start->kind, FailureKind::kCollision);
      EXPECT_EQ(v.infeasible_at_start->obstacle_id, 9);
      EXPECT_EQ(v.infeasible_at_start->step, c.infeasible_step) << c.gap;
      EXPECT_THAT(v.Summary(), HasSubstr("infeasible at start: collision at step " +
                                         std::to_string(c.infeasible_step)));
    } else {
      EXPECT_FALSE(v.infeasible_at_start.has_value()) << c.gap << ": " << v.Summary();
      EXPECT_GT(v.Find(FailureKind::kCollision)->step, 0);
    }
  }
}

TEST(VerdictTest, ACarFromBehindThatHitsAtOnceIsUnavoidable) {
  // A car 7 m behind (centre to centre: 2.5 m between the bumpers) in the ego's lane closes at
  // 40 m/s: it is into the ego's box at step 1 whatever the ego does. The same car in the next
  // lane (3.5 m over) passes by, and the same car 60 m back arrives after 1.5 s, when the ego can
  // be elsewhere: neither is certain.
  struct Case {
    double behind, y;
    bool unavoidable;
  };
  for (const Case& c : {Case{7, -1.75, true}, Case{7, 1.75, false}, Case{60, -1.75, false}}) {
    std::vector<testing::StateXml> car;
    for (int k = 0; k <= 30; ++k) car.push_back({k, {10 - c.behind + 60.0 * 0.1 * k, c.y}, 0.0, 60});
    ScenarioXml xml;
    AddStraightRoad(xml, 300)
        .DynamicObstacle(9, 4.5, 1.8, car)
        .Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
    const Scenario s = Parse(xml);
    const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20), 20));
    EXPECT_EQ(v.infeasible_at_start.has_value(), c.unavoidable)
        << c.behind << " m behind at y " << c.y << ": " << v.Summary();
    if (c.unavoidable) {
      EXPECT_EQ(v.infeasible_at_start->step, 1);
      EXPECT_THAT(v.infeasible_at_start->detail, HasSubstr("every state the vehicle can reach"));
    }
  }
}

TEST(VerdictTest, SteeringAngleBeyondItsLimit) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(10, 20)}));
  std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 20);
  traj[5].steering_angle = 1.2;
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  EXPECT_FALSE(v.solved);
  ASSERT_NE(v.Find(FailureKind::kSteeringAngle), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kSteeringAngle)->step, 5);
  EXPECT_THAT(v.Find(FailureKind::kSteeringAngle)->detail, HasSubstr("1.2000 rad"));
  // The jump to it and back is a steering rate failure too, from step 4.
  ASSERT_NE(v.Find(FailureKind::kSteeringRate), nullptr);
  EXPECT_EQ(v.Find(FailureKind::kSteeringRate)->step, 4);
}

TEST(VerdictTest, SteeringRateBeyondItsLimit) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(5, 20)}));
  VehicleParams fast;  // a car that may steer at 1 rad/s
  fast.steering_rate_max = 1.0;
  std::vector<KsInput> inputs(3, KsInput{0, 0});
  inputs.push_back({0.5, 0});  // at step 3
  inputs.push_back({-0.5, 0});
  inputs.resize(10, KsInput{0, 0});
  const std::vector<KsState> traj = Simulate(Start(10, -1.75, 20), inputs, kDt, fast);
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  ASSERT_NE(v.Find(FailureKind::kSteeringRate), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kSteeringRate)->step, 3);
  EXPECT_THAT(v.Find(FailureKind::kSteeringRate)->detail, HasSubstr("0.5000 rad/s"));
  // The same steering at 0.35 rad/s passes.
  inputs[3] = {0.35, 0};
  inputs[4] = {-0.35, 0};
  const Verdict ok = CheckTrajectory(s, s.problems[0], VehicleParams(),
                                     Simulate(Start(10, -1.75, 20), inputs, kDt, fast));
  EXPECT_TRUE(ok.solved) << ok.Summary();
}

TEST(VerdictTest, VelocityBeyondItsLimit) {
  ScenarioXml xml;
  AddStraightRoad(xml, 1000);
  xml.Problem(100, {10, -1.75}, 0, 52, {GoalTimeOnlyXml(5, 20)});
  const Scenario s = Parse(xml);
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 52), 10));
  ASSERT_EQ(v.failures.size(), 1u) << v.Summary();
  EXPECT_EQ(v.failures[0].kind, FailureKind::kVelocity);
  EXPECT_EQ(v.failures[0].step, 0);
}

TEST(VerdictTest, AccelerationFollowsTheSwitchingVelocityRule) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(1, 20)}));
  VehicleParams strong;  // generates accelerations the BMW cannot reach at speed
  strong.a_max = 30;
  // 5 m/s^2 at 20 m/s is above 11.5 * 7.319 / 20 = 4.21 m/s^2.
  std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 5, {0, 5}, strong);
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  ASSERT_NE(v.Find(FailureKind::kAcceleration), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kAcceleration)->step, 0);
  EXPECT_THAT(v.Find(FailureKind::kAcceleration)->detail, HasSubstr("4.208]"));
  // 4 m/s^2 at 20 m/s is within it.
  traj = Drive(Start(10, -1.75, 20), 2, {0, 4}, strong);
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  EXPECT_TRUE(v.solved) << v.Summary();
  // Braking at 11.6 m/s^2 is too much at any speed.
  traj = Drive(Start(10, -1.75, 20), 2, {0, -11.6}, strong);
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  ASSERT_NE(v.Find(FailureKind::kAcceleration), nullptr) << v.Summary();
}

TEST(VerdictTest, AccelerationBelowTheSwitchingVelocityMayReachAMax) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Problem(100, {10, -1.75}, 0, 2, {GoalTimeOnlyXml(1, 20)});
  const Scenario s = Parse(xml);
  // 10 m/s^2 from 2 m/s: 3 m/s, 4 m/s, ... below 7.319 m/s the limit is a_max.
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 2), 4, {0, 10}));
  EXPECT_TRUE(v.solved) << v.Summary();
}

TEST(VerdictTest, FrictionCircle) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Problem(100, {10, -1.75}, 0, 30, {GoalTimeOnlyXml(1, 20)});
  const Scenario s = Parse(xml);
  // 30 m/s with 0.05 rad of steering: 900 / 2.579 * tan(0.05) = 17.5 m/s^2 sideways.
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 30, 0, 0.05), 3));
  ASSERT_NE(v.Find(FailureKind::kFrictionCircle), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kFrictionCircle)->step, 0);
}

TEST(VerdictTest, AStateThatDoesNotFollowFromTheModel) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(5, 20)}));
  std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 20);
  std::vector<KsState> nudged = traj;
  nudged[10].y += 0.05;  // a 5 cm jump sideways
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), nudged);
  ASSERT_EQ(v.failures.size(), 1u) << v.Summary();
  EXPECT_EQ(v.failures[0].kind, FailureKind::kDynamics);
  EXPECT_EQ(v.failures[0].step, 9);
  EXPECT_THAT(v.failures[0].detail, HasSubstr("0.050 m (y)"));
  // 1.5 cm is within CommonRoad's 2 cm.
  nudged = traj;
  nudged[10].y += 0.015;
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), nudged);
  EXPECT_TRUE(v.solved) << v.Summary();
  // A heading jump.
  nudged = traj;
  nudged[12].orientation += 0.05;
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), nudged);
  ASSERT_NE(v.Find(FailureKind::kDynamics), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kDynamics)->step, 11);
}

TEST(VerdictTest, TheTrajectoryMustStartAtTheInitialState) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(5, 20)}));
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10.5, -1.75, 20), 20));
  ASSERT_NE(v.Find(FailureKind::kStart), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kStart)->step, 0);
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10.05, -1.75, 21.5), 20));
  EXPECT_TRUE(v.solved) << v.Summary();  // within 0.1 m and 2 m/s
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), Drive(Start(10, -1.75, 20, 0.2), 20));
  ASSERT_NE(v.Find(FailureKind::kStart), nullptr) << v.Summary();
  // A whole turn more is another orientation to the solution checker (np.allclose, unwrapped).
  std::vector<KsState> turned = Drive(Start(10, -1.75, 20), 20);
  for (KsState& st : turned) st.orientation += 2 * std::numbers::pi;
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), turned);
  ASSERT_NE(v.Find(FailureKind::kStart), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kDynamics), nullptr) << v.Summary();
}

TEST(VerdictTest, BrokenTrajectoriesAreNamedNotCrashedOn) {
  const Scenario s = Parse(StraightXml({GoalTimeOnlyXml(5, 20)}));
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), {});
  EXPECT_FALSE(v.solved);
  ASSERT_NE(v.Find(FailureKind::kTrajectory), nullptr);

  std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 20);
  traj[7].x = std::numeric_limits<double>::quiet_NaN();
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  ASSERT_NE(v.Find(FailureKind::kTrajectory), nullptr);
  EXPECT_EQ(v.Find(FailureKind::kTrajectory)->step, 7);
  // The rest is checked on the 7 good states: the goal window [5, 20] was open at 5.
  EXPECT_EQ(v.goal_step, 5);

  traj = Drive(Start(10, -1.75, 20), 20);
  traj[12].time_step = 14;
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  ASSERT_NE(v.Find(FailureKind::kTrajectory), nullptr);
  EXPECT_EQ(v.Find(FailureKind::kTrajectory)->step, 14);
  EXPECT_THAT(v.Find(FailureKind::kTrajectory)->detail, HasSubstr("follows step 11"));
}

TEST(VerdictTest, FailuresComeInKindOrderWithTheirFirstStep) {
  ScenarioXml xml = StraightXml({GoalTimeOnlyXml(100, 120)});
  xml.StaticObstacle(30, 4, 2, {60, -1.75}, 0);
  const Scenario s = Parse(xml);
  std::vector<KsState> traj = Drive(Start(10, -1.75, 20), 30);
  traj[3].steering_angle = 2;
  const Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), traj);
  std::vector<FailureKind> kinds;
  for (const Failure& f : v.failures) kinds.push_back(f.kind);
  EXPECT_THAT(kinds, ::testing::ElementsAre(FailureKind::kGoal, FailureKind::kCollision,
                                            FailureKind::kSteeringAngle,
                                            FailureKind::kSteeringRate, FailureKind::kFrictionCircle,
                                            FailureKind::kDynamics));
  EXPECT_THAT(v.Summary(), HasSubstr("failed: goal at step 30"));
  EXPECT_THAT(v.Summary(), HasSubstr("; collision at step 23 ("));
  EXPECT_STREQ(ToString(FailureKind::kOffRoad), "off_road");
}

TEST(VerdictTest, OptionsAreValidated) {
  VerdictOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.road_tolerance = -1;
  EXPECT_THAT(o.Validate().message(), HasSubstr("road_tolerance"));
  o = VerdictOptions();
  o.integration_substeps = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = VerdictOptions();
  o.position_tolerance = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(o.Validate().ok());
}

TEST(VerdictTest, MeetsGoalForARunner) {
  const Scenario s = Parse(StraightXml({GoalLaneletXml(1, 20, 40)}));
  KsState st = Start(50, -1.75, 20);
  st.time_step = 25;
  EXPECT_TRUE(MeetsGoal(s, s.problems[0].goals[0], st));
  st.time_step = 19;
  EXPECT_FALSE(MeetsGoal(s, s.problems[0].goals[0], st));
  st.time_step = 25;
  st.y = 1.75;
  EXPECT_FALSE(MeetsGoal(s, s.problems[0].goals[0], st));
}

// The examples: a straight constant-speed run from each initial state is checked without trouble
// (start and dynamics hold; what else fails depends on the scene).
TEST(VerdictTest, SharedExamplesCheckAStraightRun) {
  const std::string dir = std::string(FRENETIC_SHARED_DIR "/commonroad");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) GTEST_SKIP() << dir << " absent";
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".xml") continue;
    const StatusOr<Scenario> s = LoadScenario(e.path().string());
    ASSERT_TRUE(s.ok()) << s.message();
    const VerdictChecker checker(*s, VehicleParams());
    for (const PlanningProblem& p : s->problems) {
      const KsState start = Start(p.initial.position.x, p.initial.position.y,
                                  *p.initial.velocity, *p.initial.orientation);
      const Verdict v = checker.Check(p, Drive(start, 80));
      EXPECT_EQ(v.Find(FailureKind::kStart), nullptr) << e.path() << ": " << v.Summary();
      EXPECT_EQ(v.Find(FailureKind::kDynamics), nullptr) << e.path() << ": " << v.Summary();
      EXPECT_EQ(v.Find(FailureKind::kTrajectory), nullptr) << e.path() << ": " << v.Summary();
      // The ego's box at the initial state is on the road, or the problem is infeasible at
      // start for it (ZAM_Ramp: its rear past the network's closed start).
      const Failure* off = v.Find(FailureKind::kOffRoad);
      const bool off_at_start = off != nullptr && off->step == p.initial.time_step;
      EXPECT_EQ(off_at_start, v.infeasible_at_start.has_value() &&
                                  v.infeasible_at_start->kind == FailureKind::kOffRoad)
          << e.path() << ": " << v.Summary();
    }
    ++files;
  }
  EXPECT_GT(files, 0);
}

}  // namespace
}  // namespace frenetic::commonroad

// RunScenario: closed-loop planning through hand-made CommonRoad scenarios (written by the tests)
// and every shared example, judged by the verdict.
#include "frenetic/commonroad/runner.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "commonroad/scenario_xml.h"

namespace frenetic::commonroad {
namespace {

using testing::AddCurvedRoad;
using testing::AddSplitExit;
using testing::AddStraightRoad;
using testing::AddTwoWayRoad;
using testing::GoalLaneletXml;
using testing::GoalRectangleXml;
using testing::GoalTimeOnlyXml;
using testing::IntervalXml;
using testing::Lane;
using testing::LaneletXml;
using testing::Line;
using testing::ScenarioXml;
using testing::StateXml;

plan::PlannerConfig Config(PredictionMode mode = PredictionMode::kRecorded) {
  auto base = plan::PlannerConfig::LoadDefault();
  EXPECT_TRUE(base.ok()) << base.message();
  EXPECT_TRUE(base->OverlayFile(std::string(FRENETIC_SOURCE_DIR "/") + kCommonRoadConfig).ok());
  auto c = CommonRoadConfig(*base, VehicleParams(), mode);
  EXPECT_TRUE(c.ok()) << c.message();
  return *c;
}

ProblemRun RunOne(const ScenarioXml& xml, PredictionMode mode = PredictionMode::kRecorded,
                  const plan::PlannerConfig* config = nullptr, bool rescue = true) {
  if (const char* dump = std::getenv("FRENETIC_TEST_DUMP"); dump != nullptr) {
    std::ofstream(dump) << xml.Str();
  }
  auto sc = ParseScenario(xml.Str(), "test.xml");
  EXPECT_TRUE(sc.ok()) << sc.message();
  RunOptions o;
  o.prediction = mode;
  o.timing = false;
  o.rescue = rescue;
  const ScenarioRun run = RunScenario(*sc, config != nullptr ? *config : Config(mode), o);
  EXPECT_EQ(run.problems.size(), 1u);
  return run.problems.empty() ? ProblemRun{} : run.problems[0];
}

// A car on lane y at constant speed v from x0, `steps` states.
std::vector<StateXml> Drive(double x0, double y, double v, int steps) {
  std::vector<StateXml> s;
  for (int k = 0; k <= steps; ++k) s.push_back({k, {x0 + v * 0.1 * k, y}, 0.0, v});
  return s;
}

TEST(RunnerTest, ReachesARectangleAheadInTime) {
  ScenarioXml xml;
  AddStraightRoad(xml, 400).Problem(1, {10, -1.75}, 0, 20,
                                    {GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90)});
  const ProblemRun p = RunOne(xml);
  ASSERT_TRUE(p.road.ok()) << p.road.message();
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  EXPECT_EQ(p.stop_reason, "goal");
  ASSERT_TRUE(p.verdict.goal_step.has_value());
  EXPECT_GE(*p.verdict.goal_step, 50);
  // One state per step from the initial one, the last where the goal was met.
  EXPECT_EQ(static_cast<int>(p.trajectory.size()), *p.verdict.goal_step + 1);
  EXPECT_EQ(p.trajectory.size(), p.cycles.size() + 1);
}

// Each cycle's planning time holds the rescue's checks (it checks every path, and searches when
// one hits): a part of it, measured apart; without timing both read 0.
TEST(RunnerTest, EachCycleTimesTheRescueAsAPartOfItsPlanningTime) {
  ScenarioXml xml;
  AddStraightRoad(xml, 400)
      .DynamicObstacle(5, 4.8, 2, Drive(40, -1.75, 8, 80))
      .Problem(1, {10, -1.75}, 0, 20, {GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90)});
  auto sc = ParseScenario(xml.Str(), "test.xml");
  ASSERT_TRUE(sc.ok()) << sc.message();
  for (const bool timing : {true, false}) {
    RunOptions o;
    o.timing = timing;
    const ScenarioRun run = RunScenario(*sc, Config(PredictionMode::kRecorded), o);
    ASSERT_EQ(run.problems.size(), 1u);
    const std::vector<RunCycle>& cycles = run.problems[0].cycles;
    ASSERT_GT(cycles.size(), 20u);
    int rescue_timed = 0;
    for (const RunCycle& c : cycles) {
      EXPECT_GE(c.rescue_ms, 0) << c.step;
      EXPECT_LE(c.rescue_ms, c.plan_ms) << c.step;
      rescue_timed += c.rescue_ms > 0;
      if (!timing) {
        EXPECT_EQ(c.plan_ms, 0) << c.step;
      }
    }
    if (timing) {
      EXPECT_EQ(rescue_timed, static_cast<int>(cycles.size()));
    } else {
      EXPECT_EQ(rescue_timed, 0);
    }
  }
}

TEST(RunnerTest, ReachesARectangleInAFileFarFromItsOrigin) {
  // ReachesARectangleAheadInTime with every position in map-projection coordinates: read into
  // a local frame (the planner's input bounds and the reference line's fit would not take
  // millions of metres), solved the same way.
  const Vec2 far{612345.0, 5432100.0};
  ScenarioXml xml;
  testing::AddStraightRoadAt(xml, far, 400)
      .Problem(1, far + Vec2{10, -1.75}, 0, 20,
               {GoalRectangleXml(far + Vec2{150, -1.75}, 10, 3, 0, 50, 90)});
  const ProblemRun p = RunOne(xml);
  ASSERT_TRUE(p.road.ok()) << p.road.message();
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  EXPECT_EQ(p.stop_reason, "goal");
}

TEST(RunnerTest, ChangesLanesPastASlowCarIntoAGoalLanelet) {
  // A slow car 30 m ahead in the ego's lane; the goal is the left lane (lanelet 2).
  ScenarioXml xml;
  AddStraightRoad(xml, 500)
      .DynamicObstacle(5, 4.8, 2, Drive(40, -1.75, 8, 80))
      .Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, 40, 80)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
}

// Two lanelets side by side that are not adjacent, their shared line 5 mm apart from x = 20 to
// 120 m: CommonRoad's solution checker counts that sliver as road boundary (RoadArea), so a lane
// change into the goal lanelet must cross the line where it is one line, past x = 120 m.
TEST(RunnerTest, ChangesLanesOnlyWhereTheLanesTouch) {
  std::vector<Vec2> lane1_left = Line(0, 400, 0);
  for (Vec2& p : lane1_left) {
    if (p.x > 20 && p.x < 120) p.y = -0.005;
  }
  ScenarioXml xml;
  xml.Lanelet(Lane(1, lane1_left, Line(0, 400, -3.5)))
      .Lanelet(Lane(2, Line(0, 400, 3.5), Line(0, 400, 0)))
      .Problem(1, {10, -1.75}, 0, 15, {GoalLaneletXml(2, 20, 100)});
  auto sc = ParseScenario(xml.Str(), "test.xml");
  ASSERT_TRUE(sc.ok()) << sc.message();
  const VerdictChecker checker(*sc, VehicleParams());
  ASSERT_EQ(checker.road().HoleCount(), 1);
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  // No state's box reaches across the line before x = 120 m (the sliver's end).
  for (const KsState& s : p.trajectory) {
    const auto box =
        BoxCorners({s.x, s.y}, s.orientation, VehicleParams().length, VehicleParams().width);
    const bool across = std::any_of(box.begin(), box.end(), [](Vec2 c) { return c.y > -0.005; });
    if (across) {
      EXPECT_GE(s.x, 120.0 - 0.5 * VehicleParams().length) << "step " << s.time_step;
    }
  }
}

// A file's own step size: the same scene in seconds at 0.1 s, at 0.05 s (2.5 of the planner's
// 0.02 s ticks: the ego aims between two points and the path left over keeps its phase) and at
// 0.04 s. Each is solved, at about the same time, at about the same speeds: a step that is not
// a whole number of ticks neither speeds the ego up nor slows it down.
TEST(RunnerTest, AFilesOwnStepSizeDrivesTheSameSeconds) {
  struct Drove {
    double goal_t = -1;
    std::vector<double> v;  // at 0.5 s, 1 s, ... 3 s
  };
  const auto drive = [](double dt) {
    ScenarioXml xml("ZAM_Test-1_1_T-1", dt);
    std::vector<StateXml> slow;
    const int n = static_cast<int>(std::lround(8.0 / dt));
    for (int k = 0; k <= n; ++k) slow.push_back({k, {40 + 8.0 * dt * k, -1.75}, 0.0, 8.0});
    const int lo = static_cast<int>(std::lround(4.0 / dt)),
              hi = static_cast<int>(std::lround(8.0 / dt));
    AddStraightRoad(xml, 500)
        .DynamicObstacle(5, 4.8, 2, slow)
        .Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, lo, hi)});
    const ProblemRun p = RunOne(xml);
    EXPECT_TRUE(p.verdict.solved) << dt << ": " << p.verdict.Summary();
    Drove d;
    if (p.verdict.goal_step) d.goal_t = *p.verdict.goal_step * dt;
    for (int i = 1; i <= 6; ++i) {
      const std::size_t k = static_cast<std::size_t>(std::lround(0.5 * i / dt));
      d.v.push_back(k < p.trajectory.size() ? p.trajectory[k].velocity : -1);
    }
    return d;
  };
  const Drove usual = drive(0.1);
  for (const double dt : {0.05, 0.04}) {
    const Drove other = drive(dt);
    EXPECT_NEAR(other.goal_t, usual.goal_t, 0.3) << dt;
    for (std::size_t i = 0; i < usual.v.size(); ++i) {
      EXPECT_NEAR(other.v[i], usual.v[i], 1.0) << dt << " at " << 0.5 * (i + 1) << " s";
    }
  }
}

TEST(RunnerTest, PassesACarParkedHalfInTheLane) {
  // A car parked across the right lane's right half, 60 m ahead; a goal past it, time only in
  // the ego's lane, which the other lane's traffic leaves no room to leave.
  ScenarioXml xml;
  AddStraightRoad(xml, 400)
      .StaticObstacle(9, 4.8, 2.0, {70, -3.3}, 0)
      .DynamicObstacle(6, 4.8, 2, Drive(-40, 1.75, 20, 80))
      .DynamicObstacle(7, 4.8, 2, Drive(-8, 1.75, 20, 80))
      .DynamicObstacle(8, 4.8, 2, Drive(24, 1.75, 20, 80))
      .Problem(1, {10, -1.75}, 0, 20,
               {GoalRectangleXml({160, -1.75}, 20, 3.5, 0, 0, 80)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
}

TEST(RunnerTest, PassesABlockedLaneOnTheOncomingLaneAndCutsBackInTurned) {
  // A two-way road; a truck parked across the ego's whole lane 70 m ahead; the goal a strip along
  // the lane's middle just past it, crossed turned 0.2 to 0.6 rad to the right: cutting back in
  // from the oncoming lane (DEU_B471's kind).
  auto scenario = [](bool oncoming_blocked) {
    ScenarioXml xml;
    AddTwoWayRoad(xml, 400).StaticObstacle(9, 6.0, 3.0, {80, -1.75}, 0);
    if (oncoming_blocked) xml.StaticObstacle(10, 6.0, 3.0, {80, 1.75}, 3.14159);
    xml.Problem(1, {10, -1.75}, 0, 15,
                {GoalRectangleXml({115, -1.75}, 40, 2.2, 0, 0, 80,
                                  IntervalXml("orientation", -0.6, -0.2))});
    return xml;
  };
  const ProblemRun p = RunOne(scenario(false));
  ASSERT_TRUE(p.verdict.solved) << p.verdict.Summary();
  double leftmost = -1e9;
  for (const KsState& s : p.trajectory) leftmost = std::max(leftmost, s.y);
  EXPECT_GT(leftmost, 0.5) << "the ego's centre went over the centre line";
  // Both lanes blocked: no way past, and the ego stops short of the trucks.
  const ProblemRun blocked = RunOne(scenario(true));
  EXPECT_FALSE(blocked.verdict.solved);
  ASSERT_NE(blocked.verdict.Find(FailureKind::kGoal), nullptr) << blocked.verdict.Summary();
  EXPECT_EQ(blocked.verdict.failures.size(), 1u) << blocked.verdict.Summary();
}

TEST(RunnerTest, PassesAParkedTruckBeforeTheOncomingCarComes) {
  // A two-way road; a truck parked across the ego's lane 140 m ahead; a car coming the other
  // way meets the ego near the truck some seconds after it gets there. A lane change into the
  // oncoming lane that stays there meets that car within the horizon; out and back (a pass)
  // does not. The goal, in the ego's lane past the truck, closes at 15 s: waiting for the car
  // to go by first is too late.
  auto xml = [] {
    ScenarioXml x;
    AddTwoWayRoad(x, 600)
        .StaticObstacle(9, 6.0, 3.0, {150, -1.75}, 0)
        .DynamicObstacle(7, 4.8, 2.0, [] {
          std::vector<StateXml> s;  // from x = 350 at 15 m/s the other way
          for (int k = 0; k <= 150; ++k) {
            s.push_back({k, {350 - 15 * 0.1 * k, 1.75}, std::numbers::pi, 15});
          }
          return s;
        }())
        .Problem(1, {10, -1.75}, 0, 15, {GoalRectangleXml({210, -1.75}, 40, 3.0, 0, 0, 150)});
    return x;
  }();
  const ProblemRun p = RunOne(xml);
  ASSERT_TRUE(p.verdict.solved) << p.verdict.Summary();
  // Without passes the planner waits behind the truck for the car. (The limit ramps off too:
  // with them it gets there sooner, and by in the oncoming lane before the car without a pass.
  // And the goal's move across after a path's samples: a lane change into the oncoming lane,
  // short of the goal, then counts as coming back in time, and serves as a pass. And the
  // rescue: its search for a way to the goal, once the planner's plan misses it within 6 s of
  // its close, finds the pass the planner lacks.)
  plan::PlannerConfig no_passes = Config();
  ASSERT_TRUE(no_passes.Set("grid.passes", 0).ok());
  ASSERT_TRUE(no_passes.Set("grid.limit_ramps", 0).ok());
  ASSERT_TRUE(no_passes.Set("costs.goal.lateral_pace", 0).ok());
  const ProblemRun waited = RunOne(xml, PredictionMode::kRecorded, &no_passes, false);
  EXPECT_FALSE(waited.verdict.solved);
  EXPECT_EQ(waited.verdict.Find(FailureKind::kCollision), nullptr) << waited.verdict.Summary();
  EXPECT_TRUE(RunOne(xml, PredictionMode::kRecorded, &no_passes).verdict.solved);
}

TEST(RunnerTest, LeavesAnEndingLaneForTheGoal) {
  // The right lane (1) ends at 150 m; the goal lies on the left lane's next lanelet (3).
  ScenarioXml xml;
  LaneletXml r1 = Lane(1, Line(0, 150, 0), Line(0, 150, -3.5));
  r1.adjacent_left = {{2, true}};
  LaneletXml l2 = Lane(2, Line(0, 150, 3.5), Line(0, 150, 0));
  l2.adjacent_right = {{1, true}};
  l2.successors = {3};
  LaneletXml l3 = Lane(3, Line(150, 400, 3.5), Line(150, 400, 0));
  l3.predecessors = {2};
  xml.Lanelet(r1).Lanelet(l2).Lanelet(l3).Problem(
      1, {10, -1.75}, 0, 20, {GoalRectangleXml({250, 1.75}, 20, 3.5, 0, 0, 150)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  EXPECT_EQ(p.lanes, 2);
}

TEST(RunnerTest, TakesAnExitThatSplitsOffThroughTraffic) {
  // From the left lane onto the ramp that splits off the right lane at x = 200, between cars
  // of both lanes (the right lane's go straight on past the fork).
  ScenarioXml xml;
  AddSplitExit(xml)
      .DynamicObstacle(10, 4.5, 1.8, Drive(-10, -1.75, 27, 150))
      .DynamicObstacle(11, 4.5, 1.8, Drive(45, -1.75, 24, 150))
      .DynamicObstacle(12, 4.5, 1.8, Drive(110, -1.75, 26, 150))
      .DynamicObstacle(13, 4.5, 1.8, Drive(70, 1.75, 25, 150))
      .Problem(1, {20, 1.75}, 0, 25, {GoalLaneletXml(5, 0, 150)});
  for (PredictionMode mode : {PredictionMode::kRecorded, PredictionMode::kConstantVelocity}) {
    const ProblemRun p = RunOne(xml, mode);
    EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  }
}

TEST(RunnerTest, FollowsACurvedRoadToATimeOnlyGoal) {
  ScenarioXml xml;
  // From 5 m into the arc (the network's start is closed: the ego's rear must be on it).
  const double a = 5.0 / 120;
  AddCurvedRoad(xml, 120, 1.5)
      .Problem(1, {120 * std::sin(a), 120 - 120 * std::cos(a)}, a, 15, {GoalTimeOnlyXml(60, 60)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  EXPECT_EQ(*p.verdict.goal_step, 60);
}

TEST(RunnerTest, StartsFromRestToASpeedWindow) {
  // At rest near the start of the road (its rear 0.5 m from the closed end), a goal 60 m on
  // between 8 and 15 m/s.
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(
      1, {2.75, -1.75}, 0, 0,
      {GoalRectangleXml({60, -1.75}, 10, 3.5, 0, 0, 100, IntervalXml("velocity", 8, 15))});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
}

TEST(RunnerTest, WaitsInAQueueWithoutRollingBackOrTurning) {
  // A line of stopped cars from 60 m on; the goal: standing behind them, heading along the
  // lane, in a window 6 to 8 s in. The ego stops well before it and waits.
  ScenarioXml xml;
  AddStraightRoad(xml, 300)
      .StaticObstacle(9, 4.8, 2.0, {60, -1.75}, 0)
      .StaticObstacle(10, 4.8, 2.0, {67, -1.75}, 0)
      .Problem(1, {10, -1.75}, 0, 8,
               {GoalRectangleXml({50, -1.75}, 8, 3.5, 0, 60, 80,
                                 IntervalXml("velocity", 0, 1) +
                                     IntervalXml("orientation", -0.05, 0.05))});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  for (const KsState& s : p.trajectory) {
    EXPECT_GE(s.velocity, 0.0) << "step " << s.time_step;
    EXPECT_LT(std::abs(s.orientation), 0.05) << "step " << s.time_step;
  }
}

TEST(RunnerTest, FollowingAPathNeverRollsBack) {
  // At rest just ahead of a path that stays where it is (a plan to stand, the ego a few cm
  // past it): the along-track error asks for a step back; the follower stays put instead.
  const VehicleParams vp;
  const KsState ego{0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const std::vector<double> x(60, -0.05), y(60, 0.0);
  const KsState next = FollowPath(ego, x, y, 0.1, vp);
  EXPECT_GE(next.velocity, 0.0);
  EXPECT_LE(next.x, 1e-9);
  // Moving at 1 m/s along a path 1 m/s behind: it slows down, still forwards.
  std::vector<double> px, py;
  for (int i = 1; i <= 60; ++i) {
    px.push_back(-0.3 + 1.0 * 0.02 * i);
    py.push_back(0.0);
  }
  const KsState slowed = FollowPath({0, 0.0, 0.0, 0.0, 1.0, 0.0}, px, py, 0.1, vp);
  EXPECT_GE(slowed.velocity, 0.0);
  EXPECT_LT(slowed.velocity, 1.0);
}

// A path whose points lie a phase off the ticks (the whole points a step of 0.05 s leaves):
// the ego aims at the point dt in by the path's own times and keeps its speed; read as if on
// the ticks, the same path is 0.01 s (0.2 m) further on and the ego speeds up.
TEST(RunnerTest, FollowingAPathReadsItAtItsPhase) {
  const VehicleParams vp;
  KsState ego;
  ego.velocity = 20.0;
  std::vector<double> px, py;
  for (int i = 0; i < 100; ++i) {
    px.push_back(20.0 * ((i + 1) * 0.02 + 0.01));
    py.push_back(0.0);
  }
  const KsState at_phase = FollowPath(ego, px, py, 0.05, vp, 0.01);
  EXPECT_NEAR(at_phase.x, 1.0, 0.01);
  EXPECT_NEAR(at_phase.velocity, 20.0, 0.05);
  const KsState on_ticks = FollowPath(ego, px, py, 0.05, vp, 0.0);
  EXPECT_GT(on_ticks.velocity, 20.1);
}

TEST(RunnerTest, AnUnreachableGoalFailsWithItsReason) {
  // 600 m in 3 s from 20 m/s: no vehicle gets there.
  ScenarioXml xml;
  AddStraightRoad(xml, 800).Problem(1, {10, -1.75}, 0, 20,
                                    {GoalRectangleXml({600, -1.75}, 10, 3, 0, 0, 30)});
  const ProblemRun p = RunOne(xml);
  EXPECT_FALSE(p.verdict.solved);
  ASSERT_NE(p.verdict.Find(FailureKind::kGoal), nullptr) << p.verdict.Summary();
  EXPECT_EQ(p.stop_reason, "time");
  // Everything else held: the ego drove legally, on the road, without touching anyone.
  EXPECT_EQ(p.verdict.failures.size(), 1u) << p.verdict.Summary();
}

TEST(RunnerTest, AProblemWithoutARoadSaysWhy) {
  // The goal rectangle lies beside the road, on no lanelet: no route to it.
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(3, {10, -1.75}, 0, 20,
                                    {GoalRectangleXml({150, 40}, 10, 3.5, 0, 0, 100, "")});
  const ProblemRun p = RunOne(xml);
  ASSERT_FALSE(p.road.ok());
  EXPECT_NE(p.road.message().find("planning problem 3"), std::string::npos) << p.road.message();
  EXPECT_FALSE(p.verdict.solved);
  EXPECT_FALSE(p.verdict.infeasible_at_start.has_value());
  EXPECT_TRUE(p.trajectory.empty());
}

TEST(RunnerTest, TheTopSpeedIsTheSignsElseTheVehicles) {
  // An empty straight kilometre, the ego at 30 m/s, a goal far ahead: unsigned, it speeds up
  // past the 36 m/s an advisory limit would hold it to (toward the vehicle's 50.8 m/s); under a
  // 25 m/s sign it slows to the sign.
  for (const bool signed_lane : {false, true}) {
    ScenarioXml xml;
    LaneletXml l = Lane(1, Line(0, 1000, 0), Line(0, 1000, -3.5));
    if (signed_lane) l.signs = {7};
    xml.Lanelet(l);
    if (signed_lane) xml.SpeedSign(7, 25.0);
    xml.Problem(1, {10, -1.75}, 0, 30,
                {GoalRectangleXml({900, -1.75}, 20, 3.5, 0, 0, 400)});
    const ProblemRun p = RunOne(xml);
    EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
    double vmax = 0;
    for (const KsState& st : p.trajectory) vmax = std::max(vmax, st.velocity);
    if (signed_lane) {
      double late = 0;  // after 10 s
      for (size_t k = 100; k < p.trajectory.size(); ++k) late = std::max(late, p.trajectory[k].velocity);
      EXPECT_LT(late, 25.5);
      EXPECT_GT(late, 23.0);
    } else {
      EXPECT_GT(vmax, 38.0);
      EXPECT_LT(vmax, VehicleParams().v_max);
    }
  }
}

TEST(RunnerTest, StopsBeforeTheMapsEndForATimeOnlyGoal) {
  // The map ends 120 m ahead of the ego at 20 m/s; the goal is a time only, 10 s in: the ego
  // must be on the lanelets (the network's end is closed) at every step until then. It stops
  // before the end and waits.
  ScenarioXml xml;
  AddStraightRoad(xml, 130).Problem(1, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(100, 100)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  double front = -1e9;
  for (const KsState& st : p.trajectory) front = std::max(front, st.x + 0.5 * VehicleParams().length);
  EXPECT_LT(front, 130.0);
  EXPECT_GT(front, 100.0);  // it used the road, not a panic stop
}

TEST(RunnerTest, WaitsInAGoalAtTheMapsEndUntilItsWindowOpens) {
  // The goal is the last 60 m of the map (a lanelet of its own, the network's end closed), its
  // window opening 10 s in; at its 20 m/s the ego would be past the end by then. It stops in the
  // region before the end and is there when the window opens. A window open from the start is
  // met on arrival, without slowing for the end.
  for (const int opens : {100, 0}) {
    ScenarioXml xml;
    LaneletXml a = Lane(1, Line(0, 120, 0), Line(0, 120, -3.5));
    a.successors = {2};
    LaneletXml b = Lane(2, Line(120, 180, 0), Line(120, 180, -3.5));
    b.predecessors = {1};
    xml.Lanelet(a).Lanelet(b).Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, opens, 200)});
    const ProblemRun p = RunOne(xml);
    EXPECT_TRUE(p.verdict.solved) << opens << ": " << p.verdict.Summary();
    if (opens == 0) {
      ASSERT_FALSE(p.trajectory.empty());
      EXPECT_GT(p.trajectory.back().velocity, 15.0);
    }
  }
}

TEST(RunnerTest, TheRescueMeetsAGoalThePlannersPathMisses) {
  // A goal region in the left lane (y 0 to 3.5) for 0.7-0.8 s only, around where the ego gets
  // by then at 20 m/s in the right lane (y -1.75): its centre has to cross 1.75 m sideways in
  // 0.7 s, quicker than any of the planner's swerves (without the rescue the run ends beside
  // the region, at y -0.7). The rescue's search of the vehicle's own inputs finds such a way
  // once the planner's path misses the region for good, and drives it.
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(1, {10, -1.75}, 0, 20,
                                    {GoalRectangleXml({32, 1.75}, 24, 3.5, 0, 7, 8)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  int rescued = 0;
  for (const RunCycle& c : p.cycles) rescued += c.rescued;
  EXPECT_GT(rescued, 0);
  ASSERT_FALSE(p.trajectory.empty());
  EXPECT_GT(p.trajectory.back().y, 0.0);  // its centre in the region's lane
}

TEST(RunnerTest, TheRescueOvertakesForAGoalPastASlowCarBeforeItsWindowCloses) {
  // A zipper merge (as ZAM_Zip-9_9 made by scripts/commonroad-zips.py): the ego starts at 6.3
  // m/s in the left half, a slower car ahead of it in its half (8-9 m/s), two cars at 10.6-10.8
  // m/s in the right half, one behind the ego and one ahead; the goal is the merged lane at
  // steps 84-85. Following the slow car the ego is still short of the merge then; the planner's
  // lattice does not find the way past it (without the goal search past the 2 s path, none of
  // these is solved). Once its plan misses the goal while the window closes within 6 s, the
  // rescue's search finds a way through the right half and the ego drives it.
  for (const double x0 : {-85.0, -75.0}) {
    const double v0 = x0 < -80 ? 9.0 : 8.0;
    ScenarioXml xml;
    AddZipperMerge(xml);
    std::vector<StateXml> slow;
    for (int k = 0; k <= 85; ++k) {
      const double x = x0 + v0 * 0.1 * k;  // into the merged lane as 28 turns, from x = -20
      slow.push_back({k, {x, 8.75 - 3.5 * std::clamp((x + 20) / 20, 0.0, 1.0)}, 0.0, v0});
    }
    xml.DynamicObstacle(4, 4.8, 2, slow)
        .DynamicObstacle(5, 4.8, 2, Drive(-116, 5.25, 10.8, 85))
        .DynamicObstacle(6, 4.8, 2, Drive(-59, 5.25, 10.6, 85))
        .Problem(1, {-123.7, 8.75}, 0, 6.3, {GoalLaneletXml(24, 84, 85)});
    const ProblemRun p = RunOne(xml);
    EXPECT_TRUE(p.verdict.solved) << x0 << ": " << p.verdict.Summary();
    int rescued = 0;
    for (const RunCycle& c : p.cycles) rescued += c.rescued;
    EXPECT_GT(rescued, 0);
  }
}

TEST(RunnerTest, ARunEndsOnceEveryGoalRegionIsBehind) {
  // A goal region 17-23 m ahead asks to stand (0-1 m/s) in it from 2 s on; at 25 m/s the ego
  // cannot stop in it (27 m at the vehicle's full braking) and drives past. The run then ends
  // (the planner never reverses): no cycles up to the window's end at 20 s.
  ScenarioXml xml;
  AddStraightRoad(xml, 600).Problem(
      1, {10, -1.75}, 0, 25,
      {GoalRectangleXml({30, -1.75}, 6, 3.5, 0, 20, 200, IntervalXml("velocity", 0, 1))});
  const ProblemRun p = RunOne(xml);
  EXPECT_FALSE(p.verdict.solved);
  ASSERT_NE(p.verdict.Find(FailureKind::kGoal), nullptr) << p.verdict.Summary();
  EXPECT_EQ(p.stop_reason, "goal_passed");
  EXPECT_LT(p.cycles.size(), 50u);
  EXPECT_GT(p.trajectory.back().x, 34.0);
}

TEST(RunnerTest, ARunEndsAtItsFirstCollision) {
  // Both lanes have a car 40 m behind at 45 m/s, the ego at 20 m/s: nothing it can do keeps it
  // clear of both for 2 s. The run ends at the step the verdict finds the collision at (the
  // problem is failed), not at the goal window's end (10 s).
  ScenarioXml xml;
  AddStraightRoad(xml, 600);
  for (const auto& [id, y] : {std::pair{7, -1.75}, std::pair{8, 1.75}}) {
    std::vector<testing::StateXml> car;
    for (int k = 0; k <= 100; ++k) car.push_back({k, {-20 + 45.0 * 0.1 * k, y}, 0.0, 45});
    xml.DynamicObstacle(id, 4.5, 1.8, car);
  }
  xml.Problem(1, {20, -1.75}, 0, 20, {GoalTimeOnlyXml(100, 100)});
  const ProblemRun p = RunOne(xml);
  ASSERT_FALSE(p.verdict.infeasible_at_start.has_value()) << p.verdict.Summary();
  const Failure* hit = p.verdict.Find(FailureKind::kCollision);
  ASSERT_NE(hit, nullptr) << p.verdict.Summary();
  EXPECT_EQ(p.stop_reason, "collision");
  EXPECT_EQ(p.trajectory.back().time_step, hit->step);
  EXPECT_EQ(static_cast<int>(p.cycles.size()), hit->step);
  EXPECT_LT(hit->step, 40);
}

// A goal the initial state already meets (here a time-only goal from step 0) ends the run after
// one driven step: CommonRoad's feasibility check fails on a trajectory of a single state.
TEST(RunnerTest, AGoalMetAtTheStartStillDrivesOneStep) {
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(3, {20, -1.75}, 0, 20, {GoalTimeOnlyXml(0, 30)});
  const ProblemRun p = RunOne(xml);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
  EXPECT_EQ(p.stop_reason, "goal");
  ASSERT_EQ(p.trajectory.size(), 2u);
  EXPECT_EQ(p.trajectory[1].time_step, p.trajectory[0].time_step + 1);
  EXPECT_EQ(p.verdict.goal_step, 0);
}

TEST(RunnerTest, AProblemInfeasibleAtStartIsNotPlanned) {
  // Three starts no trajectory can leave from: off the road beside it, across the road's closed
  // start, and on a parked car. Each is reported infeasible at start with the failure at the
  // initial step, and nothing is planned (no cycle, the initial state only).
  struct Case {
    const char* what;
    Vec2 start;
    FailureKind kind;
  };
  for (const Case& c : {Case{"beside the road", {10, 40}, FailureKind::kOffRoad},
                        Case{"across the start", {1.0, -1.75}, FailureKind::kOffRoad},
                        Case{"on a parked car", {30, -1.75}, FailureKind::kCollision}}) {
    ScenarioXml xml;
    AddStraightRoad(xml, 300)
        .StaticObstacle(9, 4.8, 2.0, {32, -1.75}, 0)
        .Problem(3, c.start, 0, 20, {GoalTimeOnlyXml(30, 30)});
    const ProblemRun p = RunOne(xml);
    ASSERT_TRUE(p.verdict.infeasible_at_start.has_value()) << c.what << ": " << p.verdict.Summary();
    EXPECT_EQ(p.verdict.infeasible_at_start->kind, c.kind) << c.what;
    EXPECT_EQ(p.verdict.infeasible_at_start->step, 0) << c.what;
    EXPECT_FALSE(p.verdict.solved) << c.what;
    EXPECT_EQ(p.stop_reason, "infeasible_at_start") << c.what;
    EXPECT_TRUE(p.cycles.empty()) << c.what;
    EXPECT_EQ(p.trajectory.size(), 1u) << c.what;
    EXPECT_NE(p.verdict.Summary().find("infeasible at start"), std::string::npos) << c.what;
  }
  // One step further in on the same road, the start is fine and the run is planned.
  ScenarioXml ok;
  AddStraightRoad(ok, 300).Problem(3, {2.5, -1.75}, 0, 20, {GoalTimeOnlyXml(30, 30)});
  const ProblemRun p = RunOne(ok);
  EXPECT_FALSE(p.verdict.infeasible_at_start.has_value()) << p.verdict.Summary();
  EXPECT_FALSE(p.cycles.empty());
}

TEST(RunnerTest, ConstantVelocityPredictionsStillAvoidACutIn) {
  // A car in the left lane, 10 m ahead at the ego's speed, cuts into the ego's lane while
  // braking (as NGSIM traffic does); the ego sees only its present.
  ScenarioXml xml;
  AddStraightRoad(xml, 500);
  std::vector<StateXml> cutter;
  double x = 20, y = 1.75, v = 20;
  for (int k = 0; k <= 80; ++k) {
    cutter.push_back({k, {x, y}, k >= 10 && k < 30 ? -0.17 : 0.0, v});
    x += v * 0.1;
    if (k >= 10 && k < 30) y -= 3.5 / 20;
    if (k >= 10 && k < 40) v -= 0.4;
  }
  xml.DynamicObstacle(4, 4.8, 2, cutter)
      .Problem(1, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(70, 70)});
  const ProblemRun p = RunOne(xml, PredictionMode::kConstantVelocity);
  EXPECT_TRUE(p.verdict.solved) << p.verdict.Summary();
}

TEST(RunnerTest, ConstantVelocityPredictionsSeeTheOtherHalfOfAZipperMergeMergeIn) {
  // The ego in the left half of a zipper merge (its lane goes on, behind a car 20 m ahead that
  // follows it), a car alongside in the right half, all at 12 m/s; that car drives on straight
  // into the merged lane as its own lane ends. The ego sees only the present: without the merge
  // predicted, the car seems to drive on beside it, and the ego runs into it at the merge (or,
  // once the rescue reads the car's turn across the narrowing road, too late, misses the goal).
  for (const double beside : {-2.0, 0.0, 2.0}) {
    ScenarioXml xml;
    AddZipperMerge(xml);
    std::vector<StateXml> car, leader;
    for (int k = 0; k <= 85; ++k) {
      car.push_back({k, {-100 + beside + 1.2 * k, 5.25}, 0.0, 12});
      const double x = -80 + 1.2 * k;  // 28 moves 3.5 m right from x = -20 to 0
      leader.push_back({k, {x, 8.75 - 3.5 * std::clamp((x + 20) / 20, 0.0, 1.0)}, 0.0, 12});
    }
    xml.DynamicObstacle(4, 4.8, 2, car)
        .DynamicObstacle(5, 4.8, 2, leader)
        .Problem(1, {-100, 8.75}, 0, 12, {GoalLaneletXml(24, 84, 85)});
    const ProblemRun p = RunOne(xml, PredictionMode::kConstantVelocity);
    EXPECT_TRUE(p.verdict.solved) << beside << ": " << p.verdict.Summary();
    plan::PlannerConfig no_merge = Config();
    ASSERT_TRUE(no_merge.Set("prediction.merge_time", 0).ok());
    const ProblemRun blind = RunOne(xml, PredictionMode::kConstantVelocity, &no_merge);
    EXPECT_FALSE(blind.verdict.solved) << beside << ": " << blind.verdict.Summary();
  }
}

TEST(RunnerTest, PassesACarGivenAsASetBasedPrediction) {
  // A slow car 50 m ahead in the ego's lane, predicted as regions that grow along the lane; the
  // goal is the left lane. The verdict checks the ego against the regions.
  ScenarioXml xml;
  AddStraightRoad(xml, 500);
  std::vector<testing::OccupancyXml> regions;
  for (int k = 1; k <= 80; ++k) {
    regions.push_back({k, k, testing::RectangleXml(4.8 + 0.05 * k, 2.2, {60 + 0.8 * k, -1.75})});
  }
  xml.SetBasedObstacle(5, 4.8, 2, {0, {60, -1.75}, 0, 8}, regions)
      .Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, 40, 80)});
  for (const PredictionMode mode : {PredictionMode::kRecorded, PredictionMode::kConstantVelocity}) {
    const ProblemRun p = RunOne(xml, mode);
    EXPECT_TRUE(p.verdict.solved) << ToString(mode) << ": " << p.verdict.Summary();
  }
}

// The shared set-based scene (its cars' occupancies grow with the prediction's uncertainty) asks
// for a lane change into the left lane within 0.9-1.0 s: the rescue's way to the goal, pruned
// by what the vehicle can reach across the road and checked against each step's occupancy.
TEST(RunnerTest, TheSharedSetBasedSceneIsSolvedWithItsOccupancies) {
  const std::string path =
      std::string(FRENETIC_SHARED_DIR "/commonroad/us101/USA_US101-1_1_S-1.xml");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  auto sc = LoadScenario(path);
  ASSERT_TRUE(sc.ok()) << sc.message();
  RunOptions o;
  o.timing = false;
  const std::vector<ProblemRun> runs = RunScenario(*sc, Config(), o).problems;
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_TRUE(runs[0].verdict.solved) << runs[0].verdict.Summary();
  EXPECT_TRUE(std::any_of(runs[0].cycles.begin(), runs[0].cycles.end(),
                          [](const RunCycle& c) { return c.rescued; }));
}

// The problems of the scenario files in `dir` whose names end with `suffix`, each run closed-loop
// with recorded predictions (no timing) and given to on_problem (when set): how many there were,
// were solved and were infeasible at start, and the others' verdicts.
struct SharedTally {
  int problems = 0, solved = 0, infeasible = 0;
  std::string unsolved;
};
SharedTally RunSharedDir(
    const std::filesystem::path& dir, const std::string& suffix,
    const std::function<void(const std::filesystem::path&, const ProblemRun&)>& on_problem = {}) {
  RunOptions o;
  o.timing = false;
  const plan::PlannerConfig config = Config();
  SharedTally t;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!entry.path().filename().string().ends_with(suffix)) continue;
    auto sc = LoadScenario(entry.path().string());
    if (!sc.ok()) {
      ADD_FAILURE() << sc.message();
      continue;
    }
    for (const ProblemRun& p : RunScenario(*sc, config, o).problems) {
      ++t.problems;
      t.solved += p.verdict.solved;
      t.infeasible += p.verdict.infeasible_at_start.has_value();
      if (!p.verdict.solved && !p.verdict.infeasible_at_start) {
        t.unsolved += " " + sc->benchmark_id + ": " + p.verdict.Summary();
      }
      if (on_problem) on_problem(entry.path(), p);
    }
  }
  return t;
}

TEST(RunnerTest, EverySharedFileRunsAndItsTrajectoriesAreKsTrajectories) {
  const std::filesystem::path dir = std::filesystem::path(FRENETIC_SHARED_DIR) / "commonroad";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "no " << dir;
  const SharedTally t =
      RunSharedDir(dir, ".xml", [](const std::filesystem::path& path, const ProblemRun& p) {
        if (p.verdict.infeasible_at_start) {
          // No solution exists (ZAM_Ramp's ego starts with its rear past the road's closed
          // start); nothing was planned.
          EXPECT_TRUE(p.cycles.empty()) << path;
          return;
        }
        ASSERT_TRUE(p.road.ok()) << p.road.message();
        // Whatever the outcome, the runner's own part holds: a trajectory from the initial
        // state, step by step, that the KS model and the vehicle's limits allow.
        for (const FailureKind k : {FailureKind::kTrajectory, FailureKind::kStart,
                                    FailureKind::kDynamics, FailureKind::kSteeringRate,
                                    FailureKind::kSteeringAngle, FailureKind::kAcceleration,
                                    FailureKind::kFrictionCircle, FailureKind::kVelocity}) {
          EXPECT_EQ(p.verdict.Find(k), nullptr) << path << ": " << p.verdict.Summary();
        }
      });
  EXPECT_GE(t.problems, 13);
  // Every example that has a solution is solved (recorded predictions, the benchmark's
  // convention).
  EXPECT_LE(t.infeasible, 1);
  EXPECT_EQ(t.solved + t.infeasible, t.problems) << t.unsolved;
}

// The shared highD files (fast recorded traffic, cars closing from behind at twice their stated
// speed): every problem that has a solution is solved with recorded predictions. The last one
// (`ALower26-1_26451`) needed the rescue's strata by the speed across (Rescue::Stratum).
TEST(RunnerTest, EverySharedHighDProblemWithASolutionIsSolved) {
  const std::filesystem::path dir =
      std::filesystem::path(FRENETIC_SHARED_DIR) / "commonroad" / "highD";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "no " << dir;
  const SharedTally t = RunSharedDir(dir, ".cr.xml");
  EXPECT_GE(t.problems, 30);
  EXPECT_LE(t.infeasible, 3);
  EXPECT_EQ(t.solved + t.infeasible, t.problems) << t.unsolved;
}

// The scenario recorded at another step size: every trajectory obstacle's states at the steps of
// `dt` (linear between the recorded ones, the heading the short way round), the goals' time
// windows in those steps (the whole steps within them), the problems' initial steps likewise.
Scenario AtStepSize(Scenario sc, double dt) {
  const double r = dt / sc.dt;
  const auto lerp = [](const std::optional<double>& a, const std::optional<double>& b, double w) {
    return a && b ? std::optional<double>(*a + w * (*b - *a)) : a;
  };
  for (Obstacle& o : sc.obstacles) {
    o.dt = dt;
    if (o.role != ObstacleRole::kDynamic || o.prediction != ObstaclePrediction::kTrajectory)
      continue;
    std::vector<State> old{o.initial};
    old.insert(old.end(), o.trajectory.begin(), o.trajectory.end());
    const int a0 = old.front().time_step, a1 = old.back().time_step;
    std::vector<State> now;
    for (int j = static_cast<int>(std::ceil(a0 / r - 1e-9)); j * r <= a1 + 1e-9; ++j) {
      const double u = j * r - a0;
      const int i = std::min(static_cast<int>(std::floor(u + 1e-9)), a1 - a0);
      const double w = i < a1 - a0 ? u - i : 0.0;
      const State& p = old[i];
      const State& q = old[std::min(i + 1, a1 - a0)];
      State st = p;
      st.time_step = j;
      st.position = p.position + w * (q.position - p.position);
      st.velocity = lerp(p.velocity, q.velocity, w);
      st.acceleration = lerp(p.acceleration, q.acceleration, w);
      if (p.orientation && q.orientation) {
        st.orientation = *p.orientation + w * WrapAngle(*q.orientation - *p.orientation);
      }
      now.push_back(st);
    }
    if (now.empty()) continue;
    o.initial = now.front();
    o.trajectory.assign(now.begin() + 1, now.end());
  }
  for (PlanningProblem& p : sc.problems) {
    p.initial.time_step = static_cast<int>(std::lround(p.initial.time_step / r));
    for (GoalState& g : p.goals) {
      if (!g.time) continue;
      const int lo = static_cast<int>(std::ceil(g.time->start / r - 1e-9));
      const int hi = static_cast<int>(std::floor(g.time->end / r + 1e-9));
      g.time = hi >= lo ? IntervalI{lo, hi} : IntervalI{lo, lo};
    }
  }
  sc.dt = dt;
  return sc;
}

// The shared highD files of one site recorded at 0.05 s instead of 0.1 s (2.5 of the planner's
// 0.02 s ticks a step): the same traffic in seconds, and every problem with a solution is still
// solved. Before the ego aimed between two points of its path (it drove 3 ticks of path a step,
// 20% too fast) and the rescue looked 4 s ahead in steps (2 s at 0.05), 5 of 9 were.
TEST(RunnerTest, TheSharedHighDProblemsOfASiteAreSolvedAtAnotherStepSize) {
  const std::filesystem::path dir =
      std::filesystem::path(FRENETIC_SHARED_DIR) / "commonroad" / "highD";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "no " << dir;
  RunOptions o;
  o.timing = false;
  const plan::PlannerConfig config = Config();
  int problems = 0, solved = 0, infeasible = 0;
  std::string unsolved;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("DEU_LocationAUpper") || !name.ends_with(".cr.xml")) continue;
    auto sc = LoadScenario(entry.path().string());
    ASSERT_TRUE(sc.ok()) << sc.message();
    ASSERT_NEAR(sc->dt, 0.1, 1e-12);
    for (const ProblemRun& p : RunScenario(AtStepSize(*sc, 0.05), config, o).problems) {
      ++problems;
      solved += p.verdict.solved;
      infeasible += p.verdict.infeasible_at_start.has_value();
      if (!p.verdict.solved && !p.verdict.infeasible_at_start) {
        unsolved += " " + sc->benchmark_id + ": " + p.verdict.Summary();
      }
    }
  }
  EXPECT_EQ(problems, 10);
  EXPECT_LE(infeasible, 1);
  EXPECT_EQ(solved + infeasible, problems) << unsolved;
}

}  // namespace
}  // namespace frenetic::commonroad

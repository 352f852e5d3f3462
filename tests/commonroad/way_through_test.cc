// The way-through search (way_through.h): hand-made two-lane scenes where a way exists or does
// not, its agreement with the verdict's certain collisions, and the shared highD files where
// they are.
#include "frenetic/commonroad/way_through.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "commonroad/scenario_xml.h"
#include "frenetic/sanitizers.h"

namespace frenetic::commonroad {
namespace {

using testing::AddStraightRoad;
using testing::GoalRectangleXml;
using testing::GoalTimeOnlyXml;
using testing::Parse;
using testing::ScenarioXml;
using testing::StateXml;

// A car driving along +x at `v` m/s from x0, at y, its states at steps 0..steps.
std::vector<StateXml> Car(double x0, double y, double v, int steps) {
  std::vector<StateXml> out;
  for (int k = 0; k <= steps; ++k) out.push_back({k, {x0 + v * 0.1 * k, y}, 0.0, v});
  return out;
}

// At most 2000 states a step: enough for these scenes, and quick under the sanitizers.
WayThroughOptions Small() {
  WayThroughOptions o;
  o.max_states = 2000;
  return o;
}

WayThrough Search(const Scenario& s, const WayThroughOptions& options = Small()) {
  const VehicleParams vehicle;
  const VerdictChecker checker(s, vehicle);
  return SearchWayThrough(s, s.problems.at(0), checker, vehicle, options);
}

// The ego in the right lane at x = 50, 20 m/s; a car 30 m behind it in its lane at 40 m/s, there
// for 3 s: it reaches the ego in about 1.3 s unless the ego leaves the lane. The cars are 2 m
// wide: no room for the ego (1.61 m) on the line between two of them in the two lanes.
// `goal`: the problem's goal state (steps 10-30, time only, unless given).
ScenarioXml CarFromBehind(const std::string& goal = GoalTimeOnlyXml(10, 30)) {
  ScenarioXml xml;
  AddStraightRoad(xml, 400)
      .DynamicObstacle(9, 4.5, 2.0, Car(20, -1.75, 40, 30))
      .Problem(100, {50, -1.75}, 0, 20, {goal});
  return xml;
}

TEST(WayThroughTest, AFreeNextLaneIsAWayPastACarFromBehind) {
  const WayThrough w = Search(Parse(CarFromBehind()));
  EXPECT_TRUE(w.found);
  EXPECT_EQ(w.last_step, 30);  // the traffic's last step
  EXPECT_EQ(w.survived_to, 30);
  EXPECT_GT(w.checked, 30);
}

TEST(WayThroughTest, ANextLaneFullOfCarsLeavesNoWay) {
  // The same, with the left lane a column of cars alongside at the ego's speed, 1.5 m apart:
  // no gap to move into, no speed at which the car behind does not arrive.
  ScenarioXml xml = CarFromBehind();
  for (int i = 0; i < 16; ++i)
    xml.DynamicObstacle(20 + i, 4.5, 2.0, Car(-10 + 6.0 * i, 1.75, 20, 30));
  const WayThrough w = Search(Parse(xml));
  EXPECT_FALSE(w.found);
  EXPECT_EQ(w.last_step, 30);
  // Not a collision at once: the first steps have ways, the car behind ends them all.
  EXPECT_GE(w.survived_to, 5);
  EXPECT_LT(w.survived_to, 20);
}

TEST(WayThroughTest, AgreesWithTheVerdictsCertainCollisions) {
  // A car 7 m behind at 60 m/s is into every box the ego can reach at step 1
  // (VerdictChecker::UnavoidableCollision); the search finds no state at step 1 either. A start
  // on a parked car: the initial state itself fails, one state checked.
  {
    ScenarioXml xml;
    AddStraightRoad(xml, 400)
        .DynamicObstacle(9, 4.5, 1.8, Car(43, -1.75, 60, 30))
        .Problem(100, {50, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 30)});
    const Scenario s = Parse(xml);
    ASSERT_TRUE(VerdictChecker(s, VehicleParams()).UnavoidableCollision(s.problems[0]));
    const WayThrough w = Search(s);
    EXPECT_FALSE(w.found);
    EXPECT_EQ(w.survived_to, 0);
  }
  {
    ScenarioXml xml;
    AddStraightRoad(xml, 400)
        .StaticObstacle(9, 4.0, 1.8, {52, -1.75}, 0)
        .DynamicObstacle(10, 4.5, 1.8, Car(200, 1.75, 20, 30))
        .Problem(100, {50, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 30)});
    const WayThrough w = Search(Parse(xml));
    EXPECT_FALSE(w.found);
    EXPECT_EQ(w.survived_to, 0);
    EXPECT_EQ(w.checked, 1);
  }
}

TEST(WayThroughTest, TheRoadsEndIsAWallToo) {
  // No traffic near, but the road ends 32 m ahead of an ego at 30 m/s (braking needs 39.1 m at
  // 11.5 m/s^2, more than the 32 m less half its length): the road check ends every way. 62 m
  // ahead it stops in time and stands.
  for (const double road : {82.0, 112.0}) {
    ScenarioXml xml;
    AddStraightRoad(xml, road)
        .DynamicObstacle(9, 4.5, 1.8, Car(0, 1.75, 1, 40))
        .Problem(100, {50, -1.75}, 0, 30, {GoalTimeOnlyXml(10, 40)});
    const WayThrough w = Search(Parse(xml));
    EXPECT_EQ(w.found, road > 100) << road;
    if (!w.found) {
      EXPECT_LT(w.survived_to, 20) << road;
    }
  }
}

TEST(WayThroughTest, AWayToTheGoalIsToldWithItsFirstStep) {
  WayThroughOptions few = Small();
  few.max_states = 500;  // enough here, and quick under the sanitizers
  // A goal of time only (steps 10-30): the first step of its window, while the car from behind
  // is still being escaped.
  {
    const WayThrough w = Search(Parse(CarFromBehind()), few);
    EXPECT_EQ(w.goal_step, 10);
    EXPECT_EQ(w.goal_searched_to, 10);
    EXPECT_EQ(w.survived_to, 30);  // the traffic is searched to its end all the same
  }
  // A region 170-190 m along the right lane within steps 40-60, past the traffic's last step
  // (30): from x = 50 at 20 m/s it is reached at step 60 holding that speed, sooner by speeding
  // up. The search goes on past the traffic (on the road alone) to find it; `found` and
  // `survived_to` still speak of the traffic.
  {
    const WayThrough w =
        Search(Parse(CarFromBehind(GoalRectangleXml({180, -1.75}, 20, 3.0, 0.0, 40, 60))), few);
    EXPECT_TRUE(w.found);
    EXPECT_EQ(w.last_step, 30);
    EXPECT_EQ(w.survived_to, 30);
    EXPECT_GE(w.goal_step, 40);
    EXPECT_LE(w.goal_step, 60);
    EXPECT_EQ(w.goal_searched_to, w.goal_step);
  }
  // A region 200-220 m along within steps 10-12: 150 m in 1.2 s is out of the vehicle's reach.
  // No way to it, though a way through the traffic is found: searched to the traffic's last step.
  {
    const WayThrough w =
        Search(Parse(CarFromBehind(GoalRectangleXml({210, -1.75}, 20, 3.0, 0.0, 10, 12))), few);
    EXPECT_TRUE(w.found);
    EXPECT_EQ(w.goal_step, -1);
    EXPECT_EQ(w.goal_searched_to, 30);
  }
}

// Its reach is seconds, not steps: traffic recorded for 12 s is searched through to its last
// step at 0.05 s (step 240) as at 0.1 s (step 120); 200 steps would have ended it at 10 s.
TEST(WayThroughTest, AFilesOwnStepSizeSearchesTheSameSeconds) {
  for (const double dt : {0.1, 0.05}) {
    const int n = static_cast<int>(std::lround(12.0 / dt));
    std::vector<StateXml> far;  // a car in the other lane, far ahead at the ego's speed
    for (int k = 0; k <= n; ++k) far.push_back({k, {300 + 20 * dt * k, 1.75}, 0.0, 20});
    ScenarioXml xml("ZAM_Test-1_1_T-1", dt);
    AddStraightRoad(xml, 700)
        .DynamicObstacle(9, 4.5, 1.8, far)
        .Problem(100, {50, -1.75}, 0, 20, {GoalTimeOnlyXml(n, n)});
    WayThroughOptions few = Small();
    few.max_states = 100;
    const WayThrough w = Search(Parse(xml), few);
    EXPECT_EQ(w.last_step, n) << dt;
    EXPECT_TRUE(w.found) << dt;
    EXPECT_EQ(w.survived_to, n) << dt;
  }
}

TEST(WayThroughTest, WithNoTrafficAfterTheStartTheWayThroughIsFoundAndTheGoalSearchedAlone) {
  // The only car is there at step 0 alone, far off: nothing to get through. The road ends 32 m
  // ahead of the ego at 30 m/s (TheRoadsEndIsAWallToo), so every way ends before the goal's
  // window (steps 30-40) opens: no way to the goal, though `found`.
  ScenarioXml xml;
  AddStraightRoad(xml, 82)
      .DynamicObstacle(9, 4.5, 1.8, Car(0, 1.75, 1, 0))
      .Problem(100, {50, -1.75}, 0, 30, {GoalTimeOnlyXml(30, 40)});
  WayThroughOptions few = Small();
  few.max_states = 500;
  const WayThrough w = Search(Parse(xml), few);
  EXPECT_TRUE(w.found);
  EXPECT_EQ(w.last_step, 0);
  EXPECT_EQ(w.survived_to, 0);
  EXPECT_EQ(w.goal_step, -1);
  EXPECT_GT(w.goal_searched_to, 0);
  EXPECT_LT(w.goal_searched_to, 30);
}

TEST(WayThroughTest, CappedStepsAreToldAndTheSearchStaysDeterministic) {
  WayThroughOptions small = Small();
  small.max_states = 50;
  const Scenario s = Parse(CarFromBehind());
  const WayThrough a = Search(s, small), b = Search(s, small);
  EXPECT_FALSE(a.exhaustive);
  EXPECT_EQ(a.found, b.found);
  EXPECT_EQ(a.survived_to, b.survived_to);
  EXPECT_EQ(a.checked, b.checked);
  const WayThrough full = Search(s);
  EXPECT_GT(full.checked, a.checked);
}

TEST(WayThroughTest, SharedHighDProblems) {
  // A highD problem the planner fails by a collision (a car closing from behind, the next
  // lane's cars passing beside): a way exists. One the verdict finds infeasible at start (a
  // collision at step 1 whatever the ego does): no state reaches step 1 here either. Skipped
  // without the shared files.
  const std::string dir = FRENETIC_SHARED_DIR "/commonroad/highD/";
  struct Case {
    const char* file;
    bool found;
  };
  for (const Case c : {Case{"DEU_LocationAUpper26-1_262481_T-2556.cr.xml", true},
                       Case{"DEU_LocationALower26-1_261504_T-1579.cr.xml", false}}) {
    if (!std::filesystem::exists(dir + c.file)) GTEST_SKIP() << "no " << dir << c.file;
    // 75 steps of 4000 states: seconds here, a minute under ASan.
    if (c.found && kUnderSanitizer) continue;
    StatusOr<Scenario> s = LoadScenario(dir + c.file);
    ASSERT_TRUE(s.ok()) << s.message();
    const PlanningProblem& problem = s->problems.at(0);
    const VehicleParams vehicle;
    const VerdictChecker checker(*s, vehicle);
    EXPECT_EQ(checker.StartFailure(problem).has_value(), !c.found) << c.file;
    WayThroughOptions options;
    options.max_states = 4000;
    const WayThrough w = SearchWayThrough(*s, problem, checker, vehicle, options);
    EXPECT_EQ(w.found, c.found) << c.file << " survived to " << w.survived_to;
    if (!c.found) {
      EXPECT_EQ(w.survived_to, problem.initial.time_step) << c.file;
    }
  }
}

}  // namespace
}  // namespace frenetic::commonroad

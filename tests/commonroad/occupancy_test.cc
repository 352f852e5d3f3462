// Set-based predictions (<occupancySet>): read from hand-made files, what a set-based obstacle
// occupies and the state derived from it at each step, the verdict's collision check against it,
// and the shared SPOT scene.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/verdict.h"

namespace frenetic::commonroad {
namespace {

using testing::AddStraightRoad;
using testing::AddStraightRoadAt;
using testing::CircleXml;
using testing::GoalTimeOnlyXml;
using testing::OccupancyXml;
using testing::Parse;
using testing::PolygonXml;
using testing::RectangleXml;
using testing::ScenarioXml;
using ::testing::HasSubstr;

// The corners of a length x width rectangle along +x centred on `c`, as a polygon.
std::vector<Vec2> Box(Vec2 c, double length, double width) {
  return {{c.x - length / 2, c.y - width / 2},
          {c.x + length / 2, c.y - width / 2},
          {c.x + length / 2, c.y + width / 2},
          {c.x - length / 2, c.y + width / 2}};
}

// A car 4 x 2 m at (20, -1.75) heading +x at 10 m/s at step 0, then: step 1 a rectangle, step 2 a
// polygon, steps 3-5 one growing region (an interval), step 5 also a circle in the other lane,
// nothing at steps 6 and 7, a rectangle at step 8.
ScenarioXml SetBasedXml() {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.SetBasedObstacle(40, 4, 2, {0, {20, -1.75}, 0, 10},
                       {{1, 1, RectangleXml(5, 2, {21.5, -1.75})},
                        {2, 2, PolygonXml(Box({23, -1.75}, 6, 2.4))},
                        {3, 5, RectangleXml(12, 3, {27, -1.75})},
                        {5, 5, CircleXml(1, {27, 1.75})},
                        {8, 8, RectangleXml(6, 2, {40, -1.75})}});
  xml.Problem(100, {150, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  return xml;
}

TEST(OccupancySetTest, ReadsExactTimesAndIntervals) {
  const Scenario s = Parse(SetBasedXml());
  const Obstacle* o = s.FindObstacle(40);
  ASSERT_NE(o, nullptr);
  EXPECT_EQ(o->role, ObstacleRole::kDynamic);
  EXPECT_EQ(o->prediction, ObstaclePrediction::kSetBased);
  EXPECT_TRUE(o->trajectory.empty());
  ASSERT_EQ(o->occupancies.size(), 5u);
  EXPECT_EQ(o->occupancies[0].time.start, 1);
  EXPECT_EQ(o->occupancies[0].time.end, 1);
  EXPECT_EQ(o->occupancies[2].time.start, 3);
  EXPECT_EQ(o->occupancies[2].time.end, 5);
  EXPECT_EQ(o->occupancies[1].shape.shapes[0].kind, Shape::Kind::kPolygon);
  EXPECT_EQ(o->occupancies[3].shape.shapes[0].kind, Shape::Kind::kCircle);
  EXPECT_DOUBLE_EQ(o->dt, 0.1);
  EXPECT_EQ(o->LastStep(), 8);
}

TEST(OccupancySetTest, OccupancyAtEachStep) {
  const Scenario s = Parse(SetBasedXml());
  const Obstacle& o = *s.FindObstacle(40);
  // Step 0: its own shape at its initial state.
  std::optional<ShapeGroup> at = o.OccupancyAt(0);
  ASSERT_TRUE(at.has_value());
  EXPECT_TRUE(at->Contains({21.9, -1.75}));
  EXPECT_FALSE(at->Contains({22.1, -1.75}));
  // Step 1: the rectangle, x in [19, 24].
  at = o.OccupancyAt(1);
  ASSERT_TRUE(at.has_value());
  EXPECT_TRUE(at->Contains({23.9, -1.75}));
  EXPECT_FALSE(at->Contains({24.1, -1.75}));
  // Steps 3 to 5: the interval's region; at step 5 with the circle.
  for (int k = 3; k <= 5; ++k) {
    at = o.OccupancyAt(k);
    ASSERT_TRUE(at.has_value()) << k;
    EXPECT_TRUE(at->Contains({32.9, -3})) << k;
    EXPECT_EQ(at->Contains({27, 2.5}), k == 5) << k;
    EXPECT_EQ(at->shapes.size(), k == 5 ? 2u : 1u) << k;
  }
  // Gone where nothing covers the step, before the initial step and after the last.
  for (int k : {-1, 6, 7, 9, 1000}) EXPECT_FALSE(o.OccupancyAt(k).has_value()) << k;
  EXPECT_TRUE(o.OccupancyAt(8).has_value());
}

TEST(OccupancySetTest, StateAtIsTheOccupancysBoxAndItsMotion) {
  const Scenario s = Parse(SetBasedXml());
  const Obstacle& o = *s.FindObstacle(40);
  // The initial state as read.
  std::optional<State> st = o.StateAt(0);
  ASSERT_TRUE(st.has_value());
  EXPECT_DOUBLE_EQ(st->position.x, 20);
  EXPECT_DOUBLE_EQ(*st->velocity, 10);
  // Step 1: the rectangle's centre, 1.5 m on in 0.1 s.
  st = o.StateAt(1);
  ASSERT_TRUE(st.has_value());
  EXPECT_EQ(st->time_step, 1);
  EXPECT_NEAR(st->position.x, 21.5, 1e-9);
  EXPECT_NEAR(st->position.y, -1.75, 1e-9);
  EXPECT_NEAR(*st->orientation, 0, 1e-9);
  EXPECT_NEAR(*st->velocity, 15, 1e-9);
  EXPECT_FALSE(st->acceleration.has_value());
  // Step 3: from the polygon's centre (23) to the region's (27).
  st = o.StateAt(3);
  EXPECT_NEAR(st->position.x, 27, 1e-9);
  EXPECT_NEAR(*st->velocity, 40, 1e-9);
  // Step 4: the same region, standing.
  EXPECT_NEAR(*o.StateAt(4)->velocity, 0, 1e-9);
  // Step 5: the box around the region (y from -3.25) and the circle (its circumscribed 16-gon,
  // up to 1.75 + 1 / cos(pi / 16)).
  const double top = 1.75 + 1 / std::cos(std::numbers::pi / 16);
  st = o.StateAt(5);
  EXPECT_NEAR(st->position.x, 27, 1e-9);
  EXPECT_NEAR(st->position.y, 0.5 * (-3.25 + top), 1e-9);
  EXPECT_NEAR(*st->orientation, 0, 1e-9);
  // No state where no occupancy is.
  EXPECT_FALSE(o.StateAt(6).has_value());
  EXPECT_FALSE(o.StateAt(9).has_value());
  // Step 8: from step 5's centre, over 0.3 s.
  st = o.StateAt(8);
  ASSERT_TRUE(st.has_value());
  EXPECT_NEAR(*st->velocity, Distance({40, -1.75}, {27, 0.5 * (-3.25 + top)}) / 0.3, 1e-9);
}

TEST(OccupancySetTest, OrientationIsTheBoxSideNearestTheMotion) {
  // A region wider across the road than along it, ahead of the initial position: heading +x
  // (the motion), its length the 2 m along x; one turned by 0.3 rad keeps that turn.
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.SetBasedObstacle(
      41, 4, 2, {0, {20, -1.75}, 0.2, 10},
      {{1, 1, RectangleXml(2, 6, {25, -1.75})}, {2, 2, RectangleXml(8, 2, {30, -1.75}, 0.3)}});
  xml.Problem(100, {150, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  const Obstacle& o = *s.FindObstacle(41);
  std::optional<State> st = o.StateAt(1);
  EXPECT_NEAR(*st->orientation, 0, 1e-9);
  st = o.StateAt(2);
  EXPECT_NEAR(*st->orientation, 0.3, 1e-9);
  EXPECT_NEAR(st->position.x, 30, 1e-9);
  // A region barely away from the initial position: the initial orientation picks the side.
  ScenarioXml still;
  AddStraightRoad(still);
  still.SetBasedObstacle(42, 4, 2, {0, {20, -1.75}, 1.4, 0},
                         {{1, 1, RectangleXml(2, 6, {20.5, -1.75})}});
  still.Problem(100, {150, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const Scenario t = Parse(still);
  EXPECT_NEAR(*t.FindObstacle(42)->StateAt(1)->orientation, std::numbers::pi / 2, 1e-9);
}

TEST(OccupancySetTest, AFileFarFromItsOriginMovesItsOccupancies) {
  const Vec2 far{500000, 4000000};
  ScenarioXml xml;
  AddStraightRoadAt(xml, far);
  xml.SetBasedObstacle(40, 4, 2, {0, far + Vec2{20, -1.75}, 0, 10},
                       {{1, 1, RectangleXml(5, 2, far + Vec2{21.5, -1.75})},
                        {2, 3, PolygonXml(Box(far + Vec2{23, -1.75}, 6, 2.4))}});
  xml.Problem(100, far + Vec2{150, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  ASSERT_NE(s.origin.x, 0);
  const Obstacle& o = *s.FindObstacle(40);
  const Vec2 local = far - s.origin;
  EXPECT_NEAR(o.StateAt(1)->position.x, local.x + 21.5, 1e-6);
  EXPECT_NEAR(o.StateAt(3)->position.y, local.y - 1.75, 1e-6);
  EXPECT_TRUE(o.OccupancyAt(2)->Contains(local + Vec2{25.9, -1.75}));
  EXPECT_NEAR(*o.StateAt(1)->velocity, 15, 1e-6);
}

// Two lanes along +x; the ego in the right lane at x = 10, 20 m/s, driving straight: its front
// at 12.254 + 2k at step k.
std::vector<KsState> StraightRun(int steps) {
  std::vector<KsState> out;
  for (int k = 0; k <= steps; ++k) {
    KsState s;
    s.time_step = k;
    s.x = 10 + 2.0 * k;
    s.y = -1.75;
    s.velocity = 20;
    out.push_back(s);
  }
  return out;
}

TEST(OccupancySetTest, TheVerdictCollidesWithTheOccupancyAtItsStep) {
  // The region x in [60, 64] occupies the left lane until step 25 and both lanes from step 26
  // on: the ego's front passes x = 60 at step 24, so the first collision is at step 26.
  const auto scenario = [](int cross_from, int until) {
    ScenarioXml xml;
    AddStraightRoad(xml);
    xml.SetBasedObstacle(50, 4, 2, {0, {62, 1.75}, 0, 0},
                         {{1, cross_from - 1, RectangleXml(4, 2.5, {62, 1.75})},
                          {cross_from, until, PolygonXml({{60, 3}, {64, 3}, {64, -3}, {60, -3}})}});
    xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(20, 40)});
    return Parse(xml);
  };
  const std::vector<KsState> run = StraightRun(40);
  Scenario s = scenario(26, 40);
  Verdict v = CheckTrajectory(s, s.problems[0], VehicleParams(), run);
  const Failure* hit = v.Find(FailureKind::kCollision);
  ASSERT_NE(hit, nullptr) << v.Summary();
  EXPECT_EQ(hit->step, 26);
  EXPECT_EQ(hit->obstacle_id, 50);
  EXPECT_THAT(hit->detail, HasSubstr("obstacle 50 (car) at (62.00, 0.00)"));
  // Across the lane only until step 23: the ego is not there yet, no collision.
  s = scenario(20, 23);
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), run);
  EXPECT_EQ(v.Find(FailureKind::kCollision), nullptr) << v.Summary();
  // Across it from step 24 on: the ego's front (60.254) is in it then.
  s = scenario(24, 40);
  v = CheckTrajectory(s, s.problems[0], VehicleParams(), run);
  ASSERT_NE(v.Find(FailureKind::kCollision), nullptr) << v.Summary();
  EXPECT_EQ(v.Find(FailureKind::kCollision)->step, 24);
}

TEST(OccupancySetTest, AStartOnItsInitialShapeIsInfeasibleAtStart) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.SetBasedObstacle(50, 4, 2, {0, {12, -1.75}, 0, 0}, {{1, 5, RectangleXml(4, 2, {80, 1.75})}});
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(20, 40)});
  const Scenario s = Parse(xml);
  const VerdictChecker checker(s, VehicleParams());
  const std::optional<Failure> f = checker.StartFailure(s.problems[0]);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->kind, FailureKind::kCollision);
  EXPECT_EQ(f->obstacle_id, 50);
}

TEST(OccupancySetTest, TheSharedSpotSceneIsRead) {
  const std::string path =
      std::string(FRENETIC_SHARED_DIR "/commonroad/us101/USA_US101-1_1_S-1.xml");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  const StatusOr<Scenario> s = LoadScenario(path);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(s->obstacles.size(), 2u);
  for (const Obstacle& o : s->obstacles) {
    SCOPED_TRACE(o.id);
    EXPECT_EQ(o.prediction, ObstaclePrediction::kSetBased);
    ASSERT_EQ(o.occupancies.size(), 10u);
    EXPECT_EQ(o.LastStep(), 10);
    // One occupancy per step 1..10; the cars drive along +x, the regions growing.
    double previous_x = o.initial.position.x, previous_area = 0;
    for (int k = 1; k <= 10; ++k) {
      EXPECT_EQ(o.occupancies[k - 1].time.start, k);
      EXPECT_EQ(o.occupancies[k - 1].time.end, k);
      const std::optional<State> st = o.StateAt(k);
      ASSERT_TRUE(st.has_value()) << k;
      EXPECT_GT(st->position.x, previous_x) << k;
      EXPECT_GT(*st->velocity, 5) << k;
      EXPECT_LT(*st->velocity, 40) << k;
      EXPECT_LT(std::abs(*st->orientation), 0.2) << k;
      const OrientedBox box = o.OccupancyAt(k)->BoundingBox(*st->orientation);
      EXPECT_GE(box.length * box.width, previous_area - 1e-6) << k;
      previous_x = st->position.x;
      previous_area = box.length * box.width;
    }
    EXPECT_FALSE(o.OccupancyAt(11).has_value());
  }
  // Obstacle 484's region splits into a second lane at step 7 and a third at step 10.
  EXPECT_EQ(s->FindObstacle(484)->OccupancyAt(7)->shapes.size(), 2u);
  EXPECT_EQ(s->FindObstacle(484)->OccupancyAt(10)->shapes.size(), 3u);
}

}  // namespace
}  // namespace frenetic::commonroad

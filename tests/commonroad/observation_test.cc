// Observe: the sensor rows and recorded futures the planner is given at a step of a CommonRoad
// run, from hand-made scenarios.
#include "frenetic/commonroad/observation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>

#include "commonroad/scenario_xml.h"
#include "frenetic/map/reference_line.h"

namespace frenetic::commonroad {
namespace {

using testing::AddStraightRoad;
using testing::GoalTimeOnlyXml;
using testing::Parse;
using testing::ScenarioXml;
using testing::StateXml;

// A reference line along y = 0 from x = -50 to 400.
const map::ReferenceLine& Line() {
  static const std::shared_ptr<const map::ReferenceLine> line = [] {
    std::vector<map::ReferenceLine::Point> points;
    for (int i = 0; i <= 45; ++i) points.push_back({-50 + 10.0 * i, 0});
    auto fitted = map::ReferenceLine::FitOpen(points, {}, "test");
    EXPECT_TRUE(fitted.ok()) << fitted.message();
    return std::move(fitted).value();
  }();
  return *line;
}

// `n` + 1 states from (x0, y) at `v` m/s along `heading`, the stated velocity `stated`.
std::vector<StateXml> Drive(Vec2 from, double heading, double v, double stated, int n,
                            int first = 0) {
  std::vector<StateXml> out;
  for (int k = 0; k <= n; ++k) {
    const double d = v * 0.1 * k;
    out.push_back(
        {first + k, from + Vec2{d * std::cos(heading), d * std::sin(heading)}, heading, stated});
  }
  return out;
}

const plan::SensorCar* Row(const plan::Telemetry& t, int id) {
  for (const plan::SensorCar& c : t.sensor_fusion) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

const plan::CarFuture* Future(const plan::Telemetry& t, int id) {
  for (const plan::CarFuture& f : t.futures) {
    if (f.id == id) return &f;
  }
  return nullptr;
}

TEST(ObserveTest, RowsOfTheObstaclesPresent) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.StaticObstacle(30, 4, 2, {100, -1.75}, 0.1);
  xml.DynamicObstacle(31, 4.5, 1.8, Drive({20, 1.75}, 0, 10, 10, 5));
  xml.DynamicObstacle(32, 4.5, 1.8, Drive({60, -1.75}, 0, 12, 12, 10, 3));  // from step 3
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  plan::Telemetry t;
  Observe(s, 2, Line(), 10, PredictionMode::kConstantVelocity, &t);
  ASSERT_EQ(t.sensor_fusion.size(), 2u);  // 32 is not there yet
  EXPECT_TRUE(t.futures.empty());
  const plan::SensorCar* parked = Row(t, 30);
  ASSERT_NE(parked, nullptr);
  EXPECT_DOUBLE_EQ(parked->x, 100);
  EXPECT_DOUBLE_EQ(parked->vx, 0);
  EXPECT_NEAR(parked->s, Line().ToFrenet(100, -1.75).s, 1e-6);
  EXPECT_NEAR(parked->d, 1.75, 1e-3);  // d grows to the right
  EXPECT_DOUBLE_EQ(parked->length, 4);
  EXPECT_DOUBLE_EQ(parked->width, 2);
  const plan::SensorCar* car = Row(t, 31);
  ASSERT_NE(car, nullptr);
  EXPECT_NEAR(car->x, 22, 1e-9);
  EXPECT_NEAR(car->vx, 10, 1e-9);
  EXPECT_NEAR(car->vy, 0, 1e-9);
  EXPECT_NEAR(car->d, -1.75, 1e-3);
  EXPECT_DOUBLE_EQ(car->length, 4.5);

  Observe(s, 4, Line(), 10, PredictionMode::kConstantVelocity, &t);
  EXPECT_EQ(t.sensor_fusion.size(), 3u);
  Observe(s, 9, Line(), 10, PredictionMode::kConstantVelocity, &t);  // 31 is gone
  EXPECT_EQ(t.sensor_fusion.size(), 2u);
  EXPECT_EQ(Row(t, 31), nullptr);
}

TEST(ObserveTest, RecordedFuturesFromTheStepOn) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.StaticObstacle(30, 4, 2, {100, -1.75}, 0);
  xml.DynamicObstacle(31, 4.5, 1.8, Drive({20, 1.75}, 0, 10, 10, 120));
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  plan::Telemetry t;
  Observe(s, 5, Line(), 10, PredictionMode::kRecorded, &t);
  ASSERT_EQ(t.futures.size(), 2u);
  const plan::CarFuture* car = Future(t, 31);
  ASSERT_NE(car, nullptr);
  EXPECT_DOUBLE_EQ(car->dt, 0.1);
  ASSERT_EQ(car->x.size(), static_cast<size_t>(kFutureSteps) + 1);
  EXPECT_NEAR(car->x[0], 25, 1e-9);
  EXPECT_NEAR(car->x[10], 35, 1e-9);
  EXPECT_NEAR(car->v[10], 10, 1e-9);
  EXPECT_NEAR(car->heading[10], 0, 1e-9);
  // Near its end the future stops with the trajectory.
  Observe(s, 100, Line(), 10, PredictionMode::kRecorded, &t);
  ASSERT_NE(Future(t, 31), nullptr);
  EXPECT_EQ(Future(t, 31)->x.size(), 21u);
  // The standing one: its state at every step.
  ASSERT_NE(Future(t, 30), nullptr);
  EXPECT_EQ(Future(t, 30)->x.size(), static_cast<size_t>(kFutureSteps) + 1);
  // Constant velocity: the futures of the previous call go.
  Observe(s, 100, Line(), 10, PredictionMode::kConstantVelocity, &t);
  EXPECT_TRUE(t.futures.empty());
  EXPECT_EQ(t.sensor_fusion.size(), 2u);
}

TEST(ObserveTest, ASpeedNotStatedComesFromThePositions) {
  // A trajectory without velocities: 15 m/s from its positions, forward where it can.
  ScenarioXml xml;
  AddStraightRoad(xml);
  std::string states;
  for (int k = 1; k <= 3; ++k) {
    states += "<state>\n<position>" + testing::PointXml({20 + 1.5 * k, 1.75}) +
              "</position>\n<orientation><exact>0</exact></orientation>\n<time><exact>" +
              std::to_string(k) + "</exact></time>\n</state>\n";
  }
  xml.Raw(
      "<dynamicObstacle id=\"33\">\n<type>car</type>\n<shape><rectangle><length>4</length>"
      "<width>2</width></rectangle></shape>\n<initialState>\n<position>" +
      testing::PointXml({20, 1.75}) +
      "</position>\n<orientation><exact>0</exact></orientation>\n<time><exact>0</exact>"
      "</time>\n</initialState>\n<trajectory>\n" +
      states +
      "</trajectory>\n"
      "</dynamicObstacle>\n");
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  const Obstacle& o = *s.FindObstacle(33);
  EXPECT_NEAR(SpeedAt(o, 0, 0.1), 15, 1e-9);
  EXPECT_NEAR(SpeedAt(o, 3, 0.1), 15, 1e-9);
  EXPECT_EQ(SpeedAt(o, 4, 0.1), 0);
}

TEST(ObserveTest, FootprintIsTheShapesBoxPlacedAtTheState) {
  Obstacle o;
  o.shape.shapes = {Shape::Rectangle(4, 2, {1, 0}), Shape::Circle(0.5, {-1.5, 0})};
  State st;
  st.position = {10, 5};
  st.orientation = std::numbers::pi / 2;
  const Footprint f = FootprintOf(o, st);
  // x in [-2, 3], y in [-1, 1] in its own frame: centre (0.5, 0) turned a quarter.
  EXPECT_NEAR(f.centre.x, 10, 1e-9);
  EXPECT_NEAR(f.centre.y, 5.5, 1e-9);
  EXPECT_DOUBLE_EQ(f.length, 5);
  EXPECT_DOUBLE_EQ(f.width, 2);
  EXPECT_DOUBLE_EQ(f.heading, std::numbers::pi / 2);
}

// A car 4 x 2 m at (20, 1.75), 10 m/s at step 0, predicted as regions along the left lane that
// grow 1 m longer and 0.2 m wider each step, their centres 1.5 m apart; none at step 5.
ScenarioXml GrowingSetBasedXml() {
  ScenarioXml xml;
  AddStraightRoad(xml);
  std::vector<testing::OccupancyXml> occupancies;
  for (int k = 1; k <= 8; ++k) {
    if (k == 5) continue;
    occupancies.push_back({k, k, testing::RectangleXml(4 + k, 2 + 0.2 * k, {20 + 1.5 * k, 1.75})});
  }
  xml.SetBasedObstacle(40, 4, 2, {0, {20, 1.75}, 0, 10}, occupancies);
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  return xml;
}

TEST(ObserveTest, ASetBasedObstacleIsItsOccupancysBox) {
  const Scenario s = Parse(GrowingSetBasedXml());
  plan::Telemetry t;
  // Step 0: its own shape at its initial state, its stated speed.
  Observe(s, 0, Line(), 10, PredictionMode::kConstantVelocity, &t);
  const plan::SensorCar* row = Row(t, 40);
  ASSERT_NE(row, nullptr);
  EXPECT_DOUBLE_EQ(row->x, 20);
  EXPECT_DOUBLE_EQ(row->vx, 10);
  EXPECT_DOUBLE_EQ(row->length, 4);
  EXPECT_DOUBLE_EQ(row->width, 2);
  // Step 3: the region's box, the centre's speed since step 2.
  Observe(s, 3, Line(), 10, PredictionMode::kConstantVelocity, &t);
  row = Row(t, 40);
  ASSERT_NE(row, nullptr);
  EXPECT_NEAR(row->x, 24.5, 1e-9);
  EXPECT_NEAR(row->y, 1.75, 1e-9);
  EXPECT_NEAR(row->vx, 15, 1e-9);
  EXPECT_NEAR(row->vy, 0, 1e-9);
  EXPECT_NEAR(row->length, 7, 1e-9);
  EXPECT_NEAR(row->width, 2.6, 1e-9);
  EXPECT_NEAR(row->d, -1.75, 1e-3);
  // Step 5: nothing predicted, no row; step 6: the speed over the two steps since step 4.
  Observe(s, 5, Line(), 10, PredictionMode::kConstantVelocity, &t);
  EXPECT_EQ(Row(t, 40), nullptr);
  Observe(s, 6, Line(), 10, PredictionMode::kConstantVelocity, &t);
  ASSERT_NE(Row(t, 40), nullptr);
  EXPECT_NEAR(Row(t, 40)->vx, 15, 1e-9);
  EXPECT_NEAR(Row(t, 40)->length, 10, 1e-9);
}

TEST(ObserveTest, ASetBasedObstaclesFutureIsItsOccupanciesCentres) {
  const Scenario s = Parse(GrowingSetBasedXml());
  plan::Telemetry t;
  Observe(s, 1, Line(), 10, PredictionMode::kRecorded, &t);
  const plan::CarFuture* f = Future(t, 40);
  ASSERT_NE(f, nullptr);
  // Steps 1 to 4, up to the gap at step 5.
  ASSERT_EQ(f->x.size(), 4u);
  for (size_t i = 0; i < f->x.size(); ++i) {
    EXPECT_NEAR(f->x[i], 20 + 1.5 * (1 + i), 1e-9) << i;
    EXPECT_NEAR(f->y[i], 1.75, 1e-9) << i;
    EXPECT_NEAR(f->v[i], 15, 1e-9) << i;
    EXPECT_NEAR(f->heading[i], 0, 1e-9) << i;
  }
  Observe(s, 6, Line(), 10, PredictionMode::kRecorded, &t);
  ASSERT_NE(Future(t, 40), nullptr);
  EXPECT_EQ(Future(t, 40)->x.size(), 3u);  // steps 6 to 8
}

TEST(ObserveTest, TheSharedSpotSceneGivesARowPerCarAndStep) {
  const std::string path =
      std::string(FRENETIC_SHARED_DIR "/commonroad/us101/USA_US101-1_1_S-1.xml");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  const StatusOr<Scenario> s = LoadScenario(path);
  ASSERT_TRUE(s.ok()) << s.message();
  plan::Telemetry t;
  double previous_length = 0;
  for (int k = 0; k <= 10; ++k) {
    Observe(*s, k, Line(), 0, PredictionMode::kRecorded, &t);
    ASSERT_EQ(t.sensor_fusion.size(), 2u) << k;
    ASSERT_EQ(t.futures.size(), 2u) << k;
    EXPECT_EQ(t.futures[0].x.size(), static_cast<size_t>(11 - k)) << k;
    const plan::SensorCar& car = *Row(t, 484);
    EXPECT_GT(car.vx, 5) << k;
    EXPECT_LT(car.vx, 20) << k;
    EXPECT_GE(car.length, previous_length) << k;  // the region grows
    previous_length = car.length;
  }
  Observe(*s, 11, Line(), 0, PredictionMode::kRecorded, &t);
  EXPECT_TRUE(t.sensor_fusion.empty());
  EXPECT_TRUE(t.futures.empty());
}

// The speed a sensor measures (MeasureVelocity): hand-made cars whose positions advance `pace`
// m/s while their states say `stated`.
struct MeasureCase {
  const char* name;
  double pace, stated, heading;
  int step;
  double speed, direction;  // expected
};
void PrintTo(const MeasureCase& c, std::ostream* os) { *os << c.name; }

class MeasureTest : public ::testing::TestWithParam<MeasureCase> {};

TEST_P(MeasureTest, SpeedAndDirection) {
  const MeasureCase& c = GetParam();
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.DynamicObstacle(31, 4.5, 1.8, Drive({20, 1.75}, c.heading, c.pace, c.stated, 10));
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  // (The file's positions have 10 digits.)
  const MeasuredVelocity mv = MeasureVelocity(*s.FindObstacle(31), c.step, 0.1);
  EXPECT_NEAR(mv.speed, c.speed, 1e-6);
  EXPECT_NEAR(WrapAngle(mv.heading - c.direction), 0, 1e-6);
  // The row says the same.
  plan::Telemetry t;
  Observe(s, c.step, Line(), 10, PredictionMode::kConstantVelocity, &t);
  ASSERT_NE(Row(t, 31), nullptr);
  EXPECT_NEAR(Row(t, 31)->vx, c.speed * std::cos(c.direction), 1e-6);
  EXPECT_NEAR(Row(t, 31)->vy, c.speed * std::sin(c.direction), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MeasureTest,
    ::testing::Values(
        // Positions that follow the stated speed: the stated one.
        MeasureCase{"Consistent", 20, 20, 0.1, 5, 20, 0.1},
        // Within max(1 m/s, 30%): still the stated one (noise of recorded positions).
        MeasureCase{"WithinTheSlack", 25.5, 20, 0, 5, 20, 0},
        MeasureCase{"SlowWithinOneMetrePerSecond", 2.9, 2, 0, 5, 2, 0},
        // The highD case: twice the stated speed, measured.
        MeasureCase{"TwiceTheStated", 40, 20, 0.05, 5, 40, 0.05},
        MeasureCase{"HalfTheStated", 10, 20, 0, 5, 10, 0},
        MeasureCase{"StatedZeroButMoving", 5, 0, 0, 5, 5, 0},
        // Its first step: no previous position, the stated speed.
        MeasureCase{"FirstStep", 40, 20, 0, 0, 20, 0},
        // Standing (positions repeat): the stated speed, whatever it says.
        MeasureCase{"Standing", 0, 3, 0, 5, 3, 0},
        // Moving sideways or backwards: the motion's direction.
        MeasureCase{"Reversing", -5, -5, 0, 5, 5, std::numbers::pi},
        MeasureCase{"ReversingStatedForward", -5, 5, 0, 5, 5, std::numbers::pi}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(MeasureVelocityTest, AMotionOffItsOrientationGivesTheDirection) {
  // States heading +x, positions moving along +y at 3 m/s (a sideways drift the orientation
  // does not show): direction +y; drifting 20 degrees off: the orientation.
  for (const double off : {std::numbers::pi / 2, 0.35}) {
    ScenarioXml xml;
    AddStraightRoad(xml);
    std::vector<StateXml> states = Drive({20, -3}, off, 3, 3, 10);
    for (StateXml& st : states) st.orientation = 0;
    xml.DynamicObstacle(31, 4.5, 1.8, states);
    xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
    const Scenario s = Parse(xml);
    const MeasuredVelocity mv = MeasureVelocity(*s.FindObstacle(31), 4, 0.1);
    EXPECT_NEAR(mv.speed, 3, 1e-9) << off;
    EXPECT_NEAR(mv.heading, off > 1 ? off : 0, 1e-9) << off;
  }
}

TEST(MeasureVelocityTest, StaticAndAbsentObstacles) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.StaticObstacle(30, 4, 2, {100, -1.75}, 0.1);
  xml.DynamicObstacle(31, 4.5, 1.8, Drive({20, 1.75}, 0, 10, 10, 5));
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  const MeasuredVelocity parked = MeasureVelocity(*s.FindObstacle(30), 7, 0.1);
  EXPECT_EQ(parked.speed, 0);
  EXPECT_DOUBLE_EQ(parked.heading, 0.1);
  EXPECT_EQ(MeasureVelocity(*s.FindObstacle(31), 6, 0.1).speed, 0);  // gone
}

TEST(MeasureVelocityTest, RecordedFuturesCarryTheMeasuredSpeeds) {
  // Positions at twice the stated 10 m/s: every sample after the first step says 20.
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.DynamicObstacle(31, 4.5, 1.8, Drive({20, 1.75}, 0, 20, 10, 30));
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(10, 20)});
  const Scenario s = Parse(xml);
  plan::Telemetry t;
  Observe(s, 0, Line(), 10, PredictionMode::kRecorded, &t);
  const plan::CarFuture* f = Future(t, 31);
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(f->v.size(), 31u);
  EXPECT_NEAR(f->v[0], 10, 1e-9);  // step 0: no previous position
  for (size_t i = 1; i < f->v.size(); ++i) EXPECT_NEAR(f->v[i], 20, 1e-9) << i;
  EXPECT_NEAR(Row(t, 31)->vx, 10, 1e-9);
  Observe(s, 3, Line(), 10, PredictionMode::kRecorded, &t);
  EXPECT_NEAR(Future(t, 31)->v[0], 20, 1e-9);
  EXPECT_NEAR(Row(t, 31)->vx, 20, 1e-9);
}

}  // namespace
}  // namespace frenetic::commonroad

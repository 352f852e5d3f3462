// The closed loop's rescue (rescue.h) on a hand-made straight road of two 3.5 m lanes: the step
// a path runs into a predicted car, a way found past a car closing from behind that stays clear
// of it and on the road, the way into a goal region's lane, and no way when the cars of both
// lanes close in side by side; when a planner's path misses a goal that is closing, a way to it
// (kept while it still meets it), and no search for a goal out of reach, along the road or
// across it; a bound of the swerve across the road; a predicted car whose footprint grows; a
// way to a goal held and driven on when the planner sends no path that passes; a car moving
// across predicted into the next lane; a box over a lane's slanted first edge.
#include "frenetic/commonroad/rescue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "frenetic/commonroad/lanelet.h"
#include "frenetic/commonroad/road_area.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/plan/planner.h"

namespace frenetic::commonroad {
namespace {

constexpr double kStep = 0.1;
constexpr double kLane0 = -1.75, kLane1 = -5.25;  // y of the lanes' centres (d 1.75, 5.25)

std::shared_ptr<const map::Road> TwoLanes() {
  const std::vector<map::ReferenceLine::Point> pts = {{0, 0}, {600, 0}};
  auto line = map::ReferenceLine::FitOpen(pts, map::ReferenceLine::Options(), "straight");
  EXPECT_TRUE(line.ok()) << line.message();
  return map::Road::Uniform(*line, 2, 3.5);
}

plan::SensorCar Row(int id, double x, double y, double v) {
  plan::SensorCar c;
  c.id = id;
  c.x = x;
  c.y = y;
  c.vx = v;
  c.length = 4.5;
  c.width = 2.0;
  return c;
}

// A telemetry with the ego at x and these cars (no futures, no goals).
plan::Telemetry Scene(double x, std::vector<plan::SensorCar> cars = {}) {
  plan::Telemetry t;
  t.x = x;
  t.sensor_fusion = std::move(cars);
  return t;
}

KsState Ego(double x, double y, double v) {
  KsState s;
  s.x = x;
  s.y = y;
  s.velocity = v;
  return s;
}

// The way's points from ego (Rescue::Points) in *x, *y, and its length in steps.
int WaySteps(const Rescue& rescue, const KsState& ego, std::vector<double>* x,
             std::vector<double>* y) {
  rescue.Points(ego, x, y);
  return static_cast<int>(x->size()) / static_cast<int>(std::lround(kStep / plan::kTickSeconds));
}

// Points every tick along +x at y from x0 at v, the first one tick on.
void Straight(double x0, double y, double v, int n, std::vector<double>* x, std::vector<double>* y_out) {
  x->clear();
  y_out->clear();
  for (int i = 1; i <= n; ++i) {
    x->push_back(x0 + v * i * plan::kTickSeconds);
    y_out->push_back(y);
  }
}

TEST(RescueTest, PathHitIsTheStepAPathRunsIntoACar) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), kStep);
  const plan::Telemetry t = Scene(10, {Row(1, 60, kLane0, 0.0)});
  rescue.Predict(t);
  std::vector<double> x, y;
  Straight(10, kLane0, 20, 250, &x, &y);
  // The ego's front (2.25 m + 0.05 m) meets the stopped car's square (2.25 m half side) when its
  // centre is past 60 - 4.55 m: 10 + 2 k >= 55.45, step 23.
  EXPECT_EQ(rescue.PathHit(x, y), 23);
  Straight(10, kLane1, 20, 250, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 0);
  // A path that ends before the car: nothing within the steps it covers.
  Straight(10, kLane0, 20, 50, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 0);
}

// A stopped car has no heading in the telemetry (its speed is 0): the rescue lays its box along
// the road, as the planner's prediction does, at its own length and width. A bus of 12 x 2.5 m
// stopped in one lane leaves the next lane clear (as a square of 12 m it reached 6 m across,
// into both), and a path in its own lane still meets its end.
TEST(RescueTest, AStoppedCarLiesAlongTheRoadAtItsOwnSize) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), kStep);
  plan::SensorCar bus = Row(1, 100, kLane0, 0.0);
  bus.length = 12.0;
  bus.width = 2.5;
  rescue.Predict(Scene(60, {bus}));
  std::vector<double> x, y;
  // Beside it within the 4 s looked at: from x 60 at 20 m/s, past x 140.
  Straight(60, kLane1, 20, 250, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 0);
  // In its lane: the ego's front (2.3 m) meets the bus's back (6 m behind its centre) when the
  // ego's centre is past 100 - 8.3 m: from x 20 at 20 m/s, 20 + 2 k >= 91.7, step 36.
  Straight(20, kLane0, 20, 250, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 36);
}

// A lane that begins with a slanted edge: the road's lane 1 begins at s 100 (one station), while
// its lanelet's first edge runs from (100, -3.5) to (106, -7). A box over the lane's first
// metres lies between the road's borders and still sticks out of the lanelets, which the verdict
// counts as off the road: with the lanelets' outline given, the rescue sees it too.
TEST(RescueTest, WhereALaneBeginsSlantedTheBoxIsCheckedOnTheLaneletsOutline) {
  const std::vector<map::ReferenceLine::Point> pts = {{0, 0}, {600, 0}};
  auto line = map::ReferenceLine::FitOpen(pts, map::ReferenceLine::Options(), "straight");
  ASSERT_TRUE(line.ok()) << line.message();
  map::LaneProfile lane0, lane1;
  lane0.s = {0, 600};
  lane0.left = {0, 0};
  lane0.right = {3.5, 3.5};
  lane1.s = {100, 600};
  lane1.left = {3.5, 3.5};
  lane1.right = {7, 7};
  auto road = map::Road::Make(*line, {lane0, lane1}, "slanted");
  ASSERT_TRUE(road.ok()) << road.message();
  Lanelet a, b;
  a.id = 1;
  a.left = {{0, 0}, {600, 0}};
  a.right = {{0, -3.5}, {600, -3.5}};
  b.id = 2;
  b.left = {{100, -3.5}, {600, -3.5}};
  b.right = {{106, -7}, {600, -7}};
  const std::vector<Lanelet> lanelets = {a, b};
  const RoadArea area = RoadArea::Build(lanelets);

  Rescue rescue(**road, VehicleParams(), kStep);
  rescue.Predict(Scene(103));
  std::vector<double> x, y;
  // d 4.6 from x 103 at 10 m/s: at step 1 the box spans x 101.7-106.3 and y -5.46 to -3.75;
  // the edge is at y -4.49 where the box ends (x 101.7).
  Straight(103, -4.6, 10, 250, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 0);  // the road's borders alone
  rescue.SetRoadArea(&area);
  EXPECT_EQ(rescue.PathHit(x, y), 1);
  // Past the slanted edge the lane is the lanelet: the same path from x 110 stays on the road.
  Straight(110, -4.6, 10, 250, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 0);
  // In lane 0 beside the lane's start, the outline is never crossed.
  Straight(95, -1.75, 10, 250, &x, &y);
  EXPECT_EQ(rescue.PathHit(x, y), 0);
}

// A car moving across faster than the planner's lateral threshold changes lanes in the
// rescue's predictions as in the planner's: into the next lane's centre, then straight on.
TEST(RescueTest, ACarMovingAcrossIsPredictedIntoTheNextLaneAndNoFarther) {
  const std::vector<map::ReferenceLine::Point> pts = {{0, 0}, {600, 0}};
  auto line = map::ReferenceLine::FitOpen(pts, map::ReferenceLine::Options(), "straight");
  ASSERT_TRUE(line.ok()) << line.message();
  const auto road = map::Road::Uniform(*line, 3, 3.5);  // centres at y -1.75, -5.25, -8.75
  // In lane 0 at 20 m/s along, 1.5 m/s across toward lane 1 (d grows as y falls).
  plan::SensorCar car = Row(1, 40, kLane0, 20.0);
  car.vy = -1.5;
  const plan::Telemetry t = Scene(40, {car});
  std::vector<double> x, y;
  {
    Rescue rescue(*road, VehicleParams(), kStep);  // lateral_threshold 0.7 m/s
    rescue.Predict(t);
    // A path alongside in lane 1: the car's box (heading atan(-1.5 / 20), half extent across
    // 2.25 sin + 1.0 cos = 1.165 m) meets the ego's (0.805 + 0.05 m) when the car's centre is
    // past 5.25 - 2.020 = 3.230 m: 1.75 + 1.5 t >= 3.230 first at t = 1.0 s, step 10.
    Straight(40, kLane1, 20, 250, &x, &y);
    EXPECT_EQ(rescue.PathHit(x, y), 10);
    // Its move ends at lane 1's centre: a path alongside in lane 2 is never met.
    Straight(40, -8.75, 20, 250, &x, &y);
    EXPECT_EQ(rescue.PathHit(x, y), 0);
  }
  {
    RescueOptions options;
    options.lateral_threshold = 0;  // no lane changes: the car keeps its offset
    Rescue rescue(*road, VehicleParams(), kStep, options);
    rescue.Predict(t);
    Straight(40, kLane1, 20, 250, &x, &y);
    EXPECT_EQ(rescue.PathHit(x, y), 0);
  }
  {
    // Slower across than the threshold: wander, not a lane change.
    car.vy = -0.5;
    Rescue rescue(*road, VehicleParams(), kStep);
    rescue.Predict(Scene(40, {car}));
    Straight(40, kLane1, 20, 250, &x, &y);
    EXPECT_EQ(rescue.PathHit(x, y), 0);
  }
}

TEST(RescueTest, PathHitIsAlsoTheStepAPathLeavesTheRoadShortOfItsGoal) {
  const auto road = TwoLanes();  // edges at y 0 and -7
  Rescue rescue(*road, VehicleParams(), kStep);
  const plan::Telemetry t = Scene(10);
  rescue.Predict(t);
  // Along lane 0, then drifting left at 1 m/s from x = 30 (step 10): the box (1.8 m wide, the
  // margin 0.05 m more) crosses y = 0 when its centre passes y = -0.95, 0.8 s later (step 18).
  std::vector<double> x, y;
  for (int i = 1; i <= 250; ++i) {
    const double tx = 10 + 20 * i * plan::kTickSeconds;
    x.push_back(tx);
    y.push_back(kLane0 + std::max(0.0, (tx - 30) / 20));
  }
  const int left = rescue.PathHit(x, y);
  EXPECT_GE(left, 17);
  EXPECT_LE(left, 19);
  // The same path meeting a goal region before: the run ends there, what follows is not judged.
  cost::GoalRegion g;
  g.s_lo = 20;
  g.s_hi = 30;
  g.d_lo = 0;
  g.d_hi = 3.5;
  EXPECT_EQ(rescue.PathHit(x, y, {g}), 0);
  // Nor when the region is met only after it has left the road.
  g.s_lo = 60;
  g.s_hi = 80;
  EXPECT_EQ(rescue.PathHit(x, y, {g}), left);
}

TEST(RescueTest, TheSearchsStrataKeepATurnOutOfTheLaneApartFromGoingStraight) {
  // At 30 m/s a heading 0.05 rad off the start's, to either side, moves 1.5 m/s across:
  // another stratum than going straight at the same place and speed (the heading's sign alone
  // made them one).
  KsState straight;
  straight.x = 100.5;
  straight.y = 0.5;
  straight.velocity = 30;
  straight.orientation = 0.3;
  KsState out = straight;
  out.orientation = 0.35;
  KsState other = straight;
  other.orientation = 0.25;
  const double h0 = 0.3;
  EXPECT_NE(Rescue::Stratum(out, h0), Rescue::Stratum(straight, h0));
  EXPECT_NE(Rescue::Stratum(other, h0), Rescue::Stratum(straight, h0));
  // The same turn at 2 m/s moves 0.1 m/s across: one stratum with going straight.
  straight.velocity = out.velocity = 2;
  EXPECT_EQ(Rescue::Stratum(out, h0), Rescue::Stratum(straight, h0));
  // Measured from the start's heading, not the frame's x axis: on a road heading 0.3 rad, a
  // state along it is not turning, one along the x axis is.
  straight.velocity = out.velocity = 30;
  out.orientation = 0.0;
  EXPECT_NE(Rescue::Stratum(out, h0), Rescue::Stratum(straight, h0));
}

TEST(RescueTest, LateralReachBoundsTheVehiclesHardestSwerve) {
  const auto road = TwoLanes();
  const VehicleParams vp;
  Rescue rescue(*road, vp, kStep);
  // From lane 1 toward lane 0 (y grows, d shrinks: toward -1) at 20 m/s, the steering turned at
  // its full rate (past the friction circle, which the bound also lets through at the lowest
  // speed reachable): at every step the bound holds the centre's lateral move (the rear axle's,
  // and the centre b ahead of it turned with the heading), and it is not loose by more than its
  // own approximations.
  const KsState ego = Ego(50, kLane1, 20);
  KsState s = ego;
  for (int k = 1; k <= 10; ++k) {
    s = SimulateKs(s, {vp.steering_rate_max, 0.0}, kStep, vp);
    const double moved = s.y - kLane1, bound = rescue.LateralReach(50, ego, -1, k * kStep);
    EXPECT_LE(moved, bound) << k;
    EXPECT_LE(bound, 2.5 * moved + 0.05) << k;
  }
  // A lane change (3.5 m) at 20 m/s from a straight start takes more than 0.3 s.
  EXPECT_LT(rescue.LateralReach(50, ego, -1, 0.3), 1.0);
  // Steering already turned the other way gives less; heading toward the band gives more.
  KsState away = ego;
  away.steering_angle = -0.05;  // clockwise: toward +d
  EXPECT_LT(rescue.LateralReach(50, away, -1, 0.5), rescue.LateralReach(50, ego, -1, 0.5));
  KsState toward = ego;
  toward.orientation = 0.1;  // counter-clockwise: toward -d
  EXPECT_GT(rescue.LateralReach(50, toward, -1, 0.5), rescue.LateralReach(50, ego, -1, 0.5) + 0.9);
  // Symmetric on a straight road.
  EXPECT_NEAR(rescue.LateralReach(50, ego, 1, 0.7), rescue.LateralReach(50, ego, -1, 0.7), 1e-9);
}

TEST(RescueTest, APredictedCarWhoseFootprintGrowsIsCheckedAtEachSamplesSize) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), kStep);
  // A car standing 40 m ahead in the ego's lane, known by its future (a set-based prediction's
  // bounding boxes): 4.5 m long now, 2 m longer every step.
  plan::Telemetry t = Scene(10, {Row(1, 50, kLane0, 0.0)});
  plan::CarFuture f;
  f.id = 1;
  for (int k = 0; k <= 40; ++k) {
    f.x.push_back(50);
    f.y.push_back(kLane0);
    f.v.push_back(0);
    f.heading.push_back(0);
  }
  t.futures = {f};
  std::vector<double> x, y;
  Straight(10, kLane0, 10, 250, &x, &y);  // 1 m a step
  rescue.Predict(t);
  // Its own size all along: the ego's front (2.25 + 0.05 m) meets the car's rear (47.75 m) at
  // step 36 (10 + k + 2.3 >= 47.75).
  const int fixed = rescue.PathHit(x, y);
  EXPECT_EQ(fixed, 36);
  for (int k = 0; k <= 40; ++k) {
    t.futures[0].lengths.push_back(4.5 + 2.0 * k);
    t.futures[0].widths.push_back(2.0);
  }
  rescue.Predict(t);
  // Its rear at 50 - (2.25 + k): met when 10 + k + 2.3 >= 47.75 - k, step 18.
  EXPECT_EQ(rescue.PathHit(x, y), 18);
}

// The way's states (Points every tick from ego): each step's centre, and whether any is NaN.
std::vector<KsState> StepsOf(const Rescue& rescue, const KsState& ego) {
  std::vector<double> x, y;
  rescue.Points(ego, &x, &y);
  std::vector<KsState> out;
  const int ticks = static_cast<int>(std::lround(kStep / plan::kTickSeconds));
  for (std::size_t j = ticks - 1; j + 1 < x.size(); j += ticks) {
    KsState s;
    s.x = x[j];
    s.y = y[j];
    s.orientation = std::atan2(y[j + 1] - y[j - 1], x[j + 1] - x[j - 1]);
    out.push_back(s);
  }
  return out;
}

TEST(RescueTest, FindsAWayPastACarFromBehindClearOfItAndOnTheRoad) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), kStep);
  plan::Telemetry t = Scene(50, {Row(1, 20, kLane0, 40.0)});  // 30 m behind, 20 m/s faster
  rescue.Predict(t);
  std::vector<double> x, y;
  Straight(50, kLane0, 20, 250, &x, &y);
  ASSERT_GT(rescue.PathHit(x, y), 0);  // keeping the lane is hit
  const KsState ego = Ego(50, kLane0, 20);
  const std::optional<KsInput> u = rescue.Next(ego, {});
  ASSERT_TRUE(u.has_value());
  const VehicleParams vp;
  EXPECT_LE(std::abs(u->acceleration), vp.a_max);
  EXPECT_LE(std::abs(u->steering_rate), vp.steering_rate_max);
  const std::vector<KsState> steps = StepsOf(rescue, ego);
  ASSERT_GE(steps.size(), 39u);  // the whole 4 s
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const double car_x = 20 + 40.0 * kStep * (k + 1);
    const KsState& s = steps[k];
    // Apart along x by two half lengths, or across by two half widths (boxes near the axis).
    const bool apart = std::abs(s.x - car_x) > 4.5 || std::abs(s.y - kLane0) > 1.8 + 0.05;
    EXPECT_TRUE(apart) << "step " << k + 1 << " ego (" << s.x << ", " << s.y << ") car x " << car_x;
    EXPECT_LT(s.y, -0.8) << "step " << k + 1;   // the road's left edge (y 0) and the box
    EXPECT_GT(s.y, -6.2) << "step " << k + 1;   // the right edge (y -7)
  }
  // Driven again next cycle from where the first input leads: the rest of the same way is kept
  // (no new search).
  const int searches = rescue.searches();
  const KsState next = SimulateKs(ego, *u, kStep, vp);
  t.sensor_fusion = {Row(1, 24, kLane0, 40.0)};
  rescue.Predict(t);
  ASSERT_TRUE(rescue.Next(next, {}).has_value());
  EXPECT_EQ(rescue.searches(), searches);
}

// A file's own step size (0.04 s from a 25 Hz recording, 0.05 s, 0.2 s) changes neither how far
// the rescue looks (4 s, in as many steps as that takes) nor where on a path a step lies (between
// two points when the step is not a whole number of ticks), nor the way it finds.
TEST(RescueTest, AtAnyStepSizeTheRescueLooksFourSecondsAheadAndFindsAWay) {
  const auto road = TwoLanes();
  const VehicleParams vp;
  for (const double dt : {0.1, 0.05, 0.04, 0.2}) {
    SCOPED_TRACE(dt);
    Rescue rescue(*road, vp, dt);
    // A stopped car that a path at 20 m/s from x 10 meets at 3.5 s (its front 2.3 m, the car's
    // square 2.25 m half side): at the step holding 3.5 s, whatever the step's size.
    rescue.Predict(Scene(10, {Row(1, 10 + 20 * 3.5 + 4.55, kLane0, 0.0)}));
    std::vector<double> x, y;
    Straight(10, kLane0, 20, 300, &x, &y);
    const int hit = rescue.PathHit(x, y);
    ASSERT_GT(hit, 0);
    EXPECT_NEAR(hit * dt, 3.5, dt + 1e-9);
    // The car from behind of FindsAWayPastACarFromBehindClearOfItAndOnTheRoad: a way of 4 s,
    // a point every tick, clear of the car at every step.
    rescue.Predict(Scene(50, {Row(1, 20, kLane0, 40.0)}));
    Straight(50, kLane0, 20, 300, &x, &y);
    ASSERT_GT(rescue.PathHit(x, y), 0);
    const KsState ego = Ego(50, kLane0, 20);
    ASSERT_TRUE(rescue.Next(ego, {}).has_value());
    rescue.Points(ego, &x, &y);
    EXPECT_NEAR(static_cast<double>(x.size()) * plan::kTickSeconds, 4.0, 0.03);
    for (int k = 1; k * dt <= 4.0 + 1e-9; ++k) {
      const double ticks = k * dt / plan::kTickSeconds;
      if (std::abs(ticks - std::round(ticks)) > 1e-9) continue;  // a step between two points
      const std::size_t j = static_cast<std::size_t>(std::lround(ticks)) - 1;
      ASSERT_LT(j, x.size());
      const double car_x = 20 + 40.0 * k * dt;
      const bool apart = std::abs(x[j] - car_x) > 4.5 || std::abs(y[j] - kLane0) > 1.8 + 0.05;
      EXPECT_TRUE(apart) << "t " << k * dt << " ego (" << x[j] << ", " << y[j] << ") car x "
                         << car_x;
      EXPECT_LT(y[j], -0.8) << "t " << k * dt;
      EXPECT_GT(y[j], -6.2) << "t " << k * dt;
    }
  }
}

// A rescue on the two lanes with no car at all: every way lasts, the goals decide.
class RescueOnAnEmptyRoad : public ::testing::Test {
 protected:
  RescueOnAnEmptyRoad() { rescue_.Predict(t_); }
  std::shared_ptr<const map::Road> road_ = TwoLanes();
  Rescue rescue_{*road_, VehicleParams(), kStep};
  plan::Telemetry t_ = Scene(50);
};

TEST_F(RescueOnAnEmptyRoad, TheWayEndsInTheGoalRegionsLane) {
  // A goal in lane 0 (d in [0, 3.5]) along the stretch every way ends on (50 m on from
  // 20 m/s, 4 s: 80-160 m), open all along: the lane decides.
  cost::GoalRegion goal;
  goal.s_lo = 60;
  goal.s_hi = 400;
  goal.d_lo = 0.5;
  goal.d_hi = 3.0;
  const KsState ego = Ego(50, kLane1, 20);
  ASSERT_TRUE(rescue_.Next(ego, {goal}).has_value());
  std::vector<double> x, y;
  rescue_.Points(ego, &x, &y);
  ASSERT_FALSE(y.empty());
  // It meets the goal (the way ends there: inside d [0.5, 3], y [-3, -0.5]) or ends nearest it.
  EXPECT_GE(y.back(), -3.0 - 1e-6);
  EXPECT_LE(y.back(), -0.5);
  EXPECT_GE(x.back(), 60.0);
}

TEST(RescueTest, NoWayWhenCarsOfBothLanesCloseInSideBySide) {
  const auto road = TwoLanes();
  // 2 m wide cars in both lanes: 1.5 m between them, 0.75 m to each edge; the ego is 1.61 m.
  const plan::Telemetry t = Scene(50, {Row(1, 20, kLane0, 40.0), Row(2, 20, kLane1, 40.0)});
  // The searches one Next makes with a retry of that many states a step (0: none), and the
  // states they checked; none finds a way.
  const auto searches = [&](int retry_states, std::int64_t* checked) {
    RescueOptions options;
    options.retry_states = retry_states;
    Rescue rescue(*road, VehicleParams(), kStep, options);
    rescue.Predict(t);
    EXPECT_FALSE(rescue.Next(Ego(50, kLane0, 20), {}).has_value()) << retry_states;
    *checked = rescue.checked();
    return rescue.searches();
  };
  std::int64_t once = 0, twice = 0, wider = 0;
  EXPECT_EQ(searches(0, &once), 1);
  // By default once more with twice the states; a larger retry checks more again.
  EXPECT_EQ(RescueOptions().retry_states, 2 * RescueOptions().max_states);
  EXPECT_EQ(searches(RescueOptions().retry_states, &twice), 2);
  EXPECT_EQ(searches(600, &wider), 2);
  EXPECT_GT(once, 0);
  EXPECT_GT(twice, once);
  EXPECT_GT(wider, twice);
}

// A goal region in lane 0 (d in [0.5, 3]) from s 60 to s_hi, open from t_lo to t_hi s.
cost::GoalRegion Lane0Goal(double t_lo, double t_hi, double s_hi = 400) {
  return {.s_lo = 60, .s_hi = s_hi, .d_lo = 0.5, .d_hi = 3.0, .t_lo = t_lo, .t_hi = t_hi};
}

// At 0.04 s a search layer holds its input for 3 steps (0.12 s): a window of one step, at step 5
// (0.2 s), lies between two layers' ends (0.12 s, 0.24 s). The goal is looked for at every step
// within a layer too, and the way ends at the step that meets it.
TEST(RescueTest, AGoalWindowNarrowerThanASearchLayerIsStillMet) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), 0.04);
  rescue.Predict(Scene(58));
  const KsState ego = Ego(58, kLane0, 20);  // in lane 0, 2 m short of the region (s 60 on)
  ASSERT_TRUE(rescue.Next(ego, {Lane0Goal(0.2, 0.2)}, true).has_value());
  std::vector<double> x, y;
  rescue.Points(ego, &x, &y);
  EXPECT_EQ(x.size(), 10u);  // 5 steps of 0.04 s: the way ends at the step it meets the region
  // A window of three layers is still looked for at the layers' ends (and met).
  ASSERT_TRUE(rescue.Next(ego, {Lane0Goal(0.2, 0.56)}, true).has_value());
  rescue.Points(ego, &x, &y);
  EXPECT_GE(x.size() * plan::kTickSeconds, 0.2 - 1e-9);
  EXPECT_LE(x.size() * plan::kTickSeconds, 0.56 + 0.03 + 1e-9);
}

TEST(RescueTest, AGoalIsAtRiskWhenThePathMissesItAndItClosesOrIsPassed) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), kStep);
  std::vector<double> lane0_x, lane0_y, lane1_x, lane1_y;
  Straight(50, kLane0, 20, 100, &lane0_x, &lane0_y);  // 2 s, as the planner sends
  Straight(50, kLane1, 20, 100, &lane1_x, &lane1_y);
  // Closing within the path's 2 s: lane 1 misses it, lane 0 meets it.
  EXPECT_TRUE(rescue.GoalAtRisk(lane1_x, lane1_y, {Lane0Goal(1.0, 1.5)}));
  EXPECT_FALSE(rescue.GoalAtRisk(lane0_x, lane0_y, {Lane0Goal(1.0, 1.5)}));
  // Open beyond the path and not passed: later cycles may still meet it.
  EXPECT_FALSE(rescue.GoalAtRisk(lane1_x, lane1_y, {Lane0Goal(0.0, 10.0)}));
  // Open, but the path runs past its end (s 80; the path reaches s 90).
  EXPECT_TRUE(rescue.GoalAtRisk(lane1_x, lane1_y, {Lane0Goal(0.0, 10.0, 80)}));
  // At risk only when every goal is: another one still ahead and open.
  EXPECT_FALSE(rescue.GoalAtRisk(lane1_x, lane1_y, {Lane0Goal(1.0, 1.5), Lane0Goal(0.0, 10.0)}));
  // A window of one whole step comes as an instant between two steps (1.05 s): a step next to
  // it counts.
  EXPECT_FALSE(rescue.GoalAtRisk(lane0_x, lane0_y, {Lane0Goal(1.05, 1.05)}));
  // No goal: nothing at risk.
  EXPECT_FALSE(rescue.GoalAtRisk(lane1_x, lane1_y, {}));
}

TEST(RescueTest, AGoalClosingPastThePathIsAtRiskWhenThePlanMissesItAndThePathEndsOutsideIt) {
  const auto road = TwoLanes();
  Rescue rescue(*road, VehicleParams(), kStep);
  std::vector<double> lane0_x, lane0_y, lane1_x, lane1_y;
  Straight(50, kLane0, 20, 100, &lane0_x, &lane0_y);  // 2 s, ending at s 90
  Straight(50, kLane1, 20, 100, &lane1_x, &lane1_y);
  // Closing at 5 s, within goal_steps (6 s) and past the path's 2 s.
  const cost::GoalRegion closing = Lane0Goal(4.5, 5.0);
  // The planner's plan misses it and the path ends beside it: at risk.
  EXPECT_TRUE(rescue.GoalAtRisk(lane1_x, lane1_y, {closing}, true));
  // The plan meets it (the planner knows best), or the path ends inside the region: not.
  EXPECT_FALSE(rescue.GoalAtRisk(lane1_x, lane1_y, {closing}, false));
  EXPECT_FALSE(rescue.GoalAtRisk(lane0_x, lane0_y, {closing}, true));
  // Short of it along the road (the region from s 120 on): at risk.
  cost::GoalRegion ahead = closing;
  ahead.s_lo = 120;
  EXPECT_TRUE(rescue.GoalAtRisk(lane0_x, lane0_y, {ahead}, true));
  // Closing past goal_steps (7 s), or a smaller goal_steps: later cycles may still meet it.
  EXPECT_FALSE(rescue.GoalAtRisk(lane1_x, lane1_y, {Lane0Goal(6.5, 7.0)}, true));
  RescueOptions four;
  four.goal_horizon = 4.0;
  Rescue rescue4(*road, VehicleParams(), kStep, four);
  EXPECT_FALSE(rescue4.GoalAtRisk(lane1_x, lane1_y, {closing}, true));
  // No path to judge: nothing at risk.
  EXPECT_FALSE(rescue.GoalAtRisk({}, {}, {closing}, true));
}

TEST_F(RescueOnAnEmptyRoad, AWayToAClosingGoalMeetsItAndIsKeptWhileItStillDoes) {
  std::vector<cost::GoalRegion> goals = {Lane0Goal(1.5, 2.0)};
  const KsState ego = Ego(50, kLane1, 20);
  const std::optional<KsInput> u = rescue_.Next(ego, goals, true);
  ASSERT_TRUE(u.has_value());
  EXPECT_EQ(rescue_.searches(), 1);
  // The way ends at the step it meets the region: within its window (1.5-2.0 s, 15-20 steps),
  // in lane 0's part of it.
  std::vector<double> x, y;
  const int steps = WaySteps(rescue_, ego, &x, &y);
  EXPECT_GE(steps, 15);
  EXPECT_LE(steps, 20);
  ASSERT_FALSE(y.empty());
  EXPECT_GE(y.back(), -3.0);
  EXPECT_LE(y.back(), -0.5);
  // A step on, with the window a step nearer: the rest of the way is kept, no new search.
  const KsState next = SimulateKs(ego, *u, kStep, VehicleParams());
  for (cost::GoalRegion& g : goals) {
    g.t_lo -= kStep;
    g.t_hi -= kStep;
  }
  ASSERT_TRUE(rescue_.Next(next, goals, true).has_value());
  EXPECT_EQ(rescue_.searches(), 1);
  // A goal that moved out of the way's reach (its window now closes before the way gets
  // there): a new search, and a way to it only if there is one.
  goals = {Lane0Goal(0.1, 0.2, 62)};
  EXPECT_FALSE(rescue_.Next(next, goals, true).has_value());
}

TEST_F(RescueOnAnEmptyRoad, AWayToAGoalClosingPastTheHorizonIsSearchedUpToItsClose) {
  // In lane 0 from s 150 on, its window 4.5-5.0 s: past the 4 s horizon, within goal_steps.
  cost::GoalRegion goal = Lane0Goal(4.5, 5.0);
  goal.s_lo = 150;
  const KsState ego = Ego(50, kLane1, 20);
  ASSERT_TRUE(rescue_.Next(ego, {goal}, true, true).has_value());
  std::vector<double> x, y;
  const int steps = WaySteps(rescue_, ego, &x, &y);
  EXPECT_GE(steps, 45);
  EXPECT_LE(steps, 50);
  ASSERT_FALSE(y.empty());
  EXPECT_GE(x.back(), 150.0);
  EXPECT_GE(y.back(), -3.0);
  EXPECT_LE(y.back(), -0.5);
  // Not far (the path misses it for good): the search keeps to the horizon, and finds none.
  rescue_.Drop();
  EXPECT_FALSE(rescue_.Next(ego, {goal}, true).has_value());
  // Closing at the last step a search may reach (an instant at 5.9 s, the window's slack of
  // 0.075 s added: step 60): found too, at step 59.
  goal.t_lo = 5.9;
  goal.t_hi = 5.9;
  rescue_.Drop();
  ASSERT_TRUE(rescue_.Next(ego, {goal}, true, true).has_value());
  EXPECT_EQ(WaySteps(rescue_, ego, &x, &y), 59);
  // A region passed long ago whose window never closes does not cut the search short.
  cost::GoalRegion passed = Lane0Goal(0.0, std::numeric_limits<double>::infinity(), 40);
  passed.s_lo = 20;
  rescue_.Drop();
  EXPECT_TRUE(rescue_.Next(ego, {passed, goal}, true, true).has_value());
  goal = Lane0Goal(4.5, 5.0);
  goal.s_lo = 150;
  // With a search no longer than the horizon, none.
  RescueOptions four;
  four.goal_horizon = 4.0;
  Rescue rescue4(*road_, VehicleParams(), kStep, four);
  rescue4.Predict(t_);
  EXPECT_FALSE(rescue4.Next(ego, {goal}, true, true).has_value());
}

TEST(RescueTest, AFarGoalSearchThatFindsNoWayWaitsBeforeTheNext) {
  // Two stopped cars side by side at s 100 close both lanes (1.5 m between them); the goal lies
  // past them, its window 4.5-5.0 s. The planner's 2 s path stops short of the cars.
  const auto road = TwoLanes();
  RescueOptions options;
  options.retry_states = 0;  // one search each time
  Rescue rescue(*road, VehicleParams(), kStep, options);
  plan::Telemetry t = Scene(50, {Row(1, 100, kLane0, 0.0), Row(2, 100, kLane1, 0.0)});
  cost::GoalRegion goal = Lane0Goal(4.5, 5.0);
  goal.s_lo = 150;
  t.goals = {goal};
  std::vector<double> x, y;
  Straight(50, kLane1, 10, 100, &x, &y);
  const KsState ego = Ego(50, kLane1, 10);
  // A cycle's wait after the first search, two after each later one: searches in cycles 1, 3,
  // 6 and 9.
  for (int cycle = 1; cycle <= 9; ++cycle) {
    rescue.Predict(t);
    const int before = rescue.searches();
    const RescueStep step = rescue.Check(t, x, y, ego, true);
    EXPECT_EQ(step.why, RescueStep::Why::kGoal);
    EXPECT_FALSE(step.input.has_value());
    const bool expected = cycle == 1 || cycle == 3 || cycle == 6 || cycle == 9;
    EXPECT_EQ(rescue.searches() - before, expected ? 1 : 0) << "cycle " << cycle;
  }
  // With the plan meeting the goal (as the planner sees it), no search and nothing at risk.
  Rescue quiet(*road, VehicleParams(), kStep, options);
  quiet.Predict(t);
  EXPECT_EQ(quiet.Check(t, x, y, ego, false).why, RescueStep::Why::kNone);
  EXPECT_EQ(quiet.searches(), 0);
}

TEST_F(RescueOnAnEmptyRoad, NoSearchForAGoalOutOfReachOrPassed) {
  const KsState ego = Ego(50, kLane1, 20);
  // 350 m ahead, closing in 1 s: out of reach even at full acceleration.
  cost::GoalRegion far = Lane0Goal(0.0, 1.0);
  far.s_lo = 400;
  far.s_hi = 420;
  EXPECT_FALSE(rescue_.Next(ego, {far}, true).has_value());
  // Behind the ego.
  cost::GoalRegion behind = Lane0Goal(0.0, 10.0);
  behind.s_lo = 0;
  behind.s_hi = 40;
  EXPECT_FALSE(rescue_.Next(ego, {behind}, true).has_value());
  // In lane 0, 2.25 m across from the ego's centre in lane 1 at its nearest, closing in 0.25 s:
  // too little time for a swerve that far (LateralReach).
  EXPECT_FALSE(rescue_.Next(ego, {Lane0Goal(0.0, 0.25)}, true).has_value());
  // Open for 10 s, but ending 3 m ahead in lane 0: even braking at the limit the ego passes its
  // end within 0.16 s, too soon to get across.
  cost::GoalRegion ending = Lane0Goal(0.0, 10.0, 53);
  ending.s_lo = 40;
  EXPECT_FALSE(rescue_.Next(ego, {ending}, true).has_value());
  EXPECT_EQ(rescue_.searches(), 0);
  // Without goal_only a way that lasts is enough (the hit case).
  EXPECT_TRUE(rescue_.Next(ego, {far}).has_value());
  EXPECT_EQ(rescue_.searches(), 1);
}

TEST_F(RescueOnAnEmptyRoad, AHitWithAGoalClosingWithinTheHorizonSearchesForAWayToItFirst) {
  // The window closes at 1.5 s (15 steps): a way to the goal first, with 40 / 16 = 2 times the
  // states a step, then (none needed here) one that lasts.
  const KsState ego = Ego(50, kLane1, 20);
  ASSERT_TRUE(rescue_.Next(ego, {Lane0Goal(1.0, 1.5)}).has_value());
  EXPECT_EQ(rescue_.searches(), 1);
  std::vector<double> x, y;
  EXPECT_LE(WaySteps(rescue_, ego, &x, &y), 16);  // it ends where it meets the region
  ASSERT_FALSE(y.empty());
  EXPECT_GE(y.back(), -3.0);
  EXPECT_LE(y.back(), -0.5);
  // A closing goal no way can meet (lane 0 from s 60 to 72 within 1.0-1.5 s, where a car
  // stands at x 70, and the ego at 20 m/s is past s 64 by 1 s): the goal searches come first
  // and find nothing, then a way that lasts is searched for and driven.
  Rescue blocked{*road_, VehicleParams(), kStep};
  const plan::Telemetry with_car = Scene(50, {Row(1, 70, kLane0, 0.0)});
  blocked.Predict(with_car);
  ASSERT_TRUE(blocked.Next(ego, {Lane0Goal(1.0, 1.5, 72)}).has_value());
  EXPECT_GE(blocked.searches(), 2);
  EXPECT_EQ(WaySteps(blocked, ego, &x, &y), 40);
  // A window open past the horizon: a way that lasts the whole 4 s, as without a goal.
  Rescue open{*road_, VehicleParams(), kStep};
  open.Predict(t_);
  ASSERT_TRUE(open.Next(ego, {Lane0Goal(1.0, 10.0, 60.5)}).has_value());
  EXPECT_EQ(WaySteps(open, ego, &x, &y), 40);
}

TEST_F(RescueOnAnEmptyRoad, AWayToAGoalHoldsWhileItMeetsItAndContinueDrivesItsNextInput) {
  std::vector<cost::GoalRegion> goals = {Lane0Goal(1.5, 2.0)};
  const KsState ego = Ego(50, kLane1, 20);
  const std::optional<KsInput> u = rescue_.Next(ego, goals, true);
  ASSERT_TRUE(u.has_value());
  std::vector<double> x0, y0;
  rescue_.Points(ego, &x0, &y0);
  // A step on, the window a step nearer: the rest of the way still meets the goal.
  KsState next = SimulateKs(ego, *u, kStep, VehicleParams());
  for (cost::GoalRegion& g : goals) {
    g.t_lo -= kStep;
    g.t_hi -= kStep;
  }
  rescue_.Predict(t_);
  EXPECT_TRUE(rescue_.Holds(next, goals));
  const RescueStep step = rescue_.Continue();
  EXPECT_EQ(step.why, RescueStep::Why::kNoPath);
  ASSERT_TRUE(step.input.has_value());
  EXPECT_EQ(rescue_.searches(), 1);  // no new search
  // It is the same way, a step on: its points from the new state are the first ones' rest.
  std::vector<double> x1, y1;
  rescue_.Points(next, &x1, &y1);
  const int ticks = static_cast<int>(std::lround(kStep / plan::kTickSeconds));
  ASSERT_EQ(x1.size() + ticks, x0.size());
  for (std::size_t i = 0; i < x1.size(); ++i) {
    EXPECT_NEAR(x1[i], x0[i + ticks], 1e-3) << i;  // one step of 0.1 s against 5 ticks
    EXPECT_NEAR(y1[i], y0[i + ticks], 1e-3) << i;
  }
  // A goal whose window now closes before the way gets there: it no longer holds, and Continue
  // drives nothing and forgets the way.
  next = SimulateKs(next, *step.input, kStep, VehicleParams());
  goals = {Lane0Goal(0.1, 0.2, 62)};
  EXPECT_FALSE(rescue_.Holds(next, goals));
  const RescueStep none = rescue_.Continue();
  EXPECT_EQ(none.why, RescueStep::Why::kNone);
  EXPECT_FALSE(none.input.has_value());
  std::vector<double> x2, y2;
  rescue_.Points(next, &x2, &y2);
  EXPECT_TRUE(x2.empty());
}

TEST_F(RescueOnAnEmptyRoad, AWayThatOnlyLastsDoesNotHold) {
  // No goal to meet: the way found lasts the horizon, and stands in for a planner's path only
  // when that path hits something (Check), never for its least harm.
  const KsState ego = Ego(50, kLane1, 20);
  const std::optional<KsInput> u = rescue_.Next(ego, {});
  ASSERT_TRUE(u.has_value());
  const KsState next = SimulateKs(ego, *u, kStep, VehicleParams());
  rescue_.Predict(t_);
  EXPECT_FALSE(rescue_.Holds(next, {}));
  EXPECT_FALSE(rescue_.Continue().input.has_value());
}

}  // namespace
}  // namespace frenetic::commonroad

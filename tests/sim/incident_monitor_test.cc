#include "frenetic/sim/incident_monitor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "frenetic/units.h"
namespace frenetic::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Drives a synthetic ego through the monitor: per tick a heading change and a speed.
class Driver {
 public:
  explicit Driver(IncidentOptions options = {}) : monitor_(options) {}

  void Tick(double speed, double turn = 0, double d = 6.0, int collision = -1) {
    heading_ += turn;
    x_ += speed * kTick * std::cos(heading_);
    y_ += speed * kTick * std::sin(heading_);
    TickSample s;
    s.x = x_;
    s.y = y_;
    s.speed = speed;
    s.s = 100;
    s.d = d;
    s.collision_with = collision;
    t_ += kTick;
    ++ticks_;
    monitor_.Update(s, t_);
  }
  // From rest to `speed` at 2 m/s^2, then 2 s steady: never an incident.
  // Ends on a block boundary (a multiple of 10 ticks).
  void WarmUp(double speed) {
    double v = 0;
    while (v < speed) {
      v = std::min(speed, v + 2.0 * kTick);
      Tick(v);
    }
    for (int i = 0; i < 100; ++i) Tick(speed);
    while (ticks_ % 10 != 0) Tick(speed);
  }
  int count(IncidentKind k) const { return monitor_.counts()[static_cast<int>(k)]; }
  const IncidentMonitor& monitor() const { return monitor_; }

 private:
  IncidentMonitor monitor_;
  double x_ = 0, y_ = 0, heading_ = 0, t_ = 0;
  int ticks_ = 0;
};

TEST(MengerCurvature, CircleZeroStepsAndReversal) {
  std::vector<double> x, y;
  const double r = 50;
  for (int i = 0; i < 10; ++i) {
    x.push_back(r * std::cos(i * 0.01));
    y.push_back(r * std::sin(i * 0.01));
  }
  EXPECT_NEAR(MeanMengerCurvature(x.data(), y.data(), 10), 1 / r, 1e-6);
  // A repeated point: the two triples that contain the zero-length step add 0 but count.
  std::vector<double> zx = x, zy = y;
  zx[5] = zx[4];
  zy[5] = zy[4];
  const double with_stop = MeanMengerCurvature(zx.data(), zy.data(), 10);
  EXPECT_LT(with_stop, 1 / r);
  EXPECT_GT(with_stop, 0.5 / r);
  const double rx[4] = {0, 1, 0, -1}, ry[4] = {0, 0, 0, 0};  // an exact reversal
  EXPECT_NEAR(MeanMengerCurvature(rx, ry, 4), 1e6 / 2, 1);
}

TEST(IncidentMonitor, KinkRaisesAccelerationAndSmoothRampDoesNot) {
  // A kink of theta at 22 m/s adds v^2 * 2 sin(theta) / (8 * 0.88 m) to the block's normal
  // acceleration: about 9.6 m/s^2 for 4 degrees, 12 for 5.
  for (double deg : {3.0, 5.0}) {
    Driver drv;
    drv.WarmUp(22);
    for (int i = 0; i < 5; ++i) drv.Tick(22);  // the kink in the middle of a 10-tick block
    ASSERT_EQ(drv.monitor().total(), 0);
    drv.Tick(22, deg * kDeg);
    for (int i = 0; i < 100; ++i) drv.Tick(22);
    EXPECT_EQ(drv.count(IncidentKind::kAcceleration), deg > 4 ? 1 : 0) << deg << " degrees";
    const double expected = 22 * 22 * 2 * std::sin(deg * kDeg) / (8 * 0.88);
    EXPECT_NEAR(drv.monitor().max_acc(), expected, 0.05 * expected);
  }
  // A kink on the first tick of a block is never seen: its triple crosses the block boundary.
  Driver hidden;
  hidden.WarmUp(22);
  hidden.Tick(22, 5 * kDeg);
  for (int i = 0; i < 100; ++i) hidden.Tick(22);
  EXPECT_EQ(hidden.monitor().total(), 0);
  Driver ramp;
  double v = 0;
  for (int i = 0; i < 200; ++i) ramp.Tick(v = std::min(20.0, v + 5.0 * kTick));
  for (int i = 0; i < 100; ++i) ramp.Tick(20);
  EXPECT_EQ(ramp.monitor().total(), 0);
  EXPECT_NEAR(ramp.monitor().max_acc(), 5.0, 0.01);
}

TEST(IncidentMonitor, SuddenCircleRaisesJerkGentleOneDoesNot) {
  for (double radius : {30.0, 100.0}) {
    Driver drv;
    drv.WarmUp(20);
    for (int i = 0; i < 150; ++i) drv.Tick(20, 20 * kTick / radius);
    const bool hard = radius < 50;  // 20^2 / 30 = 13.3 m/s^2 vs 4 m/s^2
    EXPECT_EQ(drv.count(IncidentKind::kJerk), hard ? 1 : 0) << radius;
    EXPECT_EQ(drv.count(IncidentKind::kAcceleration), hard ? 1 : 0) << radius;
  }
}

TEST(IncidentMonitor, SpeedOverFiftyMphOnASingleTick) {
  const double mps = 1 / units::kSimMpsToMph;
  Driver drv;
  drv.WarmUp(49 * mps);
  drv.Tick(50.1 * mps);
  for (int i = 0; i < 100; ++i) drv.Tick(49 * mps);
  EXPECT_EQ(drv.count(IncidentKind::kSpeed), 1);
  EXPECT_EQ(drv.monitor().total(), 1);
  EXPECT_NEAR(drv.monitor().log()[0].value, 50.1, 1e-9);
  Driver at_limit;
  at_limit.WarmUp(50 * mps);  // exactly 50 is allowed
  EXPECT_EQ(at_limit.monitor().total(), 0);
}

TEST(IncidentMonitor, OnsetsCountOnceAndMergeWithinTheHold) {
  const double mps = 1 / units::kSimMpsToMph;
  Driver drv;
  drv.WarmUp(40 * mps);
  drv.Tick(51 * mps);
  for (int i = 0; i < 20; ++i) drv.Tick(40 * mps);
  drv.Tick(51 * mps);  // 21 ticks later: the same incident
  for (int i = 0; i < 100; ++i) drv.Tick(40 * mps);
  drv.Tick(51 * mps);  // a new one
  EXPECT_EQ(drv.count(IncidentKind::kSpeed), 2);
}

TEST(IncidentMonitor, LaneLineTimerNeedsMoreThan150Ticks) {
  for (int ticks : {149, 150, 151}) {
    Driver drv;
    for (int i = 0; i < ticks; ++i) drv.Tick(0, 0, 4.1);
    for (int i = 0; i < 10; ++i) drv.Tick(0, 0, 6.0);
    EXPECT_EQ(drv.count(IncidentKind::kLane), ticks > 150 ? 1 : 0) << ticks;
    EXPECT_EQ(drv.count(IncidentKind::kOffRoad), 0);
  }
}

TEST(IncidentMonitor, RoadEdgesAreImmediate) {
  Driver drv;
  drv.Tick(0, 0, 0.79);
  drv.Tick(0, 0, 2.0);
  EXPECT_EQ(drv.count(IncidentKind::kOffRoad), 1);
  Driver right;
  right.Tick(0, 0, 11.21);
  EXPECT_EQ(right.count(IncidentKind::kOffRoad), 1);
  Driver inside;
  inside.Tick(0, 0, 0.81);
  inside.Tick(0, 0, 11.19);
  EXPECT_EQ(inside.monitor().total(), 0);
}

TEST(IncidentMonitor, CollisionAndTheMilesCounter) {
  Driver drv;
  drv.WarmUp(20);
  for (int i = 0; i < 500; ++i) drv.Tick(20);
  const double before = drv.monitor().current_miles();
  EXPECT_GT(before, 0.1);
  for (int i = 0; i < 5; ++i) drv.Tick(20, 0, 6, 7);
  EXPECT_EQ(drv.count(IncidentKind::kCollision), 1);
  EXPECT_EQ(drv.monitor().log().back().value, 7);
  for (int i = 0; i < 40; ++i) drv.Tick(20);  // the display hold keeps the counter at 0
  EXPECT_EQ(drv.monitor().current_miles(), 0);
  for (int i = 0; i < 100; ++i) drv.Tick(20);
  EXPECT_GT(drv.monitor().current_miles(), 0);
  EXPECT_DOUBLE_EQ(drv.monitor().best_miles(), before);
  EXPECT_LT(drv.monitor().distance_to_first_incident(), drv.monitor().distance());
}

TEST(BoxesOverlap, SideBySideRearEndAndRotated) {
  const Box ego{0, 0, 0, 4.6, 2.4};
  EXPECT_FALSE(BoxesOverlap(ego, Box{0, 2.5, 0, 4.6, 2.4}));  // next lane, 2.5 m apart
  EXPECT_TRUE(BoxesOverlap(ego, Box{0, 2.3, 0, 4.6, 2.4}));
  EXPECT_TRUE(BoxesOverlap(ego, Box{-4.5, 0.3, 0, 4.6, 2.4}));  // rear-ended
  EXPECT_FALSE(BoxesOverlap(ego, Box{-4.7, 0, 0, 4.6, 2.4}));
  EXPECT_TRUE(BoxesOverlap(ego, Box{3.4, 0, std::numbers::pi / 2, 4.6, 2.4}));  // T-bone
  EXPECT_FALSE(BoxesOverlap(ego, Box{3.6, 0, std::numbers::pi / 2, 4.6, 2.4}));
  // Diagonal neighbours whose bounding circles overlap but boxes do not.
  EXPECT_FALSE(BoxesOverlap(ego, Box{4.5, 2.5, std::numbers::pi / 4, 4.6, 2.4}));
  EXPECT_TRUE(BoxesOverlap(ego, Box{4.0, 2.0, std::numbers::pi / 4, 4.6, 2.4}));
}

}  // namespace
}  // namespace frenetic::sim

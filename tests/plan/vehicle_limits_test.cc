// XyChecker's VehicleLimits: a real vehicle's steering angle and rate and its forward
// acceleration, measured on 0.1 s blocks of an XY path (points 0.02 s apart).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "frenetic/plan/feasibility.h"

namespace frenetic::plan {
namespace {

constexpr double kDt = 0.02;

// CommonRoad's vehicle 2 (BMW 320i).
VehicleLimits Bmw() {
  VehicleLimits v;
  v.wheelbase = 2.578;
  v.max_steer = 0.91;
  v.max_steer_rate = 0.4;
  v.max_accel = 11.5;
  v.switch_speed = 7.319;
  return v;
}

struct Path {
  std::vector<double> x, y;
};

// Along +x from speed v0 at constant acceleration a, with a lateral quintic move of `shift` m
// over T s starting at t0 (0: none), n points.
Path Drive(double v0, double a, int n, double shift = 0, double t0 = 0, double T = 1) {
  Path p;
  for (int i = 0; i < n; ++i) {
    const double t = i * kDt;
    p.x.push_back(v0 * t + 0.5 * a * t * t);
    const double u = std::clamp((t - t0) / T, 0.0, 1.0);
    p.y.push_back(shift * u * u * u * (10 - 15 * u + 6 * u * u));
  }
  return p;
}

XyMeasure Measure(const Path& p, const VehicleLimits& v) {
  XyChecker checker(1024, v);
  return checker.Measure(p.x.data(), p.y.data(), static_cast<int>(p.x.size()), 1);
}

TEST(VehicleLimitsTest, NotMeasuredWithoutLimits) {
  const XyMeasure m = Measure(Drive(30, 3, 200, 3.5, 1, 1), VehicleLimits{});
  EXPECT_EQ(m.steer_ratio, 0);
  EXPECT_EQ(m.steer_rate_ratio, 0);
  EXPECT_EQ(m.forward_accel_ratio, 0);
}

TEST(VehicleLimitsTest, ForwardAccelerationLimitFallsWithSpeed) {
  // 3 m/s^2 is within the limit from 15 to 18 m/s (11.5 x 7.319 / v: 5.6 to 4.7) but not at
  // 30 (2.8). The worst block is the last one, from ~17.7 m/s.
  const XyMeasure slow = Measure(Drive(15, 3, 50), Bmw());
  EXPECT_NEAR(slow.forward_accel_ratio, 3.0 / (11.5 * 7.319 / 17.7), 0.02);
  EXPECT_LT(slow.forward_accel_ratio, 1.0);
  const XyMeasure fast = Measure(Drive(30, 3, 150), Bmw());
  EXPECT_GT(fast.forward_accel_ratio, 1.0);
  // Braking is not a forward acceleration.
  EXPECT_LE(Measure(Drive(30, -8, 150), Bmw()).forward_accel_ratio, 0.0);
}

TEST(VehicleLimitsTest, SteeringRateOfALaneChange) {
  // 3.5 m in 4 s at 25 m/s: a gentle change; in 1 s: curvature swings faster than the steering
  // can follow (0.4 rad/s).
  const XyMeasure gentle = Measure(Drive(25, 0, 300, 3.5, 0.5, 4), Bmw());
  EXPECT_LT(gentle.steer_rate_ratio, 1.0);
  EXPECT_GT(gentle.steer_rate_ratio, 0.01);
  const XyMeasure abrupt = Measure(Drive(25, 0, 300, 3.5, 0.5, 1), Bmw());
  EXPECT_GT(abrupt.steer_rate_ratio, 1.0);
  EXPECT_LT(abrupt.steer_ratio, 1.0);  // the angle itself stays small
}

TEST(VehicleLimitsTest, SteeringAngleOfATightCircle) {
  // A circle of radius r at 5 m/s: delta = atan(2.578 / r): 1.2 m is past 0.91 rad, 10 m is not.
  for (const double r : {1.2, 10.0}) {
    Path p;
    for (int i = 0; i < 150; ++i) {
      const double a = 5.0 * i * kDt / r;
      p.x.push_back(r * std::sin(a));
      p.y.push_back(r - r * std::cos(a));
    }
    const XyMeasure m = Measure(p, Bmw());
    EXPECT_NEAR(m.steer_ratio, std::atan(2.578 / r) / 0.91, 0.01) << "r " << r;
  }
}

TEST(VehicleLimitsTest, NoSteeringAtACrawl) {
  // Sideways by 5 cm while creeping at 0.3 m/s: a curvature no steering gives, but a car at a
  // crawl turns its wheels as it likes; at 3 m/s the same path's steering is measured.
  const XyMeasure crawl = Measure(Drive(0.3, 0, 150, 0.05, 0.2, 2), Bmw());
  EXPECT_EQ(crawl.steer_ratio, 0.0);
  EXPECT_EQ(crawl.steer_rate_ratio, 0.0);
  const XyMeasure moving = Measure(Drive(3, 0, 150, 0.05, 0.2, 2), Bmw());
  EXPECT_GT(moving.steer_ratio, 0.0);
}

TEST(VehicleLimitsTest, NaNPathIsAViolation) {
  Path p = Drive(20, 0, 100);
  p.y[99] = NAN;
  const XyMeasure m = Measure(p, Bmw());
  EXPECT_TRUE(std::isnan(m.forward_accel_ratio));
}

}  // namespace
}  // namespace frenetic::plan

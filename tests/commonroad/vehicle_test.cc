#include <gtest/gtest.h>

#include <cmath>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/vehicle_params.h"

namespace frenetic::commonroad {
namespace {

TEST(VehicleParamsTest, TheThreeCommonRoadVehicles) {
  const VehicleParams bmw;  // the default, KS2
  EXPECT_EQ(bmw.type, 2);
  EXPECT_EQ(bmw.KsId(), "KS2");
  EXPECT_DOUBLE_EQ(bmw.length, 4.508);
  EXPECT_DOUBLE_EQ(bmw.width, 1.610);
  EXPECT_NEAR(bmw.a, 1.1561957064, 1e-12);  // 3.793293 ft
  EXPECT_NEAR(bmw.b, 1.4227170936, 1e-12);  // 4.667707 ft
  EXPECT_NEAR(bmw.Wheelbase(), 2.5789128, 1e-12);
  EXPECT_DOUBLE_EQ(bmw.steering_max, 1.066);
  EXPECT_DOUBLE_EQ(bmw.steering_rate_max, 0.4);
  EXPECT_DOUBLE_EQ(bmw.v_min, -13.6);
  EXPECT_DOUBLE_EQ(bmw.v_max, 50.8);
  EXPECT_DOUBLE_EQ(bmw.v_switch, 7.319);
  EXPECT_DOUBLE_EQ(bmw.a_max, 11.5);

  const StatusOr<VehicleParams> two = VehicleParamsForType(2);
  ASSERT_TRUE(two.ok());
  EXPECT_DOUBLE_EQ(two->b, bmw.b);

  const StatusOr<VehicleParams> ford = VehicleParamsForType(1);
  ASSERT_TRUE(ford.ok());
  EXPECT_EQ(ford->name, "Ford Escort");
  EXPECT_DOUBLE_EQ(ford->length, 4.298);
  EXPECT_DOUBLE_EQ(ford->width, 1.674);
  EXPECT_NEAR(ford->a, 0.88392, 1e-9);
  EXPECT_NEAR(ford->b, 1.50876, 1e-9);
  EXPECT_DOUBLE_EQ(ford->steering_max, 0.910);
  EXPECT_DOUBLE_EQ(ford->v_switch, 4.755);
  EXPECT_DOUBLE_EQ(ford->v_max, 45.8);
  EXPECT_DOUBLE_EQ(ford->v_min, -13.9);

  const StatusOr<VehicleParams> vw = VehicleParamsForType(3);
  ASSERT_TRUE(vw.ok());
  EXPECT_EQ(vw->KsId(), "KS3");
  EXPECT_DOUBLE_EQ(vw->length, 4.569);
  EXPECT_DOUBLE_EQ(vw->width, 1.844);
  EXPECT_NEAR(vw->a + vw->b, (3.775563 + 4.334437) * 0.3048, 1e-12);
  EXPECT_DOUBLE_EQ(vw->steering_min, -1.023);
  EXPECT_DOUBLE_EQ(vw->v_switch, 7.824);
  EXPECT_DOUBLE_EQ(vw->v_max, 41.7);

  for (int bad : {0, 4, -2}) {
    const StatusOr<VehicleParams> none = VehicleParamsForType(bad);
    ASSERT_FALSE(none.ok());
    EXPECT_NE(none.message().find(std::to_string(bad)), std::string::npos);
  }
}

TEST(VehicleParamsTest, AccelerationLimitFallsAboveTheSwitchingVelocity) {
  const VehicleParams p;
  EXPECT_DOUBLE_EQ(p.MaxAcceleration(0), 11.5);
  EXPECT_DOUBLE_EQ(p.MaxAcceleration(7.319), 11.5);
  EXPECT_DOUBLE_EQ(p.MaxAcceleration(20), 11.5 * 7.319 / 20);
  EXPECT_DOUBLE_EQ(p.MaxAcceleration(-5), 11.5);
}

TEST(KsModelTest, CentreIsBAheadOfTheRearAxle) {
  const VehicleParams p;
  KsState s;
  s.x = 10;
  s.y = 5;
  s.orientation = M_PI / 2;
  const Vec2 rear = RearAxle(s, p);
  EXPECT_NEAR(rear.x, 10, 1e-12);
  EXPECT_NEAR(rear.y, 5 - p.b, 1e-12);
  const Vec2 back = CenterFromRearAxle(rear, s.orientation, p);
  EXPECT_NEAR(back.x, 10, 1e-12);
  EXPECT_NEAR(back.y, 5, 1e-12);
}

TEST(KsModelTest, StraightConstantAcceleration) {
  const VehicleParams p;
  KsState s;
  s.velocity = 5;
  const KsState n = SimulateKs(s, {0, 2}, 0.1, p);
  EXPECT_EQ(n.time_step, 1);
  EXPECT_NEAR(n.velocity, 5.2, 1e-12);
  EXPECT_NEAR(n.x, 5 * 0.1 + 0.5 * 2 * 0.01, 1e-12);
  EXPECT_NEAR(n.y, 0, 1e-12);
}

TEST(KsModelTest, ConstantSteeringTurnsAtVOverWheelbaseTanDelta) {
  const VehicleParams p;
  KsState s;
  s.velocity = 10;
  s.steering_angle = 0.05;
  KsState n = s;
  for (int i = 0; i < 10; ++i) n = SimulateKs(n, {0, 0}, 0.1, p);
  const double yaw_rate = 10 / p.Wheelbase() * std::tan(0.05);
  EXPECT_NEAR(n.orientation, yaw_rate * 1.0, 1e-9);
  // The rear axle runs on a circle of radius l / tan(delta) about (x_r0, R).
  const double radius = p.Wheelbase() / std::tan(0.05);
  const Vec2 rear = RearAxle(n, p);
  EXPECT_NEAR(std::hypot(rear.x - (-p.b), rear.y - radius), radius, 1e-6);
}

TEST(KsModelTest, InputConstraintsAsCommonRoadAppliesThem) {
  const VehicleParams p;
  // Steering rate clipped, and zero at the steering limit when it would push beyond.
  EXPECT_DOUBLE_EQ(ConstrainInput(0, 10, {1.0, 0}, p).steering_rate, 0.4);
  EXPECT_DOUBLE_EQ(ConstrainInput(0, 10, {-1.0, 0}, p).steering_rate, -0.4);
  EXPECT_DOUBLE_EQ(ConstrainInput(1.066, 10, {0.3, 0}, p).steering_rate, 0);
  EXPECT_DOUBLE_EQ(ConstrainInput(1.066, 10, {-0.3, 0}, p).steering_rate, -0.3);
  // Acceleration: a_max, the v_switch rule, and zero at the velocity limits.
  EXPECT_DOUBLE_EQ(ConstrainInput(0, 5, {0, 20}, p).acceleration, 11.5);
  EXPECT_DOUBLE_EQ(ConstrainInput(0, 20, {0, 10}, p).acceleration, 11.5 * 7.319 / 20);
  EXPECT_DOUBLE_EQ(ConstrainInput(0, 20, {0, -20}, p).acceleration, -11.5);
  EXPECT_DOUBLE_EQ(ConstrainInput(0, 50.8, {0, 1}, p).acceleration, 0);
  EXPECT_DOUBLE_EQ(ConstrainInput(0, -13.6, {0, -1}, p).acceleration, 0);
  // So the simulation cannot accelerate past the limit.
  KsState s;
  s.velocity = 20;
  const KsState n = SimulateKs(s, {0, 10}, 0.1, p);
  EXPECT_LT(n.velocity, 20 + 0.1 * 11.5 * 7.319 / 20 + 1e-9);
}

}  // namespace
}  // namespace frenetic::commonroad

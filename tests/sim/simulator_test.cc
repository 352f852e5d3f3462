#include "frenetic/sim/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "sim_test_util.h"

namespace frenetic::sim {
namespace {

Scenario Default() { return Scenario(); }

TEST(Simulator, StartTelemetryMatchesTheRealFirstMessage) {
  FRENETIC_REQUIRE_UDACITY(world);
  ASSERT_TRUE(world->is_udacity_map);
  auto sim = Simulator::Create(world, Default(), 1);
  ASSERT_TRUE(sim.ok()) << sim.message();
  const plan::Telemetry t = (*sim)->Telemetry();
  EXPECT_FLOAT_EQ(t.x, 909.48f);
  EXPECT_FLOAT_EQ(t.y, 1128.67f);
  EXPECT_EQ(t.yaw, 0);
  EXPECT_EQ(t.speed, 0);
  EXPECT_NEAR(t.s, 124.8336, 1e-3);
  EXPECT_NEAR(t.d, 6.1648, 1e-3);
  EXPECT_TRUE(t.previous_path_x.empty());
  EXPECT_EQ(t.end_path_s, 0);
  EXPECT_EQ(t.end_path_d, 0);
  ASSERT_EQ(t.sensor_fusion.size(), 12u);
  int parked = 0;
  for (int i = 0; i < 12; ++i) {
    const plan::SensorCar& c = t.sensor_fusion[i];
    EXPECT_EQ(c.id, i);
    if (c.d < -200) {  // not spawned yet: parked off the road as in the real first message
      ++parked;
      EXPECT_GE(c.x, 762);
      EXPECT_LE(c.x, 776);
      EXPECT_GE(c.y, 1421);
      EXPECT_LE(c.y, 1442);
      EXPECT_EQ(c.vx, 0);
      EXPECT_GT(c.s, 6600);
      EXPECT_LT(c.d, -260);
      EXPECT_GT(c.d, -295);
    } else {  // spawned by the scheduler's first run, on the road
      EXPECT_GE(c.d, 0);
      EXPECT_LE(c.d, 12);
    }
  }
  EXPECT_GE(parked, 9);  // the first batch is 1-3 cars
  EXPECT_LE(parked, 11);
}

TEST(Simulator, ValidationVectorsThroughSensorFusion) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto sim = Simulator::Create(world, Default(), 1);
  ASSERT_TRUE(sim.ok());
  struct Vec { double x, y, s, d; };
  const Vec vectors[] = {{775.8, 1425.2, 6719.219, -280.149},
                         {1056.788, 1164.296, 275.778, 6.000},
                         {870.4026, 1132.156, 85.818, 2.667},
                         {1101.201, 1184.121, 324.833, 1.480}};
  Traffic& traffic = (*sim)->mutable_traffic();
  for (const Vec& v : vectors) {
    TrafficCar& car = traffic.mutable_cars()[5];
    car.spawned = false;
    car.x = v.x;
    car.y = v.y;
    std::vector<plan::SensorCar> rows;
    traffic.FillSensorFusion(&rows);
    EXPECT_NEAR(rows[5].s, v.s, 5e-3) << v.x;
    EXPECT_NEAR(rows[5].d, v.d, 2e-3) << v.x;
  }
}

TEST(Simulator, PathFollowingPreviousPathAndEndPath) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto created = Simulator::Create(world, Default(), 3);
  ASSERT_TRUE(created.ok());
  Simulator& sim = **created;
  std::vector<double> x, y;
  for (int i = 0; i < 50; ++i) {
    x.push_back(909.48 + 0.1 * i);  // point 0 is the car's position: trimmed
    y.push_back(1128.67);
  }
  ASSERT_TRUE(sim.ApplyPath(x, y).ok());
  EXPECT_EQ(sim.ego().path_size(), 49);
  sim.Advance(3);
  const plan::Telemetry t = sim.Telemetry();
  ASSERT_EQ(t.previous_path_x.size(), 46u);
  EXPECT_FLOAT_EQ(static_cast<float>(t.x), static_cast<float>(909.48 + 0.3));
  EXPECT_FLOAT_EQ(static_cast<float>(t.previous_path_x[0]), static_cast<float>(909.48 + 0.4));
  EXPECT_NEAR(t.speed, 5.0, 0.01);  // float32 positions near x = 909
  // end_path: the chord Frenet of the last point, segment chosen from the ego.
  EXPECT_NEAR(t.end_path_s, t.s + (x.back() - t.x), 0.05);
  EXPECT_NEAR(t.end_path_d, t.d, 0.05);
  // Unequal or non-finite paths are rejected with a message and change nothing.
  std::vector<double> shorter(y.begin(), y.end() - 1);
  Status bad = sim.ApplyPath(x, shorter);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("next_y"), std::string::npos);
  x[3] = std::nan("");
  EXPECT_FALSE(sim.ApplyPath(x, y).ok());
  EXPECT_EQ(sim.ego().path_size(), 46);
}

TEST(Simulator, ACloneRunsAsTheOriginalDoesAndApart) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto created = Simulator::Create(world, Default(), 3);
  ASSERT_TRUE(created.ok());
  Simulator& sim = **created;
  testing::DriveAlong(sim, 10.0, 20.0);
  sim.Advance(500);  // 10 s: traffic spawned and moving, random draws made
  const std::unique_ptr<Simulator> copy = sim.Clone();
  const plan::Telemetry before = sim.Telemetry();
  copy->Advance(250);
  // The original did not move with its copy.
  EXPECT_EQ(sim.ticks(), 500);
  EXPECT_EQ(sim.Telemetry().x, before.x);
  sim.Advance(250);
  const plan::Telemetry a = sim.Telemetry(), b = copy->Telemetry();
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.previous_path_x, b.previous_path_x);
  ASSERT_EQ(a.sensor_fusion.size(), b.sensor_fusion.size());
  int moving = 0;
  for (std::size_t i = 0; i < a.sensor_fusion.size(); ++i) {
    EXPECT_EQ(a.sensor_fusion[i].x, b.sensor_fusion[i].x) << i;
    EXPECT_EQ(a.sensor_fusion[i].y, b.sensor_fusion[i].y) << i;
    EXPECT_EQ(a.sensor_fusion[i].vx, b.sensor_fusion[i].vx) << i;
    moving += a.sensor_fusion[i].vx != 0 || a.sensor_fusion[i].vy != 0;
  }
  EXPECT_GT(moving, 3);
  EXPECT_EQ(sim.monitor().distance(), copy->monitor().distance());
  EXPECT_EQ(sim.lane_changes(), copy->lane_changes());
}

TEST(Simulator, StandsStillWithoutAPath) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto sim = Simulator::Create(world, Default(), 1);
  ASSERT_TRUE(sim.ok());
  (*sim)->Advance(50);
  EXPECT_FLOAT_EQ((*sim)->ego().x(), 909.48f);
  EXPECT_EQ((*sim)->monitor().distance(), 0);
}

TEST(Simulator, RearEndedByTrafficIsACollision) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scenario sc;
  sc.traffic.cars = 1;
  auto created = Simulator::Create(world, sc, 1);
  ASSERT_TRUE(created.ok());
  Simulator& sim = **created;
  TrafficCar& car = sim.mutable_traffic().mutable_cars()[0];
  // A fast car 8 m behind the standing ego, already too close to stop.
  car.spawned = true;
  car.queued = false;
  car.lane = 1;
  car.s = sim.ego_view().s - 8.0;
  car.d = sim.ego_view().d;
  car.v = 20;
  car.top_speed = 25;
  car.wander_amp = 0;
  sim.mutable_traffic().Place(car);
  sim.Advance(50);
  EXPECT_EQ(sim.monitor().counts()[static_cast<int>(IncidentKind::kCollision)], 1);
  EXPECT_EQ(sim.monitor().log().front().value, 0);
}

TEST(Simulator, StartPoseOptions) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scenario sc;
  sc.start.kind = StartPose::Kind::kFrenet;
  sc.start.s = -100;
  sc.start.d = 10;
  auto sim = Simulator::Create(world, sc, 1);
  ASSERT_TRUE(sim.ok());
  const plan::Telemetry t = (*sim)->Telemetry();
  EXPECT_NEAR(t.s, world->track.max_s - 100, 2.0);
  EXPECT_NEAR((*sim)->ego_view().d, 10, 1e-3);
  EXPECT_NEAR(t.d, 10, 1.5);  // the chord d: this segment's sagitta is about 1 m
  sc.start.kind = StartPose::Kind::kXY;
  sc.start.x = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(Simulator::Create(world, sc, 1).ok());
}

TEST(Simulator, RespawnSchedulerRunsAtTheFrameRate) {
  FRENETIC_REQUIRE_UDACITY(world);
  // The scheduler runs on rendered frames, every 21-60 of them: at 12.5 frames per second only
  // the scene-load batch (1-3 cars) is out after 1.6 s; at 50 more batches have followed.
  auto spawned_after = [&](double frame_rate, int ticks) {
    Scenario sc = Default();
    sc.traffic.frame_rate = frame_rate;
    auto sim = Simulator::Create(world, sc, 4);
    EXPECT_TRUE(sim.ok()) << sim.message();
    (*sim)->Advance(ticks);
    int n = 0;
    for (const TrafficCar& c : (*sim)->traffic().cars()) n += c.spawned ? 1 : 0;
    return n;
  };
  const int slow = spawned_after(12.5, 80);
  const int fast = spawned_after(50, 80);
  EXPECT_LE(slow, 3);
  EXPECT_GT(fast, slow);
  // 50 Hz is one frame per tick; a first frame-rate check in Validate.
  Scenario bad = Default();
  bad.traffic.frame_rate = 0;
  EXPECT_FALSE(bad.Validate().ok());
}

}  // namespace
}  // namespace frenetic::sim

#include "frenetic/sim/ego.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "frenetic/units.h"
namespace frenetic::sim {
namespace {

TEST(TrimStart, ClosestPointAfterTheFirstIsDroppedWithEverythingBefore) {
  const std::vector<float> x = {0, 1, 2, 3, 4}, y = {0, 0, 0, 0, 0};
  EXPECT_EQ(TrimStart(x, y, 2.1f, 0.3f), 3);  // k = 2: points 0..2 go
  EXPECT_EQ(TrimStart(x, y, 4.0f, 0.0f), 5);  // k = last: nothing is left
}

TEST(TrimStart, FirstPointKeptUnlessExactlyReached) {
  const std::vector<float> x = {10, 11, 12}, y = {5, 5, 5};
  EXPECT_EQ(TrimStart(x, y, 9.9f, 5.0f), 0);   // k = 0 at distance > 0: still ahead
  EXPECT_EQ(TrimStart(x, y, 10.0f, 5.0f), 1);  // k = 0 at distance exactly 0: dropped
}

TEST(TrimStart, TiesKeepTheFirstAndFarPathsAreKeptWhole) {
  const std::vector<float> x = {-1, 1, 3}, y = {0, 0, 0};
  EXPECT_EQ(TrimStart(x, y, 0.0f, 0.0f), 0);  // points 0 and 1 tie: k = 0, distance 1 > 0
  // Every point farther than the 10000 m start of the scan: k stays 0, nothing is dropped.
  const std::vector<float> fx = {20000, 20001}, fy = {0, 0};
  EXPECT_EQ(TrimStart(fx, fy, 0.0f, 0.0f), 0);
  EXPECT_EQ(TrimStart({}, {}, 0.0f, 0.0f), 0);
}

TEST(EgoCar, ApplyPathParsesToFloat32AndTrims) {
  EgoCar ego(909.48f, 1128.67f, 0);
  const std::vector<double> x = {909.48, 909.536, 909.6}, y = {1128.67, 1128.67, 1128.67};
  ego.ApplyPath(x, y);
  ASSERT_EQ(ego.path_size(), 2);  // point 0 is exactly the car's position: dropped
  EXPECT_EQ(ego.path_x()[0], static_cast<float>(909.536));
  EXPECT_NE(static_cast<double>(ego.path_x()[0]), 909.536);  // float32, as the simulator
}

TEST(EgoCar, TeleportsYawsTowardTheSecondPointAndNeverReachesTheLast) {
  EgoCar ego(0, 0, 0);
  const std::vector<double> x = {0.4, 0.8, 0.8}, y = {0, 0, 0.4};
  ego.ApplyPath(x, y);
  ASSERT_EQ(ego.path_size(), 3);
  ego.Tick();
  EXPECT_FLOAT_EQ(ego.x(), 0.4f);
  EXPECT_NEAR(ego.speed(), 20.0, 1e-4);  // 0.4 m in 0.02 s
  EXPECT_NEAR(ego.yaw(), 0.0, 1e-9);     // toward (0.8, 0) from (0, 0)
  ego.Tick();
  EXPECT_FLOAT_EQ(ego.x(), 0.8f);
  // From the pre-tick position (0.4, 0) toward (0.8, 0.4): 45 degrees.
  EXPECT_NEAR(ego.yaw(), std::numbers::pi / 4, 1e-6);
  ASSERT_EQ(ego.path_size(), 1);
  ego.Tick();  // one point left: stand still, the list is cleared
  EXPECT_FLOAT_EQ(ego.x(), 0.8f);
  EXPECT_FLOAT_EQ(ego.y(), 0.0f);
  EXPECT_EQ(ego.speed(), 0.0f);
  EXPECT_EQ(ego.path_size(), 0);
}

TEST(EgoCar, SpeedIsTheFloatDisplacementOverTheTick) {
  // §3.3: a 0.002 m step from x = 909.48 is logged as 0.2252774 mph (float32 positions).
  EgoCar ego(909.48f, 1128.67f, 0);
  const std::vector<double> x = {909.482, 909.484}, y = {1128.67, 1128.67};
  ego.ApplyPath(x, y);
  ego.Tick();
  EXPECT_NEAR(ego.speed() * units::kSimMpsToMph, 0.2252774, 2e-7);
}

}  // namespace
}  // namespace frenetic::sim

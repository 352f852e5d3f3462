#include "frenetic/drive/foresee.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/sim/traffic.h"
#include "sim/sim_test_util.h"

namespace frenetic::sim {
namespace {

TEST(Foresee, TheFuturesAreWhereTheCarsWillBeWhileTheEgoKeepsToItsPath) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto created = Simulator::Create(world, Scenario(), 3);
  ASSERT_TRUE(created.ok());
  Simulator& sim = **created;
  testing::DriveAlong(sim, 12.0, 30.0);
  sim.Advance(500);
  std::vector<plan::CarFuture> futures(1);  // cleared first
  Foresee(sim, 3.0, &futures);
  ASSERT_GE(futures.size(), 3u);
  std::vector<TrafficCar> now = sim.traffic().cars();
  for (const plan::CarFuture& f : futures) {
    EXPECT_DOUBLE_EQ(f.dt, 0.1);
    EXPECT_EQ(f.start, 0.0);
    ASSERT_EQ(f.x.size(), f.y.size());
    ASSERT_EQ(f.x.size(), f.v.size());
    ASSERT_EQ(f.x.size(), f.heading.size());
    EXPECT_GE(f.x.size(), 2u);
    EXPECT_LE(f.x.size(), 31u);  // 0..3 s
    for (const TrafficCar& c : now) {
      if (c.id != f.id) continue;
      EXPECT_TRUE(c.spawned);
      EXPECT_EQ(f.x[0], c.x);  // sample 0 is now
      EXPECT_EQ(f.y[0], c.y);
    }
  }
  // The ego keeps to its path (20 s of it left): the cars are where the futures said, 1 s and
  // 2 s on, exactly.
  for (int k : {10, 20}) {
    sim.Advance(50);
    int checked = 0;
    for (const plan::CarFuture& f : futures) {
      if (static_cast<int>(f.x.size()) <= k) continue;
      for (const TrafficCar& c : sim.traffic().cars()) {
        if (c.id != f.id) continue;
        EXPECT_EQ(f.x[k], c.x) << "car " << f.id << " at " << k;
        EXPECT_EQ(f.y[k], c.y) << "car " << f.id << " at " << k;
        EXPECT_NEAR(f.v[k], std::hypot(c.vx, c.vy), 1e-12);
        ++checked;
      }
    }
    EXPECT_GE(checked, 3) << k;
  }
}

}  // namespace
}  // namespace frenetic::sim

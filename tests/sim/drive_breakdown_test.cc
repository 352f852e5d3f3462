#include "frenetic/sim/drive_breakdown.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "frenetic/sim/scenario.h"
#include "frenetic/units.h"
#include "sim/sim_test_util.h"

namespace frenetic::sim {
namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

// A spawned car at `ds` m from the ego along s, in `lane` (centre d), at `v` m/s.
TrafficCar Car(int id, double ego_s, double ds, int lane, double v,
               const map::ReferenceLine& line) {
  TrafficCar c;
  c.id = id;
  c.spawned = true;
  c.s = line.WrapS(ego_s + ds);
  c.d = 2.0 + 4.0 * lane;
  c.v = v;
  return c;
}

// Drives the ego along lane `lane` at `v` for `ticks`, cars moving at their own speed; the
// leader gap is the bumper gap to the nearest car ahead in the ego's lane (4.6 m cars).
struct Drive {
  DriveBreakdown b;
  EgoView ego;
  double distance = 0;
  int lane = 1;
  std::vector<TrafficCar> cars;

  void Run(const map::ReferenceLine& line, double v, int ticks) {
    ego.speed = v;
    ego.d = 2.0 + 4.0 * lane;
    for (int i = 0; i < ticks; ++i) {
      ego.s = line.WrapS(ego.s + v * kTick);
      distance += v * kTick;
      double gap = kNone;
      for (TrafficCar& c : cars) {
        c.s = line.WrapS(c.s + c.v * kTick);
        const double ds = line.DiffS(c.s, ego.s);
        if (static_cast<int>(c.d / 4.0) == lane && ds > 0) gap = std::min(gap, ds - 4.6);
      }
      b.Update(kTick, ego, lane, false, distance, gap, cars, line);
    }
  }
};

TEST(DriveBreakdown, FreeRoadAtTheLimitIsNotFollowing) {
  FRENETIC_REQUIRE_UDACITY(world);
  Drive d;
  d.Run(*world->line, 22.0, 250);  // 49.2 mph for 5 s
  const LapBreakdown t = d.b.Total();
  EXPECT_NEAR(t.seconds, 5.0, 1e-9);
  EXPECT_NEAR(t.at_limit_s, 5.0, 1e-9);
  EXPECT_NEAR(t.at_limit_mph(), 22.0 * units::kSimMpsToMph, 1e-6);
  EXPECT_EQ(t.following_s, 0);
  EXPECT_EQ(t.missed_passes, 0);
  EXPECT_NEAR(t.avg_speed_mph(), 22.0 * units::kSimMpsToMph, 1e-6);
}

TEST(DriveBreakdown, FollowingWithOpenNeighbourLanesCountsMissedPassesOncePerSpell) {
  FRENETIC_REQUIRE_UDACITY(world);
  const map::ReferenceLine& line = *world->line;
  Drive d;
  d.cars = {Car(0, 0, 20, 1, 15.0, line)};  // a leader 20 m ahead, same speed
  d.Run(line, 15.0, 100);                     // 2 s: not yet a missed pass
  EXPECT_NEAR(d.b.Total().following_s, 2.0, 1e-9);
  EXPECT_NEAR(d.b.Total().following_open_s, 2.0, 1e-9);
  EXPECT_EQ(d.b.Total().missed_passes, 0);
  d.Run(line, 15.0, 400);  // 8 more s: both neighbour lanes open for >= 3 s, counted once each
  EXPECT_NEAR(d.b.Total().following_s, 10.0, 1e-9);
  EXPECT_EQ(d.b.Total().missed_passes, 2);
  EXPECT_EQ(d.b.Total().at_limit_s, 0);
}

TEST(DriveBreakdown, AnOccupiedNeighbourLaneIsNotAMissedPass) {
  FRENETIC_REQUIRE_UDACITY(world);
  const map::ReferenceLine& line = *world->line;
  // Leader ahead in lane 1; lane 0 taken beside the ego; lane 2 has room but a car 50 m ahead
  // as slow as the leader: nothing to gain there.
  Drive slow;
  slow.cars = {Car(0, 0, 20, 1, 15.0, line), Car(1, 0, 5, 0, 15.0, line),
               Car(2, 0, 50, 2, 15.0, line)};
  slow.Run(line, 15.0, 500);
  EXPECT_EQ(slow.b.Total().missed_passes, 0);
  EXPECT_EQ(slow.b.Total().following_open_s, 0);
  // The same with the lane-2 car faster than the leader: a pass missed there.
  Drive d;
  d.cars = {Car(0, 0, 20, 1, 15.0, line), Car(1, 0, 5, 0, 15.0, line),
            Car(2, 0, 50, 2, 20.0, line)};
  d.Run(line, 15.0, 500);
  EXPECT_EQ(d.b.Total().missed_passes, 1);
  EXPECT_NEAR(d.b.Total().following_open_s, 10.0, 1e-9);
  // A leader beyond the following reach (max(30 m, 3 s x 15 m/s) = 45 m) is not followed.
  Drive far;
  far.cars = {Car(0, 0, 60, 1, 15.0, line)};
  far.Run(line, 15.0, 500);
  EXPECT_EQ(far.b.Total().following_s, 0);
  EXPECT_EQ(far.b.Total().missed_passes, 0);
}

TEST(DriveBreakdown, PassesAndBeingPassedButNotRespawns) {
  FRENETIC_REQUIRE_UDACITY(world);
  const map::ReferenceLine& line = *world->line;
  Drive d;
  d.cars = {Car(0, 0, 10, 0, 15.0, line), Car(1, 0, -10, 2, 25.0, line)};
  d.Run(line, 20.0, 250);  // 5 s: the ego gains 25 m on car 0, car 1 gains 25 m on the ego
  EXPECT_EQ(d.b.Total().passes, 1);
  EXPECT_EQ(d.b.Total().passed_by, 1);
  // A car moved from 100 m ahead to 100 m behind with the same id is a respawn, not a pass.
  d.cars = {Car(2, d.ego.s, 100, 0, 20.0, line)};
  d.Run(line, 20.0, 10);
  d.cars[0].s = line.WrapS(d.ego.s - 100);
  d.Run(line, 20.0, 10);
  EXPECT_EQ(d.b.Total().passes, 1);
}

TEST(DriveBreakdown, SplitsByLapAndSums) {
  FRENETIC_REQUIRE_UDACITY(world);
  const map::ReferenceLine& line = *world->line;
  Drive d;
  const int ticks = static_cast<int>(line.length() / (22.0 * kTick)) + 100;
  d.Run(line, 22.0, ticks);  // a little more than one lap
  ASSERT_EQ(d.b.laps().size(), 2u);
  EXPECT_NEAR(d.b.laps()[0].distance_m, line.length(), 22.0 * kTick);
  EXPECT_NEAR(d.b.laps()[1].seconds, 100 * kTick, 2 * kTick);
  const LapBreakdown t = d.b.Total();
  EXPECT_EQ(t.lap, 2);
  EXPECT_NEAR(t.seconds, ticks * kTick, 1e-6);
  EXPECT_NEAR(t.distance_m, ticks * 22.0 * kTick, 1e-6);
}

}  // namespace
}  // namespace frenetic::sim

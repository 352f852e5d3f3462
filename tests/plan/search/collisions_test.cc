// The search planner's collision checks (CollisionChecker): the reach masks are the reach tests,
// and the boxes keep the headway and the room behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "plan/search/stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::Stages;
using testing::kS;

// StepsOf's reach masks bit by bit as FirstCollision's reach tests read (a car is kept unless
// it is farther than the reach along s or 5 m along d; NaN is kept), over a whole lattice in
// traffic, at both margin scales; and the first collision with them is the one without.
TEST(CollisionCheckerTest, StepsReachMasksAreTheReachTests) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ahead(-40.0, 70.0), speed(5.0, 24.0);
  std::vector<testing::SceneCar> cars;
  for (int k = 0; k < 14; ++k) {
    cars.push_back({kS + ahead(rng), st.ws.lane_center[k % 3], speed(rng)});
  }
  st.Prepare({kS, 18, 0, st.ws.lane_center[1], 0, 0}, cars);
  st.lattice.Generate();
  const int n_cand = static_cast<int>(st.ws.cand_lon.size());
  ASSERT_GT(n_cand, 500);
  const int w = st.ws.n_steps + 1;
  int near_bits = 0;
  for (const double scale : {1.0, 0.0}) {
    for (int c = 0; c < n_cand; c += 7) {
      const StepStates steps = st.collisions.StepsOf(c, scale, 1.0);
      for (int j = 1; j <= st.ws.n_steps; ++j) {
        const traj::FrenetState e = steps(j * st.ws.collision_step);
        const double reach = st.collisions.ReachS(e.s_d, scale, 1.0);
        std::uint64_t want = 0;
        for (int car = 0; car < std::min(st.ws.num_check_cars, 64); ++car) {
          const bool far = std::abs(st.ws.step_s[car * w + j] - e.s) > reach ||
                           std::abs(st.ws.step_d[car * w + j] - e.d) > 5;
          want |= far ? 0 : std::uint64_t{1} << car;
        }
        ASSERT_EQ(steps.Near(j), want) << "candidate " << c << " step " << j;
        near_bits += std::popcount(want);
      }
      const auto plain = [&steps](int tick) { return steps(tick); };  // no masks: every car
      EXPECT_EQ(st.collisions.FirstCollision(steps, scale, 1.0),
                st.collisions.FirstCollision(plain, scale, 1.0))
          << "candidate " << c;
    }
  }
  EXPECT_GT(near_bits, 1000) << "the scene has cars within reach";
}

// BareContact is FirstCollision on bare boxes without ghosts, measured once a cycle and read
// after; a new cycle's traffic measures anew. A bare contact within a candidate's check steps
// is a collision with the inflated boxes too (Selection skips that test then).
TEST(CollisionCheckerTest, BareContactIsTheBareFirstCollisionAndImpliesTheInflatedOne) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  ASSERT_TRUE(st.collisions.BareContactImpliesCollision());
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> gap(12.0, 70.0), speed(4.0, 24.0);
  int touching = 0, clear = 0;
  for (int scene = 0; scene < 3; ++scene) {
    std::vector<testing::SceneCar> cars;
    for (int k = 0; k < 3 + 2 * scene; ++k) {  // ahead and behind, none beside the ego
      const double s = k % 2 == 0 ? kS + gap(rng) : kS - gap(rng);
      cars.push_back({s, st.ws.lane_center[k % 3], speed(rng)});
    }
    st.Prepare({kS, 12.0 + 4 * scene, 0, st.ws.lane_center[1], 0, 0}, cars);
    st.lattice.Generate();
    const int n_cand = static_cast<int>(st.ws.cand_lon.size());
    for (int c = 0; c < n_cand; c += 3) {
      EXPECT_EQ(st.collisions.BareContactKnown(c), false) << "scene " << scene;
      const int bare = st.collisions.BareContact(c);
      EXPECT_TRUE(st.collisions.BareContactKnown(c));
      EXPECT_EQ(bare, st.collisions.FirstCollision(st.collisions.StepsOf(c, 0.0, 1.0), 0.0, 1.0,
                                                   nullptr, false))
          << "scene " << scene << " candidate " << c;
      EXPECT_EQ(st.collisions.BareContact(c), bare);
      if (bare <= st.ws.CheckSteps(c)) {
        EXPECT_TRUE(st.collisions.CandidateCollides(c)) << "scene " << scene << " candidate " << c;
        ++touching;
      } else {
        ++clear;
      }
    }
  }
  EXPECT_GT(touching, 100);
  EXPECT_GT(clear, 100);
}

TEST(CollisionCheckerTest, FindsBoxOverlapsWithHeadwayAndRoomBehind) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  auto steady = [](double s0, double v, double d) {
    return [=](int tick) { return traj::FrenetState{s0 + v * tick * kTickSeconds, v, 0, d, 0, 0}; };
  };
  const int none = st.ws.n_steps + 1;
  // Same lane, 13 m ahead at the ego's speed: bare boxes clear (13 > 4.8), but not the
  // headway (0.5 s at 20 m/s).
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 13, 6.0, 20}});
  int car = -1;
  EXPECT_EQ(st.collisions.FirstCollision(steady(kS, 20, 6.0), 1.0, 1.0, &car), 1);
  EXPECT_EQ(car, 0);
  EXPECT_EQ(st.collisions.FirstCollision(steady(kS, 20, 6.0), 0.0), none);
  // A slower car 40 m ahead is reached later: the first hit is a later step.
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 40, 6.0, 10}});
  const int hit = st.collisions.FirstCollision(steady(kS, 20, 6.0), 0.0);
  EXPECT_GT(hit, 10);
  EXPECT_LT(hit, none);
  // Collides() reads the ticks.
  st.WriteTicks(kS, 20, 6.0, [](double) { return 0.0; });
  EXPECT_TRUE(st.collisions.Collides());
  st.WriteTicks(kS, 8, 6.0, [](double) { return 0.0; });
  EXPECT_FALSE(st.collisions.Collides());
  // Cutting into a lane in front of a car there at the same speed, half the room behind
  // (margin_behind) away: bare boxes clear, but the room behind (kept even at margin scale 0)
  // is not. A metre beyond the room it is.
  const double tight = st.cfg.check.car_length + 0.5 * st.cfg.check.margin_behind;
  ASSERT_GT(0.5 * st.cfg.check.margin_behind, 1.0);
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS - tight, 2.0, 20}});
  EXPECT_LT(st.collisions.FirstCollision(steady(kS, 20, 2.0), 0.0, 1.0), none);
  EXPECT_EQ(st.collisions.FirstCollision(steady(kS, 20, 2.0), 0.0, 0.0), none);
  const double roomy = st.cfg.check.car_length + st.cfg.check.margin_behind + 1.0;
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS - roomy, 2.0, 20}});
  EXPECT_EQ(st.collisions.FirstCollision(steady(kS, 20, 2.0), 0.0, 1.0), none);
  // The same car in the ego's own lane at the start is its follower's business.
  st.Prepare({kS, 20, 0, 2.0, 0, 0}, {{kS - 10, 2.0, 20}});
  EXPECT_EQ(st.collisions.FirstCollision(steady(kS, 20, 2.0), 1.0, 1.0), none);
  // A stopped car 60 m ahead is hit headway_min at 20 m/s (10 m, 0.5 s) before bare boxes
  // touch; a car coming the other way (a two-way road's oncoming lane) is passed, not followed:
  // margin_s only.
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 60, 6.0, 0}});
  const int stopped_bare = st.collisions.FirstCollision(steady(kS, 20, 6.0), 0.0);
  EXPECT_GE(stopped_bare - st.collisions.FirstCollision(steady(kS, 20, 6.0), 1.0), 4);
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 60, 6.0, -20}});
  const int oncoming_bare = st.collisions.FirstCollision(steady(kS, 20, 6.0), 0.0);
  ASSERT_LT(oncoming_bare, none);
  EXPECT_LE(oncoming_bare - st.collisions.FirstCollision(steady(kS, 20, 6.0), 1.0), 1);
}

}  // namespace
}  // namespace frenetic::plan::search

// The search planner's hard checks: each limit rejects with its own reason, the lane-line timer,
// and the collision test's boxes, headway and room behind.
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

constexpr double kS = 800;

TEST(SearchChecksTest, SteadyDrivingIsFeasible) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  st.Prepare({kS, 20, 0, 6.0, 0, 0});
  st.WriteTicks(kS, 20, 6.0, [](double) { return 0.0; });
  Reject why = Reject::kSpeed;
  EXPECT_LE(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kCount);
}

TEST(SearchChecksTest, EachLimitRejectsWithItsReason) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  st.Prepare({kS, 20, 0, 6.0, 0, 0});
  Reject why = Reject::kCount;
  // 25 m/s is over 49.5 mph.
  st.WriteTicks(kS, 25, 6.0, [](double) { return 0.0; });
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kSpeed);
  // Braking that ramps to 11 m/s^2 over 1.5 s and back (jerk ~7 m/s^3): too hard.
  auto ramp = [](double peak) {
    return [peak](double t) {
      const double k = peak / 1.5;
      return t < 1.5 ? -k * t : t < 3.0 ? -peak + k * (t - 1.5) : 0.0;
    };
  };
  st.WriteTicks(kS, 22, 6.0, ramp(11));
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kAcceleration);
  st.WriteTicks(kS, 22, 6.0, ramp(7));
  EXPECT_LE(st.checker.Violation(&why), 0) << "7 m/s^2 is within the limit";
  // Off the road on the right.
  st.WriteTicks(kS, 20, 11.8, [](double) { return 0.0; });
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kOffRoad);
  // Backwards.
  st.WriteTicks(kS, -1, 6.0, [](double) { return 0.0; });
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kSpeed);
  // A NaN is a violation, never a pass.
  st.WriteTicks(kS, 20, 6.0, [](double) { return 0.0; });
  st.ws.tk_d[100] = NAN;
  EXPECT_GT(st.checker.Violation(&why), 0);
}

TEST(SearchChecksTest, JerkRejectsWithItsReason) {
  REQUIRE_UDACITY_MAP();
  // The simulator's acceleration is a magnitude, so with equal limits a jerk excess comes with
  // an acceleration one: a lower jerk limit isolates it.
  PlannerConfig config = testing::DefaultConfig();
  ASSERT_TRUE(config.Set("limits.max_jerk", 4).ok());
  Stages st(config);
  st.Prepare({kS, 20, 0, 6.0, 0, 0});
  // After a second of cruising (the jerk windows need the history), 6 m/s^2 of braking.
  st.WriteTicks(kS, 20, 6.0, [](double t) { return t < 1 ? 0.0 : t < 2.5 ? -6.0 : 0.0; });
  Reject why = Reject::kCount;
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kJerk);
  st.WriteTicks(kS, 20, 6.0, [](double t) { return t < 1 ? 0.0 : t < 2.5 ? -3.0 : 0.0; });
  EXPECT_LE(st.checker.Violation(&why), 0);
}

TEST(SearchChecksTest, LaneLineTimerCountsFromTheStartAndCanBeLeftOut) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  st.Prepare({kS, 20, 0, 4.0, 0, 0});
  // Astride the lane line to the end of the horizon: it would stay there.
  st.WriteTicks(kS, 20, 4.0, [](double) { return 0.0; });
  Reject why = Reject::kCount;
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kLaneLine);
  EXPECT_LE(st.checker.Violation(&why, /*lane_line=*/false), 0);
  // Astride for a second, then a smooth move into the lane (2.5 s): fine from a fresh timer,
  // not with 2.5 s already counted.
  for (int i = 1; i <= st.ws.n_ticks; ++i) {
    const double u = std::clamp((i * kTickSeconds - 1.0) / 2.5, 0.0, 1.0);
    st.ws.tk_d[i] = 4.0 + 2.0 * u * u * u * (10 - 15 * u + 6 * u * u);
  }
  st.ws.straddle_at_start = 0;
  EXPECT_LE(st.checker.Violation(&why), 0);
  st.ws.straddle_at_start = 125;
  EXPECT_GT(st.checker.Violation(&why), 0);
  EXPECT_EQ(why, Reject::kLaneLine);
  // The helpers agree: the line at 4 m is within kStraddle of 4.5, not of 5.
  EXPECT_TRUE(StraddlesRead(st.cfg, 4.5, 4.5));
  EXPECT_FALSE(StraddlesRead(st.cfg, 5.0, 5.0));
}

// The least-harm choice asks only whether a candidate breaks a limit, and the Frenet checks
// stop at the first one found broken: the answer is CandidateViolation's, and a verdict cut
// short that way is measured in full when the reason is asked for later.
TEST(SearchChecksTest, BreaksLimitsAgreesWithTheFullViolation) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  int broken = 0, cut_short_then_full = 0, total = 0;
  // Astride a line and in a lane, slow and fast, with the lane-line count fresh, near and past
  // its limit.
  for (const double d0 : {4.0, 5.2, 6.0, 9.9}) {
    for (const double v0 : {8.0, 21.5}) {
      for (const int straddle : {0, 120, 130, 200}) {
        st.Prepare({kS, v0, 0, d0, 0, 0});
        st.ws.straddle_at_start = straddle;
        st.lattice.Generate();
        ASSERT_TRUE(st.scorer.Score());
        const int n = static_cast<int>(st.ws.order.size());
        std::vector<char> breaks(n);
        for (int c = 0; c < n; ++c) breaks[c] = st.checker.CandidateBreaksLimits(c);
        for (int c = 0; c < n; ++c) {
          Reject why = Reject::kCount, why_ref = Reject::kCount;
          const double worst = st.checker.CandidateViolation(c, &why);
          st.checker.FillTicks(st.ws.Candidate(c));
          const double worst_ref = st.checker.Violation(&why_ref);
          ASSERT_EQ(breaks[c] != 0, worst_ref > 0) << "candidate " << c;
          EXPECT_EQ(worst, worst_ref) << "candidate " << c;
          EXPECT_EQ(why, why_ref) << "candidate " << c;
          broken += breaks[c];
          cut_short_then_full += breaks[c] && why == Reject::kLaneLine && straddle >= 120;
          ++total;
        }
      }
    }
  }
  EXPECT_GT(broken, total / 10);
  EXPECT_LT(broken, total);
  EXPECT_GT(cut_short_then_full, 0);
}

// StepsOf's reach masks bit by bit as FirstCollision's reach tests read (a car is kept unless
// it is farther than the reach along s or 5 m along d; NaN is kept), over a whole lattice in
// traffic, at both margin scales; and the first collision with them is the one without.
TEST(SearchChecksTest, StepsReachMasksAreTheReachTests) {
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
      const StepStates steps = st.checker.StepsOf(c, scale, 1.0);
      for (int j = 1; j <= st.ws.n_steps; ++j) {
        const traj::FrenetState e = steps(j * st.ws.collision_step);
        const double reach = st.checker.ReachS(e.s_d, scale, 1.0);
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
      EXPECT_EQ(st.checker.FirstCollision(steps, scale, 1.0),
                st.checker.FirstCollision(plain, scale, 1.0))
          << "candidate " << c;
    }
  }
  EXPECT_GT(near_bits, 1000) << "the scene has cars within reach";
}

TEST(SearchChecksTest, FindsBoxOverlapsWithHeadwayAndRoomBehind) {
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
  EXPECT_EQ(st.checker.FirstCollision(steady(kS, 20, 6.0), 1.0, 1.0, &car), 1);
  EXPECT_EQ(car, 0);
  EXPECT_EQ(st.checker.FirstCollision(steady(kS, 20, 6.0), 0.0), none);
  // A slower car 40 m ahead is reached later: the first hit is a later step.
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 40, 6.0, 10}});
  const int hit = st.checker.FirstCollision(steady(kS, 20, 6.0), 0.0);
  EXPECT_GT(hit, 10);
  EXPECT_LT(hit, none);
  // Collides() reads the ticks.
  st.WriteTicks(kS, 20, 6.0, [](double) { return 0.0; });
  EXPECT_TRUE(st.checker.Collides());
  st.WriteTicks(kS, 8, 6.0, [](double) { return 0.0; });
  EXPECT_FALSE(st.checker.Collides());
  // Cutting into a lane in front of a car there at the same speed, half the room behind
  // (margin_behind) away: bare boxes clear, but the room behind (kept even at margin scale 0)
  // is not. A metre beyond the room it is.
  const double tight = st.cfg.car_length + 0.5 * st.cfg.margin_behind;
  ASSERT_GT(0.5 * st.cfg.margin_behind, 1.0);
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS - tight, 2.0, 20}});
  EXPECT_LT(st.checker.FirstCollision(steady(kS, 20, 2.0), 0.0, 1.0), none);
  EXPECT_EQ(st.checker.FirstCollision(steady(kS, 20, 2.0), 0.0, 0.0), none);
  const double roomy = st.cfg.car_length + st.cfg.margin_behind + 1.0;
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS - roomy, 2.0, 20}});
  EXPECT_EQ(st.checker.FirstCollision(steady(kS, 20, 2.0), 0.0, 1.0), none);
  // The same car in the ego's own lane at the start is its follower's business.
  st.Prepare({kS, 20, 0, 2.0, 0, 0}, {{kS - 10, 2.0, 20}});
  EXPECT_EQ(st.checker.FirstCollision(steady(kS, 20, 2.0), 1.0, 1.0), none);
  // A stopped car 60 m ahead is hit headway_min at 20 m/s (10 m, 0.5 s) before bare boxes
  // touch; a car coming the other way (a two-way road's oncoming lane) is passed, not followed:
  // margin_s only.
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 60, 6.0, 0}});
  const int stopped_bare = st.checker.FirstCollision(steady(kS, 20, 6.0), 0.0);
  EXPECT_GE(stopped_bare - st.checker.FirstCollision(steady(kS, 20, 6.0), 1.0), 4);
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 60, 6.0, -20}});
  const int oncoming_bare = st.checker.FirstCollision(steady(kS, 20, 6.0), 0.0);
  ASSERT_LT(oncoming_bare, none);
  EXPECT_LE(oncoming_bare - st.checker.FirstCollision(steady(kS, 20, 6.0), 1.0), 1);
}

}  // namespace
}  // namespace frenetic::plan::search

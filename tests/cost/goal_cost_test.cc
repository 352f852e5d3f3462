// The goal term: how far a candidate misses a goal region within its time window.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "frenetic/cost/cost_registry.h"
#include "frenetic/cost/cost_term.h"

namespace frenetic::cost {
namespace {

constexpr int kSamples = 25;  // 6 s at 0.25 s
constexpr double kInf = std::numeric_limits<double>::infinity();

// A candidate at constant speed v along d = 2 from s = 0, with `goals`.
struct Case {
  std::vector<double> s, s_d, s_dd, d, d_d, d_dd;
  std::vector<GoalRegion> goals;
  CostContext ctx;
  CostInput in;
  explicit Case(double v, std::vector<GoalRegion> g, double a = 0) : goals(std::move(g)) {
    for (int k = 0; k < kSamples; ++k) {
      const double t = 0.25 * k;
      s.push_back(v * t + 0.5 * a * t * t);
      s_d.push_back(v + a * t);
      s_dd.push_back(a);
      d.push_back(2);
      d_d.push_back(0);
      d_dd.push_back(0);
    }
    ctx.num_samples = kSamples;
    ctx.dt = 0.25;
    ctx.num_goals = static_cast<int>(goals.size());
    ctx.goals = goals.data();
    in.s = s.data();
    in.s_d = s_d.data();
    in.s_dd = s_dd.data();
    in.d = d.data();
    in.d_d = d_d.data();
    in.d_dd = d_dd.data();
  }
};

GoalRegion Box(double s_lo, double s_hi, double t_lo, double t_hi) {
  GoalRegion g;
  g.s_lo = s_lo;
  g.s_hi = s_hi;
  g.d_lo = 0;
  g.d_hi = 4;
  g.t_lo = t_lo;
  g.t_hi = t_hi;
  return g;
}

class GoalCostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto made = CostRegistry::Global().Make("goal");
    ASSERT_TRUE(made.ok()) << made.message();
    term_ = std::move(made.value());
    Configure(0.0);
  }
  void Configure(double lateral_pace) {
    const std::vector<double> params = {10.0, 1.75, 5.0, 0.05, 1.0, 10.0, 1.0, 1.0, lateral_pace};
    term_->Configure(params);
  }
  double Eval(const Case& c) const { return term_->Evaluate(c.ctx, c.in); }
  std::unique_ptr<CostTerm> term_;
};

TEST_F(GoalCostTest, NothingWithoutAGoal) { EXPECT_EQ(Eval(Case(20, {})), 0.0); }

TEST_F(GoalCostTest, PassingThroughWithinTheWindowCostsNothing) {
  // At 20 m/s the ego is in [95, 105] from 4.75 s to 5.25 s.
  EXPECT_EQ(Eval(Case(20, {Box(95, 105, 4.0, 5.0)})), 0.0);
}

TEST_F(GoalCostTest, AShortBoxBetweenTwoSamplesIsStillPassed) {
  // A 2 m box: the samples at 20 m/s are 5 m apart (90.0 at 4.5 s, 95.0 at 4.75 s).
  EXPECT_EQ(Eval(Case(20, {Box(91.5, 93.5, 4.6, 4.65)})), 0.0);
}

TEST_F(GoalCostTest, TooEarlyOrTooLateCostsTheDistanceOverTheScale) {
  // The window [2, 3] s: at 20 m/s the ego is at 40-60 m then; the box starts at 100 m.
  EXPECT_NEAR(Eval(Case(20, {Box(100, 110, 2, 3)})), 1 + (100 - 60) / 10.0, 1e-9);
  // Past it already at the window's start (t = 1 s: 20 m, the box ends at 10 m).
  EXPECT_NEAR(Eval(Case(20, {Box(0, 10, 1, 2)})), 1 + 1.0, 1e-9);
}

TEST_F(GoalCostTest, BeyondTheSamplesTheCandidateGoesOnAtItsLastSpeed) {
  // The samples end at 6 s (120 m); at 20 m/s it reaches [200, 210] at 10-10.5 s.
  EXPECT_EQ(Eval(Case(20, {Box(200, 210, 10.2, 12)})), 0.0);
  EXPECT_NEAR(Eval(Case(20, {Box(200, 210, 7, 8)})), 1 + (200 - 160) / 10.0, 1e-9);
}

TEST_F(GoalCostTest, SpeedAndLateralMissesAddUp) {
  GoalRegion g = Box(95, 105, 4, 6);
  g.v_lo = 25;
  g.v_hi = 30;
  g.d_lo = 3.75;  // the candidate is at d = 2: 1.75 m off
  EXPECT_NEAR(Eval(Case(20, {g})), 1 + 5.0 / 5.0 + 1.75 / 1.75, 1e-9);
}

TEST_F(GoalCostTest, ThePassedWindowAndTheNearestGoalCount) {
  EXPECT_EQ(Eval(Case(20, {Box(500, 510, -3, -1)})), 0.0);  // over: nothing to steer for
  // Of two goals, the one missed least.
  EXPECT_NEAR(Eval(Case(20, {Box(300, 310, 2, 3), Box(100, 110, 2, 3)})), 1 + 4.0, 1e-9);
  // Capped.
  EXPECT_EQ(Eval(Case(20, {Box(5000, 5010, 2, 3)})), 10.0);
}

TEST_F(GoalCostTest, HeadingOutsideItsIntervalCounts) {
  // The candidate moves across at 1 m/s at 20 m/s: a heading whose tangent is 0.05 (measured as
  // tangents: 0.04996 rad).
  Case c(20, {});
  for (double& dd : c.d_d) dd = 1.0;
  GoalRegion g = Box(95, 105, 4, 6);
  g.d_hi = 1e9;
  g.h_lo = -std::tan(0.01);
  g.h_hi = std::tan(0.01);
  c.goals = {g};
  c.ctx.num_goals = 1;
  c.ctx.goals = c.goals.data();
  EXPECT_NEAR(Eval(c), 1 + (1.0 / 20 - std::tan(0.01)) / 0.05, 1e-9);
  c.goals[0].h_hi = std::tan(0.06);
  EXPECT_EQ(Eval(c), 0.0);
}

TEST_F(GoalCostTest, ARegionCrossedTurnedCreditsPassingAlongTheSideItIsEnteredFrom) {
  // A strip d in [-1, 1] crossed moving right, turned 0.2 to 0.6 (tangents): entered from the
  // left (smaller d). The candidate passes it at d = 2 going straight, then at d = -3.
  GoalRegion g = Box(95, 105, 4, 6);
  g.d_lo = -1;
  g.d_hi = 1;
  g.h_lo = 0.2;
  g.h_hi = 0.6;
  Case right(20, {g});
  // On the far side: 1 m and 0.2 of heading off the region, or 3 m off the side band
  // [-1 - 4, -1] (one lane width, 4 m by default) plus `approach` (1).
  EXPECT_NEAR(Eval(right), 1 + std::min(1 / 1.75 + 0.2 / 0.05, 1 + 3 / 1.75), 1e-9);
  Case left(20, {g});
  for (double& d : left.d) d = -3;
  EXPECT_NEAR(Eval(left), 1 + 1, 1e-9) << "in the side band: miss and approach only";
  // Crossing it: at a tangent of 0.04, a miss; at 0.2, nothing.
  Case swerve(20, {g});
  for (int k = 0; k < kSamples; ++k) {
    swerve.d[k] = -3 + 0.25 * k * 0.8;
    swerve.d_d[k] = 0.8;
  }
  EXPECT_GT(Eval(swerve), 0.0);
  for (int k = 0; k < kSamples; ++k) {
    swerve.d[k] = -20 + 0.25 * k * 4;  // d = 0 at 5 s (s = 100), tangent 0.2
    swerve.d_d[k] = 4;
  }
  EXPECT_EQ(Eval(swerve), 0.0);
  // A region turned less than kTurnedHeading is kept in a lane: no side band.
  g.h_lo = 0.5 * kTurnedHeading;
  Case slight(20, {g});
  for (double& d : slight.d) d = -3;
  EXPECT_NEAR(Eval(slight), 1 + 2 / 1.75 + 0.5 * kTurnedHeading / 0.05, 1e-9);
}

TEST_F(GoalCostTest, ASlantedRegionFollowsItsSlope) {
  // A strip 1 m wide whose middle climbs from d = 2 at s = 100 by 0.1 m per m. In the window
  // [5.4, 6] s the candidate (d = 2, 20 m/s) is at s = 108 first, where the strip spans
  // [2.3, 3.3]: 0.3 m off, and more later. In [4.9, 5.1] it crosses s = 100, inside the strip.
  GoalRegion g = Box(95, 115, 5.4, 6);
  g.d_lo = 1.5;
  g.d_hi = 2.5;
  g.s_ref = 100;
  g.d_slope = 0.1;
  EXPECT_NEAR(Eval(Case(20, {g})), 1 + 0.3 / 1.75, 1e-9);
  g.t_lo = 4.9;
  g.t_hi = 5.1;
  EXPECT_EQ(Eval(Case(20, {g})), 0.0);
}

TEST_F(GoalCostTest, NoPositionMeansTimeAndSpeedOnly) {
  GoalRegion g;
  g.t_lo = g.t_hi = 8.0;
  EXPECT_EQ(Eval(Case(20, {g})), 0.0);
  g.v_lo = 0;
  g.v_hi = 5;
  // Braking at 2 m/s^2 from 20: 8 m/s at 6 s, held: 3 m/s too fast at 8 s.
  EXPECT_NEAR(Eval(Case(20, {g}, -2)), 1 + 3.0 / 5.0, 1e-9);
}

// A candidate along d = 6, beside a region whose d is [0, 4] (the next lane), on a road open
// across to it (GoalRegion::across_open).
Case Beside(double v, double s_lo, double s_hi, bool open) {
  GoalRegion g = Box(s_lo, s_hi, 0, 100);
  g.across_open = open;
  Case c(v, {g});
  std::fill(c.d.begin(), c.d.end(), 6.0);
  return c;
}

TEST_F(GoalCostTest, ACandidateShortOfARegionInTheNextLaneMayStillMoveAcross) {
  // At 10 m/s the samples end at s = 60 (6 s); the region starts 90 m on. At 0.5 m/s across,
  // the 2 m to its side take 4 s (40 m): inside it before reaching it.
  const double straight = Eval(Beside(10, 150, 160, true));
  EXPECT_NEAR(straight, 1.0 + 2.0 / 1.75, 1e-9);  // lateral_pace 0: straight on along d = 6
  Configure(0.5);
  EXPECT_EQ(Eval(Beside(10, 150, 160, true)), 0.0);
  // Not on a road known to be open across (a ramp, a merge): straight on as before.
  EXPECT_NEAR(Eval(Beside(10, 150, 160, false)), straight, 1e-9);
}

TEST_F(GoalCostTest, PassingBesideARegionStaysAMissAndASlowerCandidateHasLongerToMove) {
  Configure(0.5);
  // At 30 m/s the samples pass [100, 110] along d = 6 (at 3.3-3.7 s): nothing is left to move.
  EXPECT_NEAR(Eval(Beside(30, 100, 110, true)), 1.0 + 2.0 / 1.75, 1e-9);
  // [80, 90]: at 10 m/s the samples end at 60, and its far end comes 3 s later with 0.5 m
  // across still to go; at 5 m/s (samples end at 30) it comes 10 s later, the move long done.
  const double at10 = Eval(Beside(10, 80, 90, true));
  EXPECT_NEAR(at10, 1.0 + 0.5 / 1.75, 1e-6);
  EXPECT_EQ(Eval(Beside(5, 80, 90, true)), 0.0);
}

// The term's meaning, evaluated densely: the least over its window (at most 1 ms apart, both
// ends included) of the miss of the candidate taken linear between its samples and straight on
// at its last speed after them.
double DenseMiss(const Case& c, const GoalRegion& g) {
  const auto out = [](double x, double lo, double hi) { return std::max({lo - x, 0.0, x - hi}); };
  const double t_end = (kSamples - 1) * 0.25, t0 = std::max(g.t_lo, 0.0);
  const double t1 = std::isfinite(g.t_hi) ? g.t_hi : t_end + 60.0;
  double best = kInf;
  const int steps = static_cast<int>(std::ceil((t1 - t0) / 0.001));
  for (int i = 0; i <= steps; ++i) {
    const double t = t0 + (t1 - t0) * i / std::max(steps, 1);
    double s, v;
    if (t >= t_end) {
      v = c.s_d[kSamples - 1];
      s = c.s[kSamples - 1] + v * (t - t_end);
    } else {
      const int k = static_cast<int>(t / 0.25);
      const double f = t / 0.25 - k;
      s = c.s[k] + f * (c.s[k + 1] - c.s[k]);
      v = c.s_d[k] + f * (c.s_d[k + 1] - c.s_d[k]);
    }
    best = std::min(best, out(s, g.s_lo, g.s_hi) / 10.0 + out(v, g.v_lo, g.v_hi) / 5.0);
  }
  return best > 0 ? std::min(1.0 + best, 10.0) : 0.0;
}

TEST_F(GoalCostTest, TheLeastMissIsExactForRegionsNearAndFar) {
  // Regions behind, among and far past the samples (the samples' span alone then bounds the
  // miss), windows short and long, speed bounds or none, candidates speeding up and slowing.
  // One just past the samples' span whose least miss lies inside it, not at a window's end:
  // slowing at 3 m/s^2 toward [70, 80] with a speed of 15-20 m/s wanted (at 4.6 s: 1 + 2.734;
  // at 6 s, the window's end, 1 + 3.0).
  // A candidate braking at 8 m/s^2 turns back at 2.5 s (its s not monotone); regions open at
  // one end and an endless window too.
  int checked = 0, missed = 0;
  for (const double a : {-8.0, -3.0, -2.0, 0.0, 2.0}) {
    for (const auto& [s_lo, s_hi] : {std::pair{-40.0, -30.0},
                                     {50.0, 60.0},
                                     {70.0, 80.0},
                                     {150.0, 160.0},
                                     {300.0, 310.0},
                                     {1000.0, 1010.0},
                                     {100.0, kInf},
                                     {-kInf, -10.0}}) {
      for (const auto& [t_lo, t_hi] :
           {std::pair{0.0, 3.0}, {2.0, 8.0}, {0.0, 40.0}, {7.0, 9.0}, {0.0, 6.0}, {1.0, kInf}}) {
        for (const auto& [v_lo, v_hi] :
             {std::pair{-kInf, kInf}, {25.0, 30.0}, {5.0, 8.0}, {15.0, 20.0}}) {
          GoalRegion g = Box(s_lo, s_hi, t_lo, t_hi);
          g.v_lo = v_lo;
          g.v_hi = v_hi;
          const Case c(20, {g}, a);
          const double dense = DenseMiss(c, g);
          EXPECT_NEAR(Eval(c), dense, 2e-3) << "a " << a << " s " << s_lo << " t [" << t_lo << ", "
                                            << t_hi << "] v [" << v_lo << ", " << v_hi << "]";
          EXPECT_LE(term_->LowerBound(c.ctx, c.in), Eval(c)) << "a " << a << " s " << s_lo;
          ++checked;
          missed += dense > 0;
        }
      }
    }
  }
  // Both kinds are in the grid: passed through and missed.
  EXPECT_EQ(checked, 960);
  EXPECT_GT(missed, 300);
  EXPECT_LT(missed, 900);
  {
    GoalRegion g = Box(70, 80, 0, 6);
    g.v_lo = 15;
    g.v_hi = 20;
    EXPECT_NEAR(Eval(Case(20, {g}, -3)), 1 + 2.734, 0.001);
  }
}

TEST_F(GoalCostTest, TheBoundIsTheValueWhereTheRegionIsOutOfReach) {
  // 20 m/s for 6 s, then on at 20 m/s to the window's close at 40 s: 800 m at most, 200 m short
  // of [1000, 1010] (1 + 20, capped: 10).
  const Case far(20, {Box(1000, 1010, 0, 40)});
  EXPECT_EQ(term_->LowerBound(far.ctx, far.in), 10.0);
  EXPECT_EQ(Eval(far), 10.0);
  // 90 m short of [890, 900] at 40 s: 1 + 9 (less the micrometre kept for rounding), the
  // value too.
  const Case short_of(20, {Box(890, 900, 0, 40)});
  EXPECT_NEAR(term_->LowerBound(short_of.ctx, short_of.in), 10.0, 1e-6);
  EXPECT_NEAR(Eval(short_of), 10.0, 1e-9);
  // Reached, or beside the lane only: no bound from s (0), while the value is the lateral miss.
  const Case reached(20, {Box(50, 60, 0, 40)});
  EXPECT_EQ(term_->LowerBound(reached.ctx, reached.in), 0.0);
  EXPECT_EQ(Eval(reached), 0.0);
  GoalRegion beside = Box(50, 60, 0, 40);
  beside.d_lo = 6;
  beside.d_hi = 10;
  const Case across(20, {beside});
  EXPECT_EQ(term_->LowerBound(across.ctx, across.in), 0.0);
  EXPECT_NEAR(Eval(across), 1 + 4 / 1.75, 1e-9);
  // Two regions: the nearer one bounds (behind the start by 40 m, window open: 1 + 4).
  const Case two(20, {Box(1000, 1010, 0, 40), Box(-50, -40, 0, 40)});
  EXPECT_NEAR(term_->LowerBound(two.ctx, two.in), 5.0, 1e-6);
  EXPECT_NEAR(Eval(two), 5.0, 1e-9);
  // A window already closed, or none left: nothing (as the value).
  const Case closed(20, {Box(1000, 1010, -5, -1)});
  EXPECT_EQ(term_->LowerBound(closed.ctx, closed.in), 0.0);
  EXPECT_EQ(Eval(closed), 0.0);
}

TEST_F(GoalCostTest, TheLastSampleCountsWhenTheWindowGoesOnPastIt) {
  // At 0.4 m/s, 10-12.4 m past a region behind it ([-20, -10]), moving across from d = 11 to 5
  // toward its side (d up to 4): the miss falls until the samples end (6 s) and grows after
  // them (straight on, farther from the region), so the least lies at the last sample:
  // 12.4 / 10 + 1 / 1.75, and 1 more for missing.
  Case c(0.4, {});
  for (int k = 0; k < kSamples; ++k) {
    c.d[k] = 11 - 0.25 * k;
    c.d_d[k] = -1;
  }
  c.goals = {Box(-20, -10, 0, 10)};
  c.ctx.num_goals = 1;
  c.ctx.goals = c.goals.data();
  EXPECT_NEAR(Eval(c), 1 + 1.24 + 1 / 1.75, 1e-9);
}

}  // namespace
}  // namespace frenetic::cost

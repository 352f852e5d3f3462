// The XY feasibility measure: Menger curvatures bit for bit, a measure with a prefix equal to the
// whole one, and the sliding check against the simulator's own blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "frenetic/plan/feasibility.h"
#include "frenetic/plan/planner.h"

namespace frenetic::plan {
namespace {

TEST(FeasibilityTest, CurvaturesOfAPathAreEachTriplesBitForBit) {
  // A wavy path with repeated points (a leg of no length), reversals, a zero chord, a point
  // far off and NaN: the run (two triples at a time) gives each triple's value exactly, from
  // an odd and an even first index.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> step(-0.4, 0.6);
  std::vector<double> x(301), y(301);
  for (int i = 1; i <= 300; ++i) {
    x[i] = x[i - 1] + 0.3 + step(rng);
    y[i] = y[i - 1] + 0.2 * step(rng);
  }
  x[40] = x[39], y[40] = y[39];   // no length
  x[80] = x[78], y[80] = y[78];   // back where it was: a zero chord
  x[120] = x[119] - 0.5;          // a reversal along x
  y[120] = y[119];
  y[118] = y[119];
  x[200] = 1e7;                    // far off
  y[250] = std::nan("");
  for (const int first : {1, 2, 37}) {
    std::vector<double> run(301, -1.0);
    MengerCurvatures(x.data(), y.data(), first, 301, run.data());
    for (int i = first; i < 300; ++i) {
      const double one = MengerCurvature(x[i - 1], y[i - 1], x[i], y[i], x[i + 1], y[i + 1]);
      EXPECT_EQ(std::memcmp(&run[i], &one, sizeof(double)), 0) << "triple " << i;
    }
    EXPECT_EQ(run[300], -1.0) << "the last point has no triple";
  }
  EXPECT_EQ(MengerCurvature(0, 0, 0, 0, 1, 0), 0.0);
  EXPECT_EQ(MengerCurvature(0, 0, 1, 0, 0, 0), 1e6);
}

TEST(FeasibilityTest, MeasureWithAPrefixEqualsTheWholeMeasure) {
  // A 400-tick path with speed changes and a bend; prefix of 120 points.
  std::vector<double> x, y;
  double px = 0, py = 0, h = 0, v = 15;
  for (int i = 0; i < 400; ++i) {
    v += (i < 150 ? 0.05 : -0.03);
    h += i > 200 && i < 260 ? 0.004 : 0.0;
    px += v * 0.02 * std::cos(h);
    py += v * 0.02 * std::sin(h);
    x.push_back(px);
    y.push_back(py);
  }
  XyChecker whole(512), cached(512);
  const XyMeasure a = whole.Measure(x.data(), y.data(), 400, 120);
  cached.SetPrefix(x.data(), y.data(), 120);
  const XyMeasure b = cached.MeasureWithPrefix(x.data(), y.data(), 400, 120);
  EXPECT_EQ(a.max_speed, b.max_speed);
  EXPECT_EQ(a.max_accel, b.max_accel);
  EXPECT_EQ(a.max_jerk, b.max_jerk);
  EXPECT_GT(a.max_accel, 0.5);
  // A different continuation of the same prefix is measured on its own points.
  for (int i = 300; i < 400; ++i) y[i] += 0.002 * (i - 300) * (i - 300);
  const XyMeasure c = whole.Measure(x.data(), y.data(), 400, 120);
  const XyMeasure d = cached.MeasureWithPrefix(x.data(), y.data(), 400, 120);
  EXPECT_EQ(c.max_accel, d.max_accel);
  EXPECT_EQ(c.max_jerk, d.max_jerk);
  EXPECT_GT(c.max_accel, a.max_accel);
}

TEST(FeasibilityTest, StopOverSkipsTheJerkOnlyWhenSpeedOrAccelerationIsOver) {
  // Speeding up from 10 m/s at 4 m/s^2 for 2 s, then on: acceleration ~4, jerk > 0.
  std::vector<double> x{0}, y(501, 0.0);
  double v = 10;
  for (int i = 1; i <= 500; ++i) {
    if (i <= 100) v += 4 * 0.02;
    x.push_back(x.back() + v * 0.02);
  }
  XyChecker full(1024), stopping(1024);
  const XyMeasure all = full.MeasureWithPrefix(x.data(), y.data(), 501, 1);
  ASSERT_GT(all.max_jerk, 0.5);
  ASSERT_GT(all.max_accel, 3.0);
  // Within every limit: measured in full, the same values.
  const XyLimits roomy{30, 9, 9};
  const XyMeasure within = stopping.MeasureWithPrefix(x.data(), y.data(), 501, 1, &roomy);
  EXPECT_EQ(within.max_jerk, all.max_jerk);
  EXPECT_EQ(within.max_accel, all.max_accel);
  // Acceleration over its limit, or speed over its own: the answer is known, the jerk is not
  // measured; what is reported is over its limit and never above the whole measure.
  for (const XyLimits over : {XyLimits{30, 3, 9}, XyLimits{15, 9, 9}}) {
    const XyMeasure cut = stopping.MeasureWithPrefix(x.data(), y.data(), 501, 1, &over);
    EXPECT_EQ(cut.max_jerk, 0.0);
    EXPECT_TRUE(cut.max_speed > over.max_speed || cut.max_accel > over.max_accel);
    EXPECT_LE(cut.max_speed, all.max_speed);
    EXPECT_LE(cut.max_accel, all.max_accel);
  }
}

// Asked only whether the speed or the acceleration is over (stop_over), the measure answers
// from the speeds alone when their block means change faster than the limit: the same answer
// as the whole measure, on paths that brake, speed up and bend at random, against limits on
// both sides of their values.
TEST(FeasibilityTest, StopOverAnswersAsTheWholeMeasureDoes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> accel(-14.0, 8.0), turn(-0.02, 0.02), limit(4.0, 14.0);
  XyChecker full(1024), stopping(1024);
  int over = 0, within = 0, early = 0;
  for (int path = 0; path < 200; ++path) {
    std::vector<double> x{0}, y{0};
    double v = 25, h = 0, a = accel(rng), w = turn(rng);
    for (int i = 1; i <= 300; ++i) {
      if (i % 60 == 0) {
        a = accel(rng);
        w = turn(rng);
      }
      v = std::max(0.0, v + a * 0.02);
      h += w * v * 0.02;
      x.push_back(x.back() + v * 0.02 * std::cos(h));
      y.push_back(y.back() + v * 0.02 * std::sin(h));
    }
    full.SetPrefix(x.data(), y.data(), 30);
    stopping.SetPrefix(x.data(), y.data(), 30);
    const XyMeasure all = full.MeasureWithPrefix(x.data(), y.data(), 301, 30);
    const XyLimits lim{40, limit(rng), 9};
    const XyMeasure cut = stopping.MeasureWithPrefix(x.data(), y.data(), 301, 30, &lim);
    const bool all_over = all.max_speed > lim.max_speed || all.max_accel > lim.max_accel;
    const bool cut_over = cut.max_speed > lim.max_speed || cut.max_accel > lim.max_accel;
    EXPECT_EQ(cut_over, all_over) << "path " << path;
    over += all_over;
    within += !all_over;
    early += cut_over && cut.max_accel < all.max_accel;  // answered before the curvature
  }
  EXPECT_GT(over, 20);
  EXPECT_GT(within, 20);
  EXPECT_GT(early, 10) << "the speeds alone never answered";
}

TEST(FeasibilityTest, SlidingCheckBoundsTheSimulatorsMeasureAndSeesKinks) {
  // From rest at 2 m/s^2 to 22 m/s, then straight on, with a 4 degree kink at tick 800.
  std::vector<double> x{0}, y{0};
  double px = 0, py = 0, heading = 0, v = 0;
  for (int i = 1; i < 1000; ++i) {
    if (i == 800) heading += 4.0 * M_PI / 180.0;
    v = std::min(22.0, v + 2.0 * kTickSeconds);
    px += v * kTickSeconds * std::cos(heading);
    py += v * kTickSeconds * std::sin(heading);
    x.push_back(px);
    y.push_back(py);
  }
  XyChecker checker(1000);
  const XyMeasure sliding = checker.Measure(x.data(), y.data(), 1000, 0);
  double sim_worst = 0;
  for (int phase = 0; phase < 10; ++phase) {
    const XyMeasure sim = MeasureLikeSimulator(x, y, phase);
    EXPECT_LE(sim.max_accel, sliding.max_accel + 1e-9);
    sim_worst = std::max(sim_worst, sim.max_accel);
  }
  // Blocks whose boundary splits the kink's triple do not see it: some phase does.
  EXPECT_GT(sim_worst, 9.0);
  EXPECT_GT(sliding.max_accel, 9.0);  // the kink is an incident
  EXPECT_NEAR(sliding.max_speed, 22, 1e-9);
  // Before the kink the path is clean (2 m/s^2; the jerk of switching it off is 2 m/s^3).
  const XyMeasure clean = checker.Measure(x.data(), y.data(), 790, 0);
  EXPECT_NEAR(clean.max_accel, 2.0, 1e-6);
  EXPECT_LT(clean.max_jerk, 2.0 + 1e-6);
}

}  // namespace
}  // namespace frenetic::plan

// Reading a planner's path at a step size that need not be whole ticks (path_time.h).
#include "frenetic/commonroad/path_time.h"

#include <gtest/gtest.h>

#include <cmath>

namespace frenetic::commonroad {
namespace {

TEST(PathTimeTest, AWholeNumberOfTicksReadsThePointItself) {
  for (const double t : {0.02, 0.04, 0.1, 0.2, 4.0}) {
    const PathIndex in = PathIndexAt(t);
    EXPECT_EQ(in.lo, static_cast<int>(std::lround(t / plan::kTickSeconds)) - 1) << t;
    EXPECT_EQ(in.frac, 0.0) << t;
  }
  // Between two points, the share of the way from the first.
  const PathIndex half = PathIndexAt(0.05);  // 2.5 ticks: between the 2nd and 3rd point
  EXPECT_EQ(half.lo, 1);
  EXPECT_NEAR(half.frac, 0.5, 1e-12);
  const PathIndex third = PathIndexAt(1.0 / 30);  // 30 Hz: 1.67 ticks
  EXPECT_EQ(third.lo, 0);
  EXPECT_NEAR(third.frac, 1.0 / 0.6 - 1.0, 1e-12);
  // Before the first point, or no time at all: the first point.
  EXPECT_EQ(PathIndexAt(0.01).lo, 0);
  EXPECT_EQ(PathIndexAt(NAN).lo, 0);
}

TEST(PathTimeTest, WholeTicksConsumedKeepTheirPhaseWithinHalfATickAndAddUpToTheTime) {
  // Whole ticks a step: that many, no phase, ever.
  for (const double dt : {0.02, 0.04, 0.1, 0.2}) {
    double phase = 0;
    for (int k = 0; k < 1000; ++k) {
      ASSERT_EQ(TicksConsumed(dt, &phase), static_cast<int>(std::lround(dt / plan::kTickSeconds)))
          << dt;
      ASSERT_EQ(phase, 0.0) << dt;
    }
  }
  // 0.05 s a step: 3 points, then 2 (2.5 ticks), the phase 0.01 s, then 0; 1/30 s: 5 points
  // every 3 steps (0.1 s), the phase never past half a tick.
  double phase = 0;
  for (int k = 0; k < 1000; ++k) {
    ASSERT_EQ(TicksConsumed(0.05, &phase), 3) << k;
    ASSERT_NEAR(phase, 0.01, 1e-12) << k;
    ASSERT_EQ(TicksConsumed(0.05, &phase), 2) << k;
    ASSERT_EQ(phase, 0.0) << k;
  }
  phase = 0;
  for (int k = 0; k < 1000; ++k) {
    int three = 0;
    for (int j = 0; j < 3; ++j) {
      three += TicksConsumed(1.0 / 30, &phase);
      ASSERT_LE(std::abs(phase), 0.5 * plan::kTickSeconds + 1e-12) << k;
    }
    ASSERT_EQ(three, 5) << k;
  }
  // A step no path is that long: a million points, not an overflow.
  phase = 0;
  EXPECT_EQ(TicksConsumed(1e9, &phase), 1000000);
  EXPECT_EQ(PathIndexAt(1e9).lo, 1000000);
}

}  // namespace
}  // namespace frenetic::commonroad

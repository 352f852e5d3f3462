// Reading a planner's path at a step size that need not be whole ticks (path_time.h).
#include "frenetic/commonroad/path_time.h"

#include <cmath>

#include <gtest/gtest.h>

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
  // 0.05 s and 1/30 s a step: the points consumed over many steps are the time passed, to half
  // a tick, and the phase never exceeds half a tick.
  for (const double dt : {0.05, 1.0 / 30}) {
    double phase = 0;
    long total = 0;
    for (int k = 1; k <= 3000; ++k) {
      total += TicksConsumed(dt, &phase);
      ASSERT_LE(std::abs(phase), 0.5 * plan::kTickSeconds + 1e-12) << dt << " step " << k;
      ASSERT_NEAR(total * plan::kTickSeconds, k * dt + phase, 1e-9) << dt << " step " << k;
    }
  }
}

}  // namespace
}  // namespace frenetic::commonroad

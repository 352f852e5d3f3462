// frenetic::UsableCores, what every --jobs 0 (drive, commonroad, tune, fidelity) and serve's
// --planning-threads 0 start from: the cores this process may run on, not the machine's.
#include "frenetic/cores.h"

#include <gtest/gtest.h>

#if defined(__linux__)
#include <sched.h>
#endif

namespace frenetic {
namespace {

#if defined(__linux__)
TEST(UsableCores, AreTheAffinityMasksCoresNotTheMachines) {
  cpu_set_t saved;
  CPU_ZERO(&saved);
  ASSERT_EQ(sched_getaffinity(0, sizeof(saved), &saved), 0);
  EXPECT_EQ(UsableCores(), CPU_COUNT(&saved));
  // Pinned to one core (taskset -c N): one, whatever the machine has.
  int first = 0;
  while (first < CPU_SETSIZE && !CPU_ISSET(first, &saved)) ++first;
  ASSERT_LT(first, CPU_SETSIZE);
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  ASSERT_EQ(sched_setaffinity(0, sizeof(one), &one), 0);
  const int pinned = UsableCores();
  ASSERT_EQ(sched_setaffinity(0, sizeof(saved), &saved), 0);
  EXPECT_EQ(pinned, 1);
  EXPECT_EQ(UsableCores(), CPU_COUNT(&saved));
}
#endif

TEST(UsableCores, AreAtLeastOne) { EXPECT_GE(UsableCores(), 1); }

}  // namespace
}  // namespace frenetic

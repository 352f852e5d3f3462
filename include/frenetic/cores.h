// The cores this process may run on: the count of its CPU affinity mask (taskset, a container's
// cpuset), else std::thread::hardware_concurrency(), at least 1. Every `--jobs 0` means these:
// a run pinned to one core (`taskset -c 1 frenetic commonroad ...`, as the timing notes measure)
// then plans on one thread, and its per-cycle times are not those of two threads sharing a core.
#pragma once

#include <algorithm>
#include <thread>

#if defined(__linux__)
#include <sched.h>
#endif

namespace frenetic {

inline int UsableCores() {
#if defined(__linux__)
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
#endif
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace frenetic

// The process's allocation counters, for the tests and the benchmarks: every malloc, calloc and
// realloc passed to glibc while `g_count_allocations` is set, C libraries' included (NLopt
// allocates its work arrays with malloc inside nlopt_optimize). The planner library interposes
// the C heap (frenetic/plan/scratch_heap.h) and counts there; under sanitizers, which own malloc,
// nothing is counted and kAllocationsCounted is false (callers skip their checks).
#pragma once

#include "frenetic/plan/scratch_heap.h"

namespace frenetic::testing_util {
using plan::heap::g_allocations;
using plan::heap::g_count_allocations;
inline constexpr bool kAllocationsCounted = plan::heap::kInterposed;
}  // namespace frenetic::testing_util

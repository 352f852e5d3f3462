// The interposed C heap: inside a ScratchScope the thread's C allocations come from its slot and
// are counted nowhere; outside, glibc's (counted); the slot is wound back once all is freed.
#include "frenetic/plan/scratch_heap.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <nlopt.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace frenetic::plan::heap {
namespace {

// The allocations passed to glibc while `f` runs.
template <typename F>
std::int64_t Counted(F f) {
  g_allocations = 0;
  g_count_allocations = true;
  f();
  g_count_allocations = false;
  return g_allocations;
}

// A malloc the optimiser cannot see through (the pointer escapes to an opaque free).
void* volatile g_sink = nullptr;

TEST(ScratchHeapTest, AScopeServesTheThreadFromItsSlotAndWindsItBack) {
  if (!kInterposed) GTEST_SKIP() << "malloc is the sanitizer's";
  {
    const ScratchScope scope;
    const std::int64_t n = Counted([] {
      char* a = static_cast<char*>(std::malloc(100));
      ASSERT_NE(a, nullptr);
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a) % 16, 0u);
      std::memset(a, 7, 100);
      int* b = static_cast<int*>(std::calloc(10, sizeof(int)));
      ASSERT_NE(b, nullptr);
      for (int i = 0; i < 10; ++i) EXPECT_EQ(b[i], 0);
      char* c = static_cast<char*>(std::realloc(a, 300));  // grown: the bytes come along
      ASSERT_NE(c, nullptr);
      for (int i = 0; i < 100; ++i) ASSERT_EQ(c[i], 7);
      EXPECT_EQ(ThreadSlotUse().live, 2);
      EXPECT_GE(ThreadSlotUse().bytes, 100u + 40u + 300u);
      std::free(b);
      std::free(c);
    });
    EXPECT_EQ(n, 0);
    EXPECT_EQ(ThreadSlotUse().live, 0);
  }
  EXPECT_EQ(ThreadSlotUse().bytes, 0u);  // wound back at the scope's end
  // Outside a scope: glibc, counted.
  EXPECT_EQ(Counted([] {
              g_sink = std::malloc(64);
              std::free(g_sink);
            }),
            1);
}

TEST(ScratchHeapTest, APauseAndABlockLeftLiveKeepTheSlot) {
  if (!kInterposed) GTEST_SKIP() << "malloc is the sanitizer's";
  void* kept = nullptr;
  {
    const ScratchScope scope;
    {
      const ScratchPause pause;  // a callback's buffer that outlives the scope: glibc's
      EXPECT_EQ(Counted([] { g_sink = std::malloc(32); }), 1);
      std::free(g_sink);
    }
    kept = std::malloc(48);  // from the slot, and still live when the scope ends
    EXPECT_EQ(ThreadSlotUse().live, 1);
  }
  const std::size_t used = ThreadSlotUse().bytes;
  EXPECT_GT(used, 0u);  // not wound back while a block is live
  {
    const ScratchScope scope;
    void* volatile more = std::malloc(16);
    EXPECT_NE(more, kept);
    EXPECT_GT(ThreadSlotUse().bytes, used);  // after the live block, not over it
    std::free(more);
  }
  std::free(kept);  // freed outside any scope: known by its address
  { const ScratchScope scope; }
  EXPECT_EQ(ThreadSlotUse().bytes, 0u);
  EXPECT_EQ(ThreadSlotUse().live, 0);
}

TEST(ScratchHeapTest, BeyondTheSlotGlibcServesAndABlockMayBeFreedOnAnotherThread) {
  if (!kInterposed) GTEST_SKIP() << "malloc is the sanitizer's";
  void* mine = nullptr;
  {
    const ScratchScope scope;
    EXPECT_EQ(Counted([] {
                g_sink = std::malloc(kSlotBytes + 1);  // larger than a slot
                std::free(g_sink);
              }),
              1);
    mine = std::malloc(64);
  }
  // (Threads are started outside scopes: a thread's start allocates what outlives it.)
  std::thread other([mine] { std::free(mine); });
  other.join();
  EXPECT_EQ(ThreadSlotUse().live, 0);
  { const ScratchScope scope; }
  EXPECT_EQ(ThreadSlotUse().bytes, 0u);
  // A thread's own scope gets a slot of its own.
  std::int64_t live_there = -1;
  std::thread another([&live_there] {
    const ScratchScope scope;
    void* volatile p = std::malloc(80);
    live_there = ThreadSlotUse().live;
    std::free(p);
  });
  another.join();
  EXPECT_EQ(live_there, 1);
  EXPECT_EQ(ThreadSlotUse().live, 0);
}

// As glibc's: realloc(p, 0) frees p and returns null; malloc_usable_size answers for a block of
// the slot; the aligned allocations are glibc's and counted.
TEST(ScratchHeapTest, ReallocToZeroUsableSizeAndAlignedAllocationsAsGlibc) {
  if (!kInterposed) GTEST_SKIP() << "malloc is the sanitizer's";
  {
    const ScratchScope scope;
    void* p = std::malloc(20);
    EXPECT_EQ(malloc_usable_size(p), 32u);
    EXPECT_EQ(std::realloc(p, 0), nullptr);
    EXPECT_EQ(ThreadSlotUse().live, 0);
    const std::int64_t counted = Counted([] {
      void* a = nullptr;
      EXPECT_EQ(posix_memalign(&a, 64, 100), 0);
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a) % 64, 0u);
      EXPECT_GE(malloc_usable_size(a), 100u);  // glibc's own answer
      std::free(a);
      g_sink = std::aligned_alloc(32, 64);
      std::free(g_sink);
    });
    EXPECT_EQ(counted, 2);
    void* a = nullptr;
    EXPECT_EQ(posix_memalign(&a, 3, 8), EINVAL);
  }
  EXPECT_EQ(ThreadSlotUse().bytes, 0u);
}

double Bowl(unsigned n, const double* x, double* grad, void*) {
  (void)grad;
  double f = 0;
  for (unsigned i = 0; i < n; ++i) f += (x[i] - 0.3 * i) * (x[i] - 0.3 * i);
  return f;
}

// What the planner's refinement relies on: nlopt_optimize mallocs on every call (counted
// without a scope) and frees all of it (nothing counted, nothing left live, with one).
TEST(ScratchHeapTest, NloptOptimizeAllocatesOnlyFromTheSlot) {
  if (!kInterposed) GTEST_SKIP() << "malloc is the sanitizer's";
  nlopt_opt opt = nlopt_create(NLOPT_LN_COBYLA, 4);
  ASSERT_NE(opt, nullptr);
  nlopt_set_min_objective(opt, &Bowl, nullptr);
  nlopt_set_maxeval(opt, 30);
  const double lo[4] = {-1, -1, -1, -1}, hi[4] = {1, 1, 1, 1};
  nlopt_set_lower_bounds(opt, lo);
  nlopt_set_upper_bounds(opt, hi);
  const double start[4] = {0.5, 0.5, 0.5, 0.5};
  const auto run = [&] {
    double x[4] = {start[0], start[1], start[2], start[3]}, f = 0;
    EXPECT_GT(nlopt_optimize(opt, x, &f), 0);
    EXPECT_LT(f, Bowl(4, start, nullptr, nullptr));
  };
  EXPECT_GT(Counted(run), 0);
  for (int i = 0; i < 3; ++i) {
    const ScratchScope scope;
    EXPECT_EQ(Counted(run), 0);
    EXPECT_EQ(ThreadSlotUse().live, 0);
  }
  nlopt_destroy(opt);
}

}  // namespace
}  // namespace frenetic::plan::heap

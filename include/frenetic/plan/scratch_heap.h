// The process's C heap, interposed, so that a library call that mallocs its scratch on every
// call (NLopt's nlopt_optimize allocates its work arrays per call and has no API to hand it a
// workspace) allocates nothing after warm-up: inside a ScratchScope, the calling thread's
// malloc, calloc and realloc are served from the thread's slot of one reserved region (a bump
// pointer, wound back when everything it handed out has been freed); anywhere else, and when a
// slot is full, they go to glibc (its __libc_* entry points). free() knows the region's pointers
// by their address, on any thread. The planner's refinement runs NLopt in a scope and pauses it
// (ScratchPause) around its own callbacks, whose buffers live on.
//
// Sanitizer builds own malloc: nothing is interposed there (kInterposed is false), scopes do
// nothing and nothing is counted.
//
// The interposer also counts the allocations it passes to glibc while g_count_allocations is
// set (the aligned ones too: posix_memalign, aligned_alloc, memalign, valloc, pvalloc), C
// libraries' included: the tests' and the benchmarks' allocation counters. realloc(p, 0) frees
// p and returns null, as glibc's; malloc_usable_size knows the region's blocks.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "frenetic/sanitizers.h"

// FRENETIC_HEAP_INTERPOSED may be given (CMake sets it to 0 for every sanitizer but UBSan's:
// LeakSanitizer, for one, defines no macro of its own and owns the aligned allocations).
#ifndef FRENETIC_HEAP_INTERPOSED
#define FRENETIC_HEAP_INTERPOSED (!FRENETIC_HEAP_SANITIZER)
#endif

namespace frenetic::plan::heap {

inline constexpr bool kInterposed = FRENETIC_HEAP_INTERPOSED != 0;

// Counted: every malloc, calloc and realloc passed to glibc while set (any thread).
extern std::atomic<bool> g_count_allocations;
extern std::atomic<std::int64_t> g_allocations;

// The bytes of one thread's slot, and how many slots the region has (threads beyond them, and
// requests beyond a slot, are served by glibc).
inline constexpr std::size_t kSlotBytes = std::size_t{256} << 10;
inline constexpr int kSlots = 256;

// While one lives, the thread's allocations come from its slot (nested scopes: the outermost
// counts). The first scope of a thread claims a slot (given back when the thread ends).
class ScratchScope {
 public:
  ScratchScope();
  ~ScratchScope();
  ScratchScope(const ScratchScope&) = delete;
  ScratchScope& operator=(const ScratchScope&) = delete;
};

// While one lives, the thread's allocations go to glibc again (a callback inside a scope whose
// buffers outlive it).
class ScratchPause {
 public:
  ScratchPause();
  ~ScratchPause();
  ScratchPause(const ScratchPause&) = delete;
  ScratchPause& operator=(const ScratchPause&) = delete;

 private:
  int saved_;
};

// The thread's slot: bytes handed out since it was last wound back, the blocks not yet freed,
// and every block it has served since the thread took it (all 0 before the thread's first
// scope, or without a slot).
struct SlotUse {
  std::size_t bytes = 0;
  std::int64_t live = 0;
  std::int64_t served = 0;
};
SlotUse ThreadSlotUse();

}  // namespace frenetic::plan::heap

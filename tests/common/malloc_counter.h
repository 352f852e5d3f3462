// Counts every heap allocation of the process while `g_count_allocations` is set: the C++ ones
// (operator new ends in malloc) and those of C libraries (NLopt allocates its work arrays with
// malloc inside nlopt_optimize), which a replaced operator new or -Wl,--wrap=malloc (static
// references only) would miss. Interposes malloc, calloc and realloc in the executable and
// forwards to glibc's __libc_* entry points (exported by glibc 2.36).
//
// Every translation unit may include it for the counters; exactly one per executable defines
// FRENETIC_DEFINE_MALLOC_INTERPOSER before including it, to define the interposers. Under
// sanitizers, which own malloc, nothing is interposed and kAllocationsCounted is false
// (callers skip their checks).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace frenetic::testing_util {
inline std::atomic<bool> g_count_allocations{false};
inline std::atomic<std::int64_t> g_allocations{0};
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kAllocationsCounted = false;
#else
inline constexpr bool kAllocationsCounted = true;
#endif
inline void CountAllocation() {
  if (g_count_allocations.load(std::memory_order_relaxed)) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
}
}  // namespace frenetic::testing_util

#if defined(FRENETIC_DEFINE_MALLOC_INTERPOSER) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__)
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t n, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);

void* malloc(std::size_t size) noexcept {
  frenetic::testing_util::CountAllocation();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  frenetic::testing_util::CountAllocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  frenetic::testing_util::CountAllocation();
  return __libc_realloc(p, size);
}
}  // extern "C"
#endif

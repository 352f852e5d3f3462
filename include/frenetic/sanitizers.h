// Whether a sanitizer that owns the heap is on (AddressSanitizer, ThreadSanitizer,
// MemorySanitizer, LeakSanitizer). GCC says so with __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__,
// clang only through __has_feature. Such a build also runs the code several times slower.
#pragma once

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define FRENETIC_HEAP_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer) || __has_feature(leak_sanitizer)
#define FRENETIC_HEAP_SANITIZER 1
#endif
#endif
#ifndef FRENETIC_HEAP_SANITIZER
#define FRENETIC_HEAP_SANITIZER 0
#endif

namespace frenetic {
inline constexpr bool kUnderSanitizer = FRENETIC_HEAP_SANITIZER != 0;
}  // namespace frenetic

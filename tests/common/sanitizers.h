// Whether the tests run under AddressSanitizer or ThreadSanitizer: these own the heap (the
// resident set is not the program's) and slow the code several times. GCC says so with
// __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__, clang only through __has_feature.
#pragma once

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define FRENETIC_TEST_UNDER_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define FRENETIC_TEST_UNDER_SANITIZER 1
#endif
#endif

namespace frenetic::testing_util {
#ifdef FRENETIC_TEST_UNDER_SANITIZER
inline constexpr bool kUnderSanitizer = true;
#else
inline constexpr bool kUnderSanitizer = false;
#endif
}  // namespace frenetic::testing_util

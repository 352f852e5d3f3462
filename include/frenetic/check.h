// FRENETIC_CHECK: invariants that hold unless the program itself is wrong. Bad input never
// reaches a CHECK; it is reported with a Status instead.
#pragma once

#include <cstdio>
#include <cstdlib>

#define FRENETIC_CHECK(cond)                                                        \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                 \
    }                                                                               \
  } while (0)

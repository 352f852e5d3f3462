// The percentiles frenetic reports (planning time p50 / p99 in `drive`, `serve`, `commonroad`
// and their records): the nearest rank, the smallest value with at least the share q of the
// values at or below it (q = 0: the smallest). 0 for no values. The fidelity statistics
// interpolate instead, as numpy does (eval/fidelity_traffic.cc).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace frenetic {

// The index of the nearest rank among n > 0 sorted values: ceil(q n) - 1, within [0, n - 1]
// (q n within 1e-9 of a whole number counts as that number: 0.99 * 100 is 99).
inline std::size_t NearestRankIndex(std::size_t n, double q) {
  const double rank = std::ceil(q * static_cast<double>(n) - 1e-9);
  if (!(rank > 1)) return 0;  // also a NaN q
  return std::min(n, static_cast<std::size_t>(rank)) - 1;
}

// The percentile q (0..1) of *values, which it reorders (no copy).
inline double PercentileInPlace(std::vector<double>* values, double q) {
  if (values->empty()) return 0;
  const auto k = values->begin() + static_cast<std::ptrdiff_t>(NearestRankIndex(values->size(), q));
  std::nth_element(values->begin(), k, values->end());
  return *k;
}

// The percentile q (0..1) of the values.
inline double Percentile(std::vector<double> values, double q) {
  return PercentileInPlace(&values, q);
}

}  // namespace frenetic

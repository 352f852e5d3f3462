// The grid the reachability searches (way_through.cc, rescue.cc) merge their states on, and the
// order they check a step's states in.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "frenetic/key_table.h"

namespace frenetic::commonroad::reach {

using frenetic::KeyTable;
using frenetic::MixKey;

// floor(x) as an integer, for x within the range of std::int64_t: the same as
// static_cast<std::int64_t>(std::floor(x)) without the call (the baseline x86-64 has no
// rounding instruction, and the searches take ten floors a state).
inline std::int64_t FloorToInt(double x) {
  const auto t = static_cast<std::int64_t>(x);  // toward zero
  return static_cast<double>(t) > x ? t - 1 : t;
}

// sin x and cos x; for |x| <= 0.25 (a search state's turn within a step, at any speed past a
// crawl) by their Taylor series to x^11 and x^12, whose next terms are below 1e-17: within an
// ulp or two of std::sin and std::cos at a fraction of their cost. Else (and for NaN) those.
inline void SmallSinCos(double x, double* sin_x, double* cos_x) {
  if (!(std::abs(x) <= 0.25)) {
    *sin_x = std::sin(x);
    *cos_x = std::cos(x);
    return;
  }
  const double x2 = x * x;
  *sin_x = x * (1 - x2 * (1.0 / 6) * (1 - x2 * (1.0 / 20) * (1 - x2 * (1.0 / 42) *
           (1 - x2 * (1.0 / 72) * (1 - x2 * (1.0 / 110))))));
  *cos_x = 1 - x2 * 0.5 * (1 - x2 * (1.0 / 12) * (1 - x2 * (1.0 / 30) * (1 - x2 * (1.0 / 56) *
           (1 - x2 * (1.0 / 90) * (1 - x2 * (1.0 / 132))))));
}

// The cell of a state of five values, packed in 64 bits (the first two, the position, 14 bits
// each, the others 12, wrapping: two states that far apart never meet in one step's set).
inline std::uint64_t CellOf(double x, double y, double c, double d, double e, const double cell[5]) {
  const auto bits = [](double value, double size, int width) {
    return static_cast<std::uint64_t>(FloorToInt(value / size)) & ((std::uint64_t{1} << width) - 1);
  };
  return bits(x, cell[0], 14) << 50 | bits(y, cell[1], 14) << 36 | bits(c, cell[2], 12) << 24 |
         bits(d, cell[3], 12) << 12 | bits(e, cell[4], 12);
}


// SpreadOrder's scratch, kept between calls so that it allocates only while it grows.
struct SpreadScratch {
  KeyTable strata;
  std::vector<std::pair<std::uint64_t, std::size_t>> keys;  // (hash, index in next)
  std::vector<std::pair<std::uint64_t, std::size_t>> keys_out;  // SortByHash's other buffer
  std::vector<std::uint32_t> counts;                              // SortByHash's histograms
  std::vector<std::size_t> at_level;
  std::vector<std::pair<std::size_t, std::size_t>> sorted;
};

// Sorts (hash, index) pairs of distinct hashes by hash, as std::sort would (the order is
// the hashes' alone): a least-significant-digit radix sort, eight passes of a byte, for the
// thousands of a search step (~3x faster there); std::sort below 256.
inline void SortByHash(std::vector<std::pair<std::uint64_t, std::size_t>>& keys,
                       std::vector<std::pair<std::uint64_t, std::size_t>>& other,
                       std::vector<std::uint32_t>& counts) {
  const std::size_t n = keys.size();
  if (n < 256) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  other.resize(n);
  counts.assign(8 * 256, 0u);
  for (const auto& k : keys) {
    for (int b = 0; b < 8; ++b) ++counts[b * 256 + ((k.first >> (8 * b)) & 0xff)];
  }
  for (int b = 0; b < 8; ++b) {
    std::uint32_t* c = &counts[b * 256];
    std::uint32_t sum = 0;
    for (int i = 0; i < 256; ++i) {
      const std::uint32_t here = c[i];
      c[i] = sum;
      sum += here;
    }
    for (const auto& k : keys) other[c[(k.first >> (8 * b)) & 0xff]++] = k;
    keys.swap(other);
  }
}

// The order a capped step checks its new states in: round-robin over coarse strata (the
// stratum_of(state) keys), each in the order of a hash of the cells (deterministic, and
// unrelated to where they are), so that a capped step keeps a spread. `next` holds (cell,
// state) pairs, left as they are; `rank` receives (rank in its stratum, index in next) sorted by
// the rank, then the hash (only (hash, index) pairs are sorted, not the states).
template <typename State, typename StratumOf>
void SpreadOrder(const std::vector<std::pair<std::uint64_t, State>>& next, StratumOf stratum_of,
                 SpreadScratch& scratch, std::vector<std::pair<std::size_t, std::size_t>>& rank) {
  auto& [strata, keys, keys_out, counts, at_level, sorted] = scratch;
  const std::size_t n = next.size();
  keys.resize(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = {MixKey(next[i].first), i};
  SortByHash(keys, keys_out, counts);  // the cells differ, so do their hashes
  strata.Clear();
  rank.resize(n);
  bool fresh = false;
  std::size_t levels = 0;
  for (std::size_t p = 0; p < n; ++p) {
    const std::size_t r = strata.At(stratum_of(next[keys[p].second].second), &fresh)++;
    rank[p] = {r, p};
    levels = std::max(levels, r + 1);
  }
  // Sorted by (rank, p): a counting sort by rank, stable in p.
  at_level.assign(levels + 1, 0);
  for (const auto& [r, p] : rank) ++at_level[r + 1];
  for (std::size_t l = 1; l <= levels; ++l) at_level[l] += at_level[l - 1];
  sorted.resize(n);
  for (const auto& [r, p] : rank) sorted[at_level[r]++] = {r, keys[p].second};
  rank.swap(sorted);
}

}  // namespace frenetic::commonroad::reach

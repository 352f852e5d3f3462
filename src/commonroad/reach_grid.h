// The grid the reachability searches (way_through.cc, rescue.cc) merge their states on, and the
// hash that orders their checks.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace frenetic::commonroad::reach {

// The cell of a state of five values, packed in 64 bits (the first two, the position, 14 bits
// each, the others 12, wrapping: two states that far apart never meet in one step's set).
inline std::uint64_t CellOf(double x, double y, double c, double d, double e, const double cell[5]) {
  const auto bits = [](double value, double size, int width) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(value / size))) &
           ((std::uint64_t{1} << width) - 1);
  };
  return bits(x, cell[0], 14) << 50 | bits(y, cell[1], 14) << 36 | bits(c, cell[2], 12) << 24 |
         bits(d, cell[3], 12) << 12 | bits(e, cell[4], 12);
}

// splitmix64's finaliser: a cell's place in the checking order.
inline std::uint64_t Mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return z ^ (z >> 31);
}

// The order a capped step checks its new states in: round-robin over coarse strata (the
// stratum_of(state) keys), each in the order of a hash of the cells (deterministic, and
// unrelated to where they are), so that a capped step keeps a spread. `next` holds (cell,
// state) pairs, left as they are; `rank` receives (rank in its stratum, index in next) sorted by
// the rank, then the hash. `strata` and `keys` are scratch (the states are not moved: only
// (hash, index) pairs are sorted).
template <typename State, typename StratumOf>
void SpreadOrder(const std::vector<std::pair<std::uint64_t, State>>& next, StratumOf stratum_of,
                 std::unordered_map<std::uint64_t, std::size_t>& strata,
                 std::vector<std::pair<std::uint64_t, std::size_t>>& keys,
                 std::vector<std::pair<std::size_t, std::size_t>>& rank) {
  const std::size_t n = next.size();
  keys.resize(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = {Mix(next[i].first), i};
  std::sort(keys.begin(), keys.end());  // the cells differ, so do their hashes
  strata.clear();
  rank.resize(n);
  for (std::size_t p = 0; p < n; ++p) rank[p] = {strata[stratum_of(next[keys[p].second].second)]++, p};
  std::sort(rank.begin(), rank.end());
  for (auto& [r, at] : rank) at = keys[at].second;
}

}  // namespace frenetic::commonroad::reach

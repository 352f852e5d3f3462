// The grid the reachability searches (way_through.cc, rescue.cc) merge their states on, and the
// hash that orders their checks.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
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

// A table from cells to counts, for the sets a step builds and clears many times: open
// addressing (linear probing on Mix), cleared in O(1) by a generation number, so that it
// allocates only while it grows.
class CellTable {
 public:
  // The count of `key`, 0 when it is new; *fresh: whether it was.
  std::size_t& At(std::uint64_t key, bool* fresh) {
    if (2 * (size_ + 1) > keys_.size()) Grow();
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = Mix(key) & mask;; i = (i + 1) & mask) {
      if (gen_[i] != generation_) {
        gen_[i] = generation_;
        keys_[i] = key;
        counts_[i] = 0;
        ++size_;
        *fresh = true;
        return counts_[i];
      }
      if (keys_[i] == key) {
        *fresh = false;
        return counts_[i];
      }
    }
  }
  // Whether `key` was new (it is in the table now).
  bool Insert(std::uint64_t key) {
    bool fresh = false;
    At(key, &fresh);
    return fresh;
  }
  void Clear() {
    size_ = 0;
    if (++generation_ == 0) {  // wrapped: every slot's mark could match again
      std::fill(gen_.begin(), gen_.end(), 0u);
      generation_ = 1;
    }
  }

 private:
  void Grow() {
    const std::size_t n = std::max<std::size_t>(64, 2 * keys_.size());
    std::vector<std::uint64_t> keys(n);
    std::vector<std::uint32_t> gen(n, 0u);
    std::vector<std::size_t> counts(n);
    for (std::size_t i = 0; i < keys_.size(); ++i) {
      if (gen_[i] != generation_) continue;
      for (std::size_t j = Mix(keys_[i]) & (n - 1);; j = (j + 1) & (n - 1)) {
        if (gen[j] != 1u) {
          gen[j] = 1u;
          keys[j] = keys_[i];
          counts[j] = counts_[i];
          break;
        }
      }
    }
    keys_ = std::move(keys);
    gen_ = std::move(gen);
    counts_ = std::move(counts);
    generation_ = 1;
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> gen_;  // a slot is taken when it holds generation_
  std::vector<std::size_t> counts_;
  std::uint32_t generation_ = 1;
  std::size_t size_ = 0;
};

// SpreadOrder's scratch, kept between calls so that it allocates only while it grows.
struct SpreadScratch {
  CellTable strata;
  std::vector<std::pair<std::uint64_t, std::size_t>> keys;  // (hash, index in next)
  std::vector<std::size_t> at_level;
  std::vector<std::pair<std::size_t, std::size_t>> sorted;
};

// The order a capped step checks its new states in: round-robin over coarse strata (the
// stratum_of(state) keys), each in the order of a hash of the cells (deterministic, and
// unrelated to where they are), so that a capped step keeps a spread. `next` holds (cell,
// state) pairs, left as they are; `rank` receives (rank in its stratum, index in next) sorted by
// the rank, then the hash (only (hash, index) pairs are sorted, not the states).
template <typename State, typename StratumOf>
void SpreadOrder(const std::vector<std::pair<std::uint64_t, State>>& next, StratumOf stratum_of,
                 SpreadScratch& scratch, std::vector<std::pair<std::size_t, std::size_t>>& rank) {
  auto& [strata, keys, at_level, sorted] = scratch;
  const std::size_t n = next.size();
  keys.resize(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = {Mix(next[i].first), i};
  std::sort(keys.begin(), keys.end());  // the cells differ, so do their hashes
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

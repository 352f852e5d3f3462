// A hash table of 64-bit keys with counts, and the hash it probes with: the state sets of the
// searches (the incident judge's transposition table, the CommonRoad reachability grids).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace frenetic {

// splitmix64's finaliser: a 64-bit key spread over all bits.
inline std::uint64_t MixKey(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return z ^ (z >> 31);
}

// A table from 64-bit keys to counts, for sets that a search builds and clears many times:
// open addressing (linear probing on MixKey, grown at half full), cleared in O(1) by a
// generation number, so that it allocates only while it grows. Any key, 0 and ~0 included.
class KeyTable {
 public:
  // The count of `key`, 0 when it is new; *fresh: whether it was.
  std::size_t& At(std::uint64_t key, bool* fresh) {
    if (2 * (size_ + 1) > keys_.size()) Grow();
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = MixKey(key) & mask;; i = (i + 1) & mask) {
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
  // Whether `key` is in the table.
  bool Contains(std::uint64_t key) const {
    if (keys_.empty()) return false;
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = MixKey(key) & mask;; i = (i + 1) & mask) {
      if (gen_[i] != generation_) return false;
      if (keys_[i] == key) return true;
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
      for (std::size_t j = MixKey(keys_[i]) & (n - 1);; j = (j + 1) & (n - 1)) {
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

}  // namespace frenetic

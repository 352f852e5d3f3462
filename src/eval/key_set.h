// A set of 64-bit keys: the incident judge's transposition table (incident_judge.cc).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frenetic::sim::judge {

// A set of 64-bit keys below 2^63 (open addressing, linear probing, grown at half full): probed
// for every child of every node of the judge's search (std::unordered_set took a sixth of the
// judging time).
class KeySet {
 public:
  void Clear() {
    slots_.assign(1024, 0);
    size_ = 0;
  }
  bool Contains(std::uint64_t key) const {
    const std::uint64_t k = key | kUsed;
    for (std::size_t i = Mix(k) & (slots_.size() - 1);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i] == k) return true;
      if (slots_[i] == 0) return false;
    }
  }
  bool Insert(std::uint64_t key) {  // false when already there
    if (2 * (size_ + 1) > slots_.size()) Grow();
    const std::uint64_t k = key | kUsed;
    for (std::size_t i = Mix(k) & (slots_.size() - 1);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i] == k) return false;
      if (slots_[i] == 0) {
        slots_[i] = k;
        ++size_;
        return true;
      }
    }
  }

 private:
  static constexpr std::uint64_t kUsed = 1ULL << 63;  // keys use fewer bits: 0 marks a free slot
  static std::uint64_t Mix(std::uint64_t x) {         // splitmix64's finaliser
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }
  void Grow() {
    std::vector<std::uint64_t> old;
    old.swap(slots_);
    slots_.assign(2 * old.size(), 0);
    size_ = 0;
    for (std::uint64_t k : old) {
      if (k != 0) Insert(k);
    }
  }
  std::vector<std::uint64_t> slots_ = std::vector<std::uint64_t>(1024, 0);
  std::size_t size_ = 0;
};

}  // namespace frenetic::sim::judge

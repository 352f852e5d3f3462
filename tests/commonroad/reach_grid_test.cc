// The reachability searches' grid (reach_grid.h): the cell table a step dedupes its states and
// counts its strata with, and the order a capped step checks its states in.
#include "frenetic/commonroad/reach_grid.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace frenetic::commonroad::reach {
namespace {

TEST(CellTableTest, InsertsOnceCountsAndClearsAcrossGrowth) {
  CellTable table;
  // Enough keys to grow it several times (it starts at 64 slots), some of them colliding in
  // the low bits, and the all-ones key.
  std::vector<std::uint64_t> keys;
  for (std::uint64_t i = 0; i < 1000; ++i) keys.push_back(i << 50 | i);
  keys.push_back(~std::uint64_t{0});
  for (const std::uint64_t k : keys) EXPECT_TRUE(table.Insert(k)) << k;
  for (const std::uint64_t k : keys) EXPECT_FALSE(table.Insert(k)) << k;
  // Counts per key, kept through growth.
  CellTable counts;
  bool fresh = false;
  for (int round = 0; round < 3; ++round) {
    for (const std::uint64_t k : keys) ++counts.At(k, &fresh);
  }
  for (const std::uint64_t k : keys) {
    EXPECT_EQ(counts.At(k, &fresh), 3u);
    EXPECT_FALSE(fresh);
  }
  // Cleared: every key is new again, with a count of 0.
  counts.Clear();
  EXPECT_EQ(counts.At(keys[5], &fresh), 0u);
  EXPECT_TRUE(fresh);
  table.Clear();
  for (const std::uint64_t k : keys) EXPECT_TRUE(table.Insert(k)) << k;
}

TEST(SpreadOrderTest, RoundRobinOverStrataEachInHashOrder) {
  // States 0..29 in cells 100 + i, in three strata (i % 3).
  std::vector<std::pair<std::uint64_t, int>> next;
  for (int i = 0; i < 30; ++i) next.push_back({100u + i, i});
  SpreadScratch scratch;
  std::vector<std::pair<std::size_t, std::size_t>> rank;
  SpreadOrder(next, [](int state) { return static_cast<std::uint64_t>(state % 3); }, scratch, rank);
  ASSERT_EQ(rank.size(), next.size());
  // Each state once; `next` left as it was.
  std::set<std::size_t> seen;
  for (const auto& [r, at] : rank) seen.insert(at);
  EXPECT_EQ(seen.size(), next.size());
  EXPECT_EQ(next[7].first, 107u);
  // Rank by rank: one state of each stratum before any stratum's second; within a rank in the
  // order of the cells' hashes; and each stratum's states in hash order across the ranks.
  std::map<int, std::uint64_t> last_in_stratum;
  for (std::size_t v = 0; v < rank.size(); ++v) {
    const auto [r, at] = rank[v];
    EXPECT_EQ(r, v / 3) << v;
    const int stratum = next[at].second % 3;
    const std::uint64_t hash = Mix(next[at].first);
    if (v % 3 != 0) EXPECT_LT(Mix(next[rank[v - 1].second].first), hash) << v;
    if (auto it = last_in_stratum.find(stratum); it != last_in_stratum.end()) {
      EXPECT_LT(it->second, hash) << v;
    }
    last_in_stratum[stratum] = hash;
  }
  // The same order again from the same scratch.
  std::vector<std::pair<std::size_t, std::size_t>> again;
  SpreadOrder(next, [](int state) { return static_cast<std::uint64_t>(state % 3); }, scratch, again);
  EXPECT_EQ(again, rank);
}

}  // namespace
}  // namespace frenetic::commonroad::reach

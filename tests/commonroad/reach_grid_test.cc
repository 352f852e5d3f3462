// The reachability searches' grid (reach_grid.h): the order a capped step checks its states in.
#include "frenetic/commonroad/reach_grid.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace frenetic::commonroad::reach {
namespace {

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
    const std::uint64_t hash = MixKey(next[at].first);
    if (v % 3 != 0) {
      EXPECT_LT(MixKey(next[rank[v - 1].second].first), hash) << v;
    }
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

// The reachability searches' grid (reach_grid.h): the order a capped step checks its states in,
// and the helpers of their steps.
#include "frenetic/commonroad/reach_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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

// The radix sort gives std::sort's order at every size, across the small-size cut.
TEST(SortByHashTest, TheOrderOfStdSort) {
  std::vector<std::pair<std::uint64_t, std::size_t>> other;
  std::vector<std::uint32_t> counts;
  for (const std::size_t n : {0, 1, 2, 255, 256, 257, 3000}) {
    std::vector<std::pair<std::uint64_t, std::size_t>> keys;
    for (std::size_t i = 0; i < n; ++i) keys.push_back({MixKey(i * 7919 + n), i});
    keys.push_back({0, n});  // the extremes of the range
    keys.push_back({~std::uint64_t{0}, n + 1});
    auto expected = keys;
    std::sort(expected.begin(), expected.end());
    SortByHash(keys, other, counts);
    EXPECT_EQ(keys, expected) << n;
  }
}

TEST(FloorToIntTest, FloorAsAnInteger) {
  for (const double x : {0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.999999, -2.000001, -3.0, 1e15 + 0.5,
                         -1e15 - 0.5, 4503599627370497.0, -4503599627370497.0,
                         std::nextafter(-7.0, 0.0), std::nextafter(-7.0, -8.0),
                         std::numeric_limits<double>::denorm_min(),
                         -std::numeric_limits<double>::denorm_min()}) {
    EXPECT_EQ(FloorToInt(x), static_cast<std::int64_t>(std::floor(x))) << x;
  }
}

TEST(SmallSinCosTest, WithinAFewUlpsOfLibmAndLibmOutsideItsRange) {
  // Across the series' range, both signs and its edge: within 2e-16 of std::sin and std::cos
  // (the sine's x^11 term left out would show as 6e-15 at 0.25, the cosine's x^10 as 3e-13).
  for (int i = -2500; i <= 2500; ++i) {
    const double x = i * 1e-4;
    double s = 0, c = 0;
    SmallSinCos(x, &s, &c);
    EXPECT_NEAR(s, std::sin(x), 2e-16) << x;
    EXPECT_NEAR(c, std::cos(x), 2e-16) << x;
  }
  // Past it, std's own values, exactly; NaN stays NaN.
  for (const double x : {0.2500001, -0.3, 1.0, -3.0, 100.0}) {
    double s = 0, c = 0;
    SmallSinCos(x, &s, &c);
    EXPECT_EQ(s, std::sin(x)) << x;
    EXPECT_EQ(c, std::cos(x)) << x;
  }
  double s = 0, c = 0;
  SmallSinCos(std::numeric_limits<double>::quiet_NaN(), &s, &c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

}  // namespace
}  // namespace frenetic::commonroad::reach

// frenetic::Percentile, the nearest rank behind every planning-time p50 / p99 that drive, serve
// and commonroad print.
#include "frenetic/percentile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace frenetic {
namespace {

TEST(Percentile, IsTheNearestRank) {
  std::vector<double> v(100);
  std::iota(v.begin(), v.end(), 1.0);  // 1..100, so the value is the rank
  EXPECT_EQ(Percentile(v, 0.99), 99);  // not the largest: 99 of 100 are at or below 99
  EXPECT_EQ(Percentile(v, 0.5), 50);
  EXPECT_EQ(Percentile(v, 1.0), 100);
  EXPECT_EQ(Percentile(v, 0.0), 1);
  EXPECT_EQ(Percentile(v, 0.001), 1);
  EXPECT_EQ(Percentile(v, 0.011), 2);
}

TEST(Percentile, SmallSetsAndUnsortedInput) {
  EXPECT_EQ(Percentile({}, 0.5), 0);
  EXPECT_EQ(Percentile({7}, 0.99), 7);
  EXPECT_EQ(Percentile({5, 1, 4, 2, 6}, 0.5), 4);  // 1 2 4 5 6: the third
  EXPECT_EQ(Percentile({5, 1, 4, 2, 6}, 0.99), 6);
  EXPECT_EQ(Percentile({3, 1}, 0.5), 1);  // the lower of two
  EXPECT_EQ(Percentile({3, 1}, std::nan("")), 1);
}

TEST(Percentile, InPlaceGivesTheSameValueAndKeepsTheValues) {
  std::vector<double> v;
  for (int i = 0; i < 1753; ++i) v.push_back(std::fmod(i * 7.31, 13.0));
  const double copy = Percentile(v, 0.99);
  std::vector<double> w = v;
  EXPECT_EQ(PercentileInPlace(&w, 0.99), copy);
  std::sort(v.begin(), v.end());
  std::sort(w.begin(), w.end());
  EXPECT_EQ(v, w);
  EXPECT_EQ(copy, v[1735]);  // ceil(0.99 * 1753) = 1736th
}

}  // namespace
}  // namespace frenetic

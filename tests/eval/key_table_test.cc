// The searches' key table (key_table.h; the incident judge's transposition table): a key is
// there once inserted, never before, none is lost when the table grows, counts are kept, and a
// cleared table is empty.
#include "frenetic/key_table.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <vector>

namespace frenetic {
namespace {

TEST(KeyTableTest, InsertsOnceAndFinds) {
  KeyTable set;
  EXPECT_FALSE(set.Contains(0));
  EXPECT_TRUE(set.Insert(0));  // 0 is a key like any other (a generation marks a slot)
  EXPECT_TRUE(set.Contains(0));
  EXPECT_FALSE(set.Insert(0));
  EXPECT_FALSE(set.Contains(1));
  EXPECT_TRUE(set.Insert(1));
  EXPECT_TRUE(set.Contains(1));
}

TEST(KeyTableTest, GrowsWithoutLosingKeysAndClears) {
  KeyTable set;
  std::mt19937_64 rng(7);
  std::set<std::uint64_t> keys;
  while (keys.size() < 5000) {  // several doublings past the first 64 slots
    const std::uint64_t k = rng();
    EXPECT_EQ(set.Insert(k), keys.insert(k).second);
  }
  for (const std::uint64_t k : keys) ASSERT_TRUE(set.Contains(k)) << k;
  int absent_found = 0;
  for (int i = 0; i < 5000; ++i) {
    const std::uint64_t k = rng();
    if (!keys.count(k) && set.Contains(k)) ++absent_found;
  }
  EXPECT_EQ(absent_found, 0);
  set.Clear();
  for (const std::uint64_t k : keys) ASSERT_FALSE(set.Contains(k)) << k;
  EXPECT_TRUE(set.Insert(*keys.begin()));
}

TEST(KeyTableTest, CountsPerKeyThroughGrowthAndClear) {
  KeyTable table;
  // Enough keys to grow it several times (it starts at 64 slots), some of them colliding in
  // the low bits, and the all-ones key.
  std::vector<std::uint64_t> keys;
  for (std::uint64_t i = 0; i < 1000; ++i) keys.push_back(i << 50 | i);
  keys.push_back(~std::uint64_t{0});
  EXPECT_FALSE(table.Contains(keys[0]));
  for (const std::uint64_t k : keys) EXPECT_TRUE(table.Insert(k)) << k;
  for (const std::uint64_t k : keys) EXPECT_FALSE(table.Insert(k)) << k;
  for (const std::uint64_t k : keys) EXPECT_TRUE(table.Contains(k)) << k;
  EXPECT_FALSE(table.Contains(12345));
  // Counts per key, kept through growth.
  KeyTable counts;
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
  EXPECT_FALSE(table.Contains(keys[7]));
  for (const std::uint64_t k : keys) EXPECT_TRUE(table.Insert(k)) << k;
}

}  // namespace
}  // namespace frenetic

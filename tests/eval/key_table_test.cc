// The judge's transposition table: a key is there once inserted, never before, and none is lost
// when the table grows.
#include "eval/key_set.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>

namespace frenetic::sim::judge {
namespace {

TEST(KeySetTest, InsertsOnceAndFinds) {
  KeySet set;
  EXPECT_FALSE(set.Contains(0));
  EXPECT_TRUE(set.Insert(0));  // 0 is a key like any other (the used bit marks a slot)
  EXPECT_TRUE(set.Contains(0));
  EXPECT_FALSE(set.Insert(0));
  EXPECT_FALSE(set.Contains(1));
  EXPECT_TRUE(set.Insert(1));
  EXPECT_TRUE(set.Contains(1));
}

TEST(KeySetTest, GrowsWithoutLosingKeysAndClears) {
  KeySet set;
  std::mt19937_64 rng(7);
  std::set<std::uint64_t> keys;
  while (keys.size() < 5000) {  // several doublings past the first 1024 slots
    const std::uint64_t k = rng() >> 1;
    EXPECT_EQ(set.Insert(k), keys.insert(k).second);
  }
  for (const std::uint64_t k : keys) ASSERT_TRUE(set.Contains(k)) << k;
  int absent_found = 0;
  for (int i = 0; i < 5000; ++i) {
    const std::uint64_t k = rng() >> 1;
    if (!keys.count(k) && set.Contains(k)) ++absent_found;
  }
  EXPECT_EQ(absent_found, 0);
  set.Clear();
  for (const std::uint64_t k : keys) ASSERT_FALSE(set.Contains(k)) << k;
  EXPECT_TRUE(set.Insert(*keys.begin()));
}

}  // namespace
}  // namespace frenetic::sim::judge

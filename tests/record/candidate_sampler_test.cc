// The candidate sampler on its own (the reader's tests cover it through records).
#include "record/candidate_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace frenetic::record {
namespace {

CycleCandidates Cycle(int k) {
  CycleCandidates c;
  c.exchange = k;
  c.listed = 1;
  c.candidates.resize(1);
  return c;
}

std::vector<int> Exchanges(std::vector<CycleCandidates> cycles) {
  std::vector<int> out;
  for (const CycleCandidates& c : cycles) out.push_back(c.exchange);
  return out;
}

TEST(CandidateSamplerTest, KeepsAnEvenlySpreadBudgetInExchangeOrder) {
  CandidateSampler sampler(4);
  for (int k = 0; k < 40; ++k) sampler.Add(Cycle(k), false, false);
  // The stride doubled from 1 until at most 4 were left: multiples of 16.
  EXPECT_EQ(Exchanges(sampler.Take()), (std::vector<int>{0, 16, 32}));
  EXPECT_TRUE(sampler.Take().empty());
}

TEST(CandidateSamplerTest, AnIncidentPinsItsCycleAndTheFiveBeforeNewestFirst) {
  CandidateSampler sampler(4);
  for (int k = 0; k < 40; ++k) sampler.Add(Cycle(k), k == 23, false);
  // Four incident pins (the budget): 23, 22, 21, 20; the rest as spread.
  EXPECT_EQ(Exchanges(sampler.Take()), (std::vector<int>{0, 16, 20, 21, 22, 23, 32}));
}

TEST(CandidateSamplerTest, AnIncidentWithoutCandidatesStillPinsTheCyclesBefore) {
  CandidateSampler sampler(100);
  for (int k = 0; k < 10; ++k) sampler.Add(Cycle(k), false, false);
  sampler.AddWithoutCandidates(true);  // exchange 10
  for (int k = 11; k < 300; ++k) sampler.Add(Cycle(k), false, false);
  const std::vector<int> kept = Exchanges(sampler.Take());
  for (int k = 4; k < 10; ++k) {
    EXPECT_NE(std::find(kept.begin(), kept.end(), k), kept.end()) << k;
  }
}

TEST(CandidateSamplerTest, LaneChangesHaveTheirOwnBudget) {
  CandidateSampler sampler(2);
  for (int k = 0; k < 64; ++k) {
    const bool lane_change = k % 8 == 3;  // 3, 11, 19...: only the first two are pinned
    sampler.Add(Cycle(k), k == 45, lane_change);
  }
  EXPECT_EQ(Exchanges(sampler.Take()), (std::vector<int>{0, 3, 11, 32, 44, 45}));
}

}  // namespace
}  // namespace frenetic::record

// The search planner's scoring: every candidate costed exactly as the cost set costs its input,
// the deadline's checkpoint, the broad-phase masks, and the lazy sort into cost order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "plan/search/stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::Stages;
using testing::kS;

void Scene(Stages& st) {
  st.Prepare({kS, 18, 0, 6.0, 0, 0},
             {{kS + 30, 6.0, 14}, {kS - 10, 2.0, 20}, {kS + 60, 10.0, 16}, {kS + 15, 2.0, 18}});
  st.lattice.Generate();
}

// Scene(st), scored to the end: the number of candidates.
int ScoredScene(Stages& st) {
  Scene(st);
  EXPECT_TRUE(st.scorer.Score());
  return static_cast<int>(st.ws.order.size());
}

TEST(SearchScoringTest, ScoresEveryCandidateWithTheCostSet) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  Scene(st);
  ASSERT_TRUE(st.scorer.Score());
  const Workspace& ws = st.ws;
  const int n = static_cast<int>(ws.cand_lon.size());
  ASSERT_GT(n, 100);
  ASSERT_EQ(static_cast<int>(ws.order.size()), n);
  for (int c = 0; c < n; ++c) EXPECT_EQ(ws.order[c], c) << "unsorted until asked";
  ASSERT_TRUE(st.scorer.ResolveAll());
  for (int c = 0; c < n; ++c) {
    const double v = st.costs->Evaluate(ws.ctx, st.scorer.InputFor(ws.cand_lon[c], ws.cand_lat[c]));
    EXPECT_EQ(ws.cand_cost[c], v);
    // A trajectory sampled on the fly costs what its bundle pair costs.
    EXPECT_DOUBLE_EQ(
        st.scorer.CostOf(ws.Candidate(c), ws.lon[ws.cand_lon[c]], ws.lat[ws.cand_lat[c]]), v)
        << c;
  }
}

TEST(SearchScoringTest, SortsLazilyIntoCostOrderTiesByIndex) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  Scene(st);
  ASSERT_TRUE(st.scorer.Score());
  ASSERT_TRUE(st.scorer.ResolveAll());
  Workspace& ws = st.ws;
  const int n = static_cast<int>(ws.order.size());
  // Two equal costs: the lower index ranks first.
  ws.cand_cost[5] = ws.cand_cost[9] = -1.0;
  st.scorer.SortUpTo(0);
  EXPECT_GE(ws.sorted, 1);
  EXPECT_LT(ws.sorted, n) << "only a prefix is sorted";
  EXPECT_EQ(ws.order[0], 5);
  EXPECT_EQ(ws.order[1], 9);
  st.scorer.SortUpTo(n - 1);
  EXPECT_EQ(ws.sorted, n);
  for (int r = 1; r < n; ++r) EXPECT_TRUE(Cheaper(ws, ws.order[r - 1], ws.order[r])) << r;
}

TEST(SearchScoringTest, LazyCostingRanksLikeAFullSortByExactCost) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  const int n = ScoredScene(st);
  Workspace& ws = st.ws;
  std::vector<double> exact(n);
  std::vector<int> want(n);
  for (int c = 0; c < n; ++c) {
    const double v = st.costs->Evaluate(ws.ctx, st.scorer.InputFor(ws.cand_lon[c], ws.cand_lat[c]));
    exact[c] = std::isfinite(v) ? v : 1e300;
    want[c] = c;
    EXPECT_LE(st.costs->LowerBound(ws.ctx, st.scorer.InputFor(ws.cand_lon[c], ws.cand_lat[c])),
              exact[c]);
  }
  std::sort(want.begin(), want.end(), [&exact](int a, int b) {
    return exact[a] < exact[b] || (exact[a] == exact[b] && a < b);
  });
  for (int r = 0; r < n; ++r) {
    st.scorer.SortUpTo(r);
    ASSERT_EQ(ws.order[r], want[r]) << "rank " << r;
    EXPECT_EQ(ws.cand_cost[ws.order[r]], exact[ws.order[r]]) << "rank " << r;
  }
}

TEST(SearchScoringTest, CoarseBoundsAreCompletedOnlyWhenNeeded) {
  // Score() leaves coarse bounds (no Sampled() term); ranking the first candidates completes
  // a few, Bound completes any: the cheap terms' bound, never above the exact cost.
  REQUIRE_UDACITY_MAP();
  Stages st;
  Scene(st);
  ASSERT_TRUE(st.scorer.Score());
  Workspace& ws = st.ws;
  const int n = static_cast<int>(ws.order.size());
  ASSERT_TRUE(st.scorer.SortUpTo(3));
  int complete = 0;
  for (int c = 0; c < n; ++c) complete += st.scorer.BoundComplete(c);
  EXPECT_GE(complete, 4);
  EXPECT_LT(complete, n / 2) << "the sort completes only the bounds it needs";
  for (int c = 0; c < n; ++c) {
    const cost::CostInput in = st.scorer.InputFor(ws.cand_lon[c], ws.cand_lat[c]);
    const double known = st.scorer.KnownBound(c);
    const double lower = st.costs->LowerBound(ws.ctx, in);
    const double bound = st.scorer.Bound(c);
    ASSERT_TRUE(st.scorer.BoundComplete(c));
    EXPECT_EQ(bound, std::isfinite(lower) ? std::min(lower, 1e300) : 1e300) << c;
    EXPECT_LE(known, bound) << c;
    const double exact = st.costs->Evaluate(ws.ctx, in);
    EXPECT_LE(bound, std::isfinite(exact) ? exact : 1e300) << c;
  }
}

// Advance: from the complete bound up to the exact cost, one expensive term at a time, never
// down, never above the exact cost; in the next cycle the term that added most goes first.
TEST(SearchScoringTest, AdvanceClimbsTermByTermToTheExactCost) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  const int n = ScoredScene(st);
  Workspace& ws = st.ws;
  const std::vector<int>& expensive = st.costs->expensive_terms();
  ASSERT_GE(expensive.size(), 2u);
  std::vector<double> added(st.costs->size(), 0.0);  // weighted, per term, over the cycle
  int raised = 0;
  for (int c = 0; c < n; ++c) {
    const cost::CostInput in = st.scorer.InputFor(ws.cand_lon[c], ws.cand_lat[c]);
    std::vector<double> values(st.costs->size());
    const double v = st.costs->Evaluate(ws.ctx, in, values.data());
    const double exact = std::isfinite(v) ? v : 1e300;
    for (int t : expensive) added[t] += st.costs->weight(t) * values[t];
    double last = st.scorer.Bound(c);
    int steps = 0;
    while (!st.scorer.Resolved(c)) {
      const double next = st.scorer.Advance(c);
      ASSERT_GE(next, last) << c;
      ASSERT_LE(next, exact) << c;
      raised += steps == 0 && next > last && next < exact;
      last = next;
      ASSERT_LE(++steps, static_cast<int>(expensive.size())) << c;
    }
    EXPECT_EQ(last, exact) << c;
    EXPECT_EQ(ws.cand_cost[c], exact) << c;
  }
  EXPECT_GT(raised, 0) << "one term alone lifts some bounds";
  // The next cycle (the same scene): one Advance evaluates the term that added most.
  const int first = *std::max_element(expensive.begin(), expensive.end(),
                                      [&](int a, int b) { return added[a] < added[b]; });
  ASSERT_TRUE(st.scorer.Score());
  for (int c = 0; c < n; ++c) {
    const cost::CostInput in = st.scorer.InputFor(ws.cand_lon[c], ws.cand_lat[c]);
    // The bound's values (the expensive terms' lower bounds), that term's exact value in.
    std::vector<double> values(st.costs->size()), bounds(st.costs->size());
    st.costs->Evaluate(ws.ctx, in, values.data());
    st.costs->LowerBound(ws.ctx, in, bounds.data());
    bounds[first] = values[first];
    const double want = st.costs->SumOf(bounds.data());
    if (!std::isfinite(want)) continue;
    st.scorer.Bound(c);
    ASSERT_EQ(st.scorer.Advance(c), std::min(want, 1e300)) << c;
  }
}

TEST(SearchScoringTest, DeadlineStopsScoringAtACheckpoint) {
  REQUIRE_UDACITY_MAP();
  PlannerConfig config = testing::DefaultConfig();
  ASSERT_TRUE(config.Set("budget_ms", 10).ok());
  Stages st(config);
  Scene(st);
  const int n = static_cast<int>(st.ws.cand_lon.size());
  ASSERT_GT(n, 200);
  // The clock reads 0 at the start and at the first checkpoint (candidate 63), then 6 ms: more
  // than half the budget at the second checkpoint (candidate 127).
  int readings = 0;
  CycleClock ticking([&readings] { return readings++ < 2 ? 0.0 : 6.0; });
  Scorer scorer(st.cfg, *st.costs, st.ws, ticking);
  ticking.Start();
  EXPECT_FALSE(scorer.Score());
  EXPECT_EQ(st.ws.order.size(), 127u) << "candidates 0..126, in generation order";
  for (int c = 0; c < 127; ++c) EXPECT_EQ(st.ws.order[c], c);
}

TEST(SearchScoringTest, BroadPhaseMasksMarkTheCarsWithinEachReach) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  Scene(st);
  const Workspace& ws = st.ws;
  const int n = ws.n_samples;
  ASSERT_EQ(ws.ctx.num_cars, 4);
  for (int i = 0; i < static_cast<int>(ws.lon.size()); i += 7) {
    // A lon bundle's masks are filled when a candidate of it is first costed in full.
    st.scorer.InputFor(i, 0);
    ASSERT_TRUE(ws.lon_near_have[i]);
    const double* s = ws.lon_s.data() + i * n;
    const std::uint64_t* near = ws.lon_near.data() + 2 * i * n;
    for (int k = 0; k < n; ++k) {
      for (int c = 0; c < ws.ctx.num_cars; ++c) {
        const double gap = std::abs(ws.car_s[c * n + k] - s[k]);
        EXPECT_EQ((near[k] >> c) & 1, gap < cost::kNearLongitudinal[0] ? 1u : 0u);
        EXPECT_EQ((near[n + k] >> c) & 1, gap < cost::kNearLongitudinal[1] ? 1u : 0u);
      }
    }
  }
  for (int j = 0; j < static_cast<int>(ws.lat.size()); ++j) {
    const double* d = ws.lat_d.data() + j * n;
    const std::uint64_t* near = ws.lat_near.data() + 2 * j * n;
    for (int k = 0; k < n; ++k) {
      for (int c = 0; c < ws.ctx.num_cars; ++c) {
        const double gap = std::abs(ws.car_d[c * n + k] - d[k]);
        EXPECT_EQ((near[k] >> c) & 1, gap < cost::kNearLateral[0] ? 1u : 0u);
        EXPECT_EQ((near[n + k] >> c) & 1, gap < cost::kNearLateral[1] ? 1u : 0u);
      }
    }
  }
  // The cost input of a pair points at its bundles' masks; the lower bound's at none.
  const cost::CostInput bound = st.scorer.BoundInputFor(3, 2);
  EXPECT_EQ(bound.near_lon[0], nullptr);
  EXPECT_EQ(bound.near_lat[0], nullptr);
  const cost::CostInput in = st.scorer.InputFor(3, 2);
  EXPECT_EQ(in.near_lon[0], ws.lon_near.data() + 2 * 3 * n);
  EXPECT_EQ(in.near_lon[1], ws.lon_near.data() + 2 * 3 * n + n);
  EXPECT_EQ(in.near_lat[0], ws.lat_near.data() + 2 * 2 * n);
  EXPECT_EQ(in.near_lat[1], ws.lat_near.data() + 2 * 2 * n + n);
}

}  // namespace
}  // namespace frenetic::plan::search

// The search planner's refinement: the refined winner is never costlier nor infeasible nor in
// collision, the parameters map back to the winner, and braking is sent as sampled.
#include <gtest/gtest.h>

#include "plan/search/stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::SceneCar;
using testing::Stages;
using testing::kS;

PlannerConfig Pinned() {
  PlannerConfig config = testing::DefaultConfig();
  config.PinDeadlines();  // refine.max_iterations bounds NLopt, not its clock
  return config;
}

// The cheapest candidate that passes every check, as the planner's lazy check finds it.
bool TakeFirstFeasible(Stages& st) {
  Workspace& ws = st.ws;
  st.lattice.Generate();
  if (!st.scorer.Score()) return false;
  for (int r = 0; r < static_cast<int>(ws.order.size()); ++r) {
    st.scorer.SortUpTo(r);
    const int c = ws.order[r];
    const traj::FrenetTrajectory tr = ws.Candidate(c);
    if (st.collisions.FirstCollision([&tr](int i) { return tr.At(i * kTickSeconds); }, 1.0) <=
        ws.n_steps) {
      continue;
    }
    st.ws.FillTicks(tr);
    if (st.limits.Violation(nullptr) > 0) continue;
    ws.TakeWinner(c);
    return true;
  }
  return false;
}

TEST(SearchRefinerTest, NeverReturnsACostlierOrInfeasibleWinner) {
  REQUIRE_UDACITY_MAP();
  // Without the constant-acceleration runs, which win below the limit and are sent unrefined.
  PlannerConfig config = Pinned();
  ASSERT_TRUE(config.Set("grid.accels", 0).ok());
  const std::vector<std::pair<double, std::vector<SceneCar>>> scenes = {
      {20, {}},
      {5, {}},
      {18, {{kS + 35, 6.0, 14}}},
      {20, {{kS + 25, 6.0, 12}, {kS + 5, 2.0, 20}}},
      {15, {{kS + 40, 6.0, 15}, {kS + 30, 10.0, 10}, {kS - 20, 2.0, 22}}},
      {22, {{kS + 60, 6.0, 8}}},
  };
  int refined = 0, improved = 0;
  for (size_t i = 0; i < scenes.size(); ++i) {
    Stages st(config);
    ASSERT_TRUE(st.refiner.available());
    st.Prepare({kS, scenes[i].first, 0, 6.0, 0, 0}, scenes[i].second);
    ASSERT_TRUE(TakeFirstFeasible(st)) << "scene " << i;
    const LonTraj lb = st.ws.lon[st.ws.winner_lon];
    const LatTraj db = st.ws.lat[st.ws.winner_lat];
    const double before = st.scorer.CostOf(st.ws.winner, lb, db);
    PlanSummary sum;
    st.refiner.Refine(sum);
    if (lb.kind == cost::LonKind::kBraking || lb.kind == cost::LonKind::kAccelerating) continue;
    ++refined;
    EXPECT_GT(sum.refine_iterations, 0) << "scene " << i;
    EXPECT_LE(sum.refine_iterations, st.cfg.refine.iterations + 1) << "scene " << i;
    EXPECT_EQ(sum.refine_cost_before, before) << "scene " << i;
    const double after = st.scorer.CostOf(st.ws.winner, lb, db);
    EXPECT_LE(after, before) << "scene " << i;
    EXPECT_EQ(sum.refine_cost_after, after) << "scene " << i;
    improved += after < before;
    st.ws.FillTicks(st.ws.winner);
    EXPECT_LE(st.limits.Violation(nullptr), 0) << "scene " << i;
    EXPECT_FALSE(st.collisions.Collides()) << "scene " << i;
  }
  EXPECT_GE(refined, 4);
  EXPECT_GE(improved, 1) << "the refinement should find something in these scenes";
}

TEST(SearchRefinerTest, TheWinnersOwnParametersGiveTheWinnerBack) {
  REQUIRE_UDACITY_MAP();
  Stages st(Pinned());
  st.Prepare({kS, 18, 0, 6.0, 0, 0}, {{kS + 35, 6.0, 14}});
  ASSERT_TRUE(TakeFirstFeasible(st));
  const LonTraj& lb = st.ws.lon[st.ws.winner_lon];
  const LatTraj& db = st.ws.lat[st.ws.winner_lat];
  ASSERT_NE(lb.kind, cost::LonKind::kBraking);
  ASSERT_EQ(db.traj.delay, 0);
  const double x[4] = {lb.param, lb.traj.duration, db.traj.duration, db.offset};
  const traj::FrenetTrajectory tr = st.refiner.FromParams(x);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(tr.lon.poly.c[k], st.ws.winner.lon.poly.c[k]) << k;
    EXPECT_EQ(tr.lat.poly.c[k], st.ws.winner.lat.poly.c[k]) << k;
  }
  EXPECT_EQ(tr.lon.duration, st.ws.winner.lon.duration);
  EXPECT_EQ(tr.lat.duration, st.ws.winner.lat.duration);
}

TEST(SearchRefinerTest, BrakingIsSentAsSampled) {
  REQUIRE_UDACITY_MAP();
  Stages st(Pinned());
  st.Prepare({kS, 20, 0, 6.0, 0, 0});
  st.lattice.Generate();
  ASSERT_TRUE(st.scorer.Score());
  int braking = -1;
  for (int c = 0; c < static_cast<int>(st.ws.cand_lon.size()) && braking < 0; ++c) {
    if (st.ws.lon[st.ws.cand_lon[c]].kind == cost::LonKind::kBraking) braking = c;
  }
  ASSERT_GE(braking, 0);
  st.ws.TakeWinner(braking);
  const traj::FrenetTrajectory before = st.ws.winner;
  PlanSummary sum;
  st.refiner.Refine(sum);
  EXPECT_EQ(sum.refine_iterations, 0);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(st.ws.winner.lon.poly.c[k], before.lon.poly.c[k]);
}

}  // namespace
}  // namespace frenetic::plan::search

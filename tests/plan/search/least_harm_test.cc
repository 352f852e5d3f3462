// The search planner's least-harm choice: collision-free before colliding, more clearance
// before less, the latest contact when all collide, the cost order last, and never infeasible.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "plan/search/stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::kS;
using testing::SceneCar;
using testing::Stages;

// Candidates by hand: velocity keeping to (end speed, T) in the middle lane, at the given costs.
struct Option {
  double end_speed, T, cost;
};
// No bundles and no candidates.
void ClearCandidates(Workspace& ws) {
  ws.lon.clear();
  ws.lat.clear();
  ws.cand_lon.clear();
  ws.cand_lat.clear();
  ws.cand_cost.clear();
  ws.order.clear();
}
void SetCandidates(Stages& st, const std::vector<Option>& options) {
  Workspace& ws = st.ws;
  ClearCandidates(ws);
  ws.lat.push_back(st.lattice.MakeLat(1, 0.0, 3.0));
  for (const Option& o : options) {
    ws.cand_lon.push_back(static_cast<int>(ws.lon.size()));
    ws.lon.push_back(st.lattice.MakeLon(cost::LonKind::kVelocityKeeping, -1, o.end_speed, o.T));
    ws.cand_lat.push_back(0);
    ws.order.push_back(static_cast<int>(ws.cand_cost.size()));
    ws.cand_cost.push_back(o.cost);
  }
  st.scorer.TakeCostsAsExact();
}

void Start(Stages& st, const std::vector<SceneCar>& cars) {
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, cars);
  st.Prepare({kS, 20, 0, st.ws.lane_center[1], 0, 0}, cars);
}

// The default configuration with least harm ranking every clear candidate by its room
// (check.clear_enough 0) and check.side_clear set to `side` (0: off, every separation counts).
PlannerConfig RoomiestConfig(double side = 0) {
  PlannerConfig config = testing::DefaultConfig();
  const std::string overlay = "check:\n  clear_enough: 0\n  side_clear: " + std::to_string(side);
  EXPECT_TRUE(config.Overlay(overlay + "\n", "test").ok());
  return config;
}

TEST(SearchLeastHarmTest, ClearanceIsTheBareBoxesSeparation) {
  REQUIRE_UDACITY_MAP();
  Stages st(RoomiestConfig(0));  // every separation counts (SideClearCountsACarAlongsideAsClear)
  // Alongside in the next lane at the same speed: 4 m apart laterally, 2.4 m wide.
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS, 2.0, 20}});
  traj::FrenetTrajectory tr;
  tr.lon.poly.c[0] = kS;
  tr.lon.poly.c[1] = 20;
  tr.lon.duration = 5;
  tr.lat.poly.c[0] = 6.0;
  tr.lat.duration = 5;
  EXPECT_NEAR(Clearance(st.ws, tr), 4.0 - st.cfg.check.car_width, 1e-6);
  // 30 m ahead in the same lane: the longitudinal gap minus a car length.
  st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS + 30, 6.0, 20}});
  EXPECT_NEAR(Clearance(st.ws, tr), 30.0 - st.cfg.check.car_length, 1e-6);
}

TEST(SearchLeastHarmTest, PrefersMoreClearanceOverLowerCost) {
  REQUIRE_UDACITY_MAP();
  Stages st(RoomiestConfig());
  // A slower car 30 m ahead: keeping 20 m/s hits it; slowing to 10 m/s in 4 s leaves ~5 m of
  // clearance, in 3 s ~10 m.
  Start(st, {{kS + 30, st.ws.lane_center[1], 10}});
  SetCandidates(st, {{20, 3.0, 1.0}, {10, 4.0, 2.0}, {10, 3.0, 3.0}});
  bool over_budget = false;
  ASSERT_TRUE(st.least_harm.Choose(&over_budget));
  EXPECT_FALSE(over_budget);
  EXPECT_EQ(st.ws.winner_index, 2);
  // Without the roomiest one, the next in room; without both, the collision.
  SetCandidates(st, {{20, 3.0, 1.0}, {10, 4.0, 2.0}});
  ASSERT_TRUE(st.least_harm.Choose(&over_budget));
  EXPECT_EQ(st.ws.winner_index, 1);
  SetCandidates(st, {{20, 3.0, 1.0}});
  ASSERT_TRUE(st.least_harm.Choose(&over_budget));
  EXPECT_EQ(st.ws.winner_index, 0);
  EXPECT_EQ(st.ws.sorted, 0) << "a feasible colliding one is found without the whole ranking";
}

// The harness sets costs without Scorer::Score (SetCandidates, Scorer::TakeCostsAsExact): they
// are exact, and their own bounds. (Before, the bounds were read unsized: heap garbage, and the
// next test failed or passed with what the previous test left in the heap.)
TEST(SearchLeastHarmTest, CostsSetWithoutScoringAreTheirOwnBounds) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  Start(st, {});
  SetCandidates(st, {{20, 3.0, 1.5}, {10, 4.0, 2.5}});
  for (int c = 0; c < 2; ++c) {
    EXPECT_EQ(st.scorer.KnownBound(c), st.ws.cand_cost[c]);
    EXPECT_EQ(st.scorer.Bound(c), st.ws.cand_cost[c]);
    EXPECT_EQ(st.scorer.ExactCost(c), st.ws.cand_cost[c]);
  }
}

// check.clear_enough: the cheapest candidate keeping that much room wins over the roomiest.
TEST(SearchLeastHarmTest, ClearEnoughTakesTheCheapestWithThatMuchRoom) {
  REQUIRE_UDACITY_MAP();
  auto with = [](double enough) {
    PlannerConfig c = testing::DefaultConfig();
    EXPECT_TRUE(c.Overlay("check:\n  clear_enough: " + std::to_string(enough) + "\n", "test").ok());
    return c;
  };
  // The scene of PrefersMoreClearanceOverLowerCost: ~5 m of room for the second, ~10 m for the
  // third, the first collides.
  const std::vector<Option> options = {{20, 3.0, 1.0}, {10, 4.0, 2.0}, {10, 3.0, 3.0}};
  for (const auto& [enough, winner] : {std::pair{3.0, 1}, std::pair{8.0, 2}, std::pair{19.0, 2}}) {
    Stages st(with(enough));
    Start(st, {{kS + 30, st.ws.lane_center[1], 10}});
    SetCandidates(st, options);
    bool over_budget = false;
    ASSERT_TRUE(st.least_harm.Choose(&over_budget)) << enough;
    EXPECT_FALSE(over_budget);
    EXPECT_EQ(st.ws.winner_index, winner) << "clear_enough " << enough;
  }
}

// check.side_clear: a car that far to the side is clear at that step, so a car passing
// alongside in the next lane no longer caps the clearance of a harder brake.
TEST(SearchLeastHarmTest, SideClearCountsACarAlongsideAsClear) {
  REQUIRE_UDACITY_MAP();
  traj::FrenetTrajectory tr;  // on in the middle lane at 20 m/s
  tr.lon.poly.c[0] = kS;
  tr.lon.poly.c[1] = 20;
  tr.lon.duration = 5;
  tr.lat.poly.c[0] = 6.0;
  tr.lat.duration = 5;
  // Alongside in the next lane: 4 m - 2.4 m apart across.
  const double across = 4.0 - testing::DefaultConfig().value("check.car_width");
  for (const auto& [side, clearance] :
       {std::pair{0.0, across}, std::pair{across + 0.1, across}, std::pair{across - 0.1, 1e9}}) {
    Stages st(RoomiestConfig(side));
    st.Prepare({kS, 20, 0, 6.0, 0, 0}, {{kS, 2.0, 20}});
    EXPECT_NEAR(Clearance(st.ws, tr), clearance, 1e-6) << "side_clear " << side;
  }
  // A slower car 30 m ahead in the ego's lane, and a faster one 25 m behind in the next lane.
  // A mild brake (to 14 m/s in 4 s) keeps the car behind out of reach; a hard one (to 8 m/s in
  // 2.5 s) leaves more room ahead but lets the car behind come alongside, 1.6 m across.
  const std::vector<Option> options = {{14, 4.0, 1.0}, {8, 2.5, 2.0}};
  for (const auto& [side, winner] : {std::pair{0.0, 0}, std::pair{1.0, 1}}) {
    Stages st(RoomiestConfig(side));
    const std::vector<SceneCar> cars = {{kS + 30, st.ws.lane_center[1], 14},
                                        {kS - 25, st.ws.lane_center[0], 26}};
    Start(st, cars);
    SetCandidates(st, options);
    double clearance[2];
    for (int c = 0; c < 2; ++c) {
      clearance[c] = ClearanceAt(st.ws, st.collisions.StepsOf(c, 0.0, 1.0));
    }
    bool over_budget = false;
    ASSERT_TRUE(st.least_harm.Choose(&over_budget)) << side;
    EXPECT_FALSE(over_budget);
    EXPECT_EQ(st.ws.winner_index, winner)
        << "side_clear " << side << ": clearances " << clearance[0] << ", " << clearance[1];
  }
}

TEST(SearchLeastHarmTest, EqualClearanceGoesToTheLowerCost) {
  REQUIRE_UDACITY_MAP();
  Stages st(RoomiestConfig());
  Start(st, {{kS + 30, st.ws.lane_center[1], 10}});
  // The same trajectory twice: the same clearance, the cost decides, then the index.
  SetCandidates(st, {{10, 3.0, 3.0}, {10, 4.0, 2.0}, {10, 3.0, 1.0}, {10, 3.0, 1.0}});
  bool over_budget = false;
  ASSERT_TRUE(st.least_harm.Choose(&over_budget));
  EXPECT_EQ(st.ws.winner_index, 2);
}

TEST(SearchLeastHarmTest, TakesTheLatestContactWhenAllCollideAndCostBreaksTies) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  // A stopped car 40 m ahead: every option reaches it, braking later.
  Start(st, {{kS + 40, st.ws.lane_center[1], 0}});
  SetCandidates(st, {{20, 3.0, 1.0}, {10, 3.0, 5.0}, {10, 3.0, 4.0}});
  bool over_budget = false;
  ASSERT_TRUE(st.least_harm.Choose(&over_budget));
  EXPECT_EQ(st.ws.winner_index, 2) << "identical trajectories: the cheaper one";
}

TEST(SearchLeastHarmTest, KeepLaneHoldsTheLastWinnersLaneAfterACycleWithNonePassing) {
  REQUIRE_UDACITY_MAP();
  // Stopped cars 36 m ahead in the ego's (middle) lane and 46 m ahead in the left one. Keeping
  // the lane at 20 m/s meets the first after about 1.5 s; moving left in 2 s meets the second
  // about 0.5 s later, so the latest contact moves left. After a cycle in which none passed,
  // check.keep_lane keeps the last winner's lane (the middle) when that is at most keep_lane
  // sooner.
  struct Case {
    double keep_lane;
    bool none_passed_before;
    int winner;
  };
  for (const Case& k :
       {Case{0.0, true, 1}, Case{0.3, true, 1}, Case{0.8, true, 0}, Case{0.8, false, 1}}) {
    PlannerConfig config = testing::DefaultConfig();
    ASSERT_TRUE(
        config.Overlay("check:\n  keep_lane: " + std::to_string(k.keep_lane) + "\n", "test").ok());
    Stages st(config);
    Start(st, {{kS + 36, st.ws.lane_center[1], 0}, {kS + 46, st.ws.lane_center[0], 0}});
    Workspace& ws = st.ws;
    ClearCandidates(ws);
    ws.lon.push_back(st.lattice.MakeLon(cost::LonKind::kVelocityKeeping, -1, 20, 3.0));
    ws.lat.push_back(st.lattice.MakeLat(1, 0.0, 3.0));
    ws.lat.push_back(st.lattice.MakeLat(0, 0.0, 2.0));
    for (int c = 0; c < 2; ++c) {
      ws.cand_lon.push_back(0);
      ws.cand_lat.push_back(c);
      ws.order.push_back(c);
      ws.cand_cost.push_back(1.0 + c);
    }
    st.scorer.TakeCostsAsExact();
    ws.prev_lat_lane = 1;
    const int contact[2] = {st.collisions.BareContact(0), st.collisions.BareContact(1)};
    ASSERT_LE(contact[1], ws.n_steps) << "the move left meets the car in the left lane";
    const double sooner = (contact[1] - contact[0]) * ws.collision_step * kTickSeconds;
    ASSERT_GT(sooner, 0.35) << "keeping the lane meets its car sooner";
    ASSERT_LT(sooner, 0.75);
    bool over_budget = false;
    ASSERT_TRUE(st.least_harm.Choose(&over_budget, k.none_passed_before));
    EXPECT_FALSE(over_budget);
    EXPECT_EQ(ws.winner_index, k.winner)
        << "keep_lane " << k.keep_lane << ", none passed before " << k.none_passed_before;
  }
}

TEST(SearchLeastHarmTest, NeverTakesAnInfeasibleCandidate) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  Start(st, {});
  // Accelerating to 30 m/s breaks the speed limit.
  SetCandidates(st, {{30, 3.0, 1.0}});
  bool over_budget = false;
  EXPECT_FALSE(st.least_harm.Choose(&over_budget));
  EXPECT_FALSE(over_budget);
}

// The default configuration with check.clear_enough set to `metres`.
PlannerConfig ClearEnoughConfig(double metres) {
  PlannerConfig config = testing::DefaultConfig();
  EXPECT_TRUE(
      config.Overlay("check:\n  clear_enough: " + std::to_string(metres) + "\n", "test").ok());
  return config;
}

// The whole ranking as the search planner once did it: every candidate's contact and
// clearance, sorted, then the first feasible one with the lane-line timer; astride a line
// (the timer running), the first clear one within the simulator's count less a little
// (check.last_resort_ticks); else the first feasible one without the timer.
// *last_resort: the choice came from the simulator's count; *kept_side: from the last winner's
// lane.
int ReferenceChoice(Stages& st, bool* last_resort = nullptr, bool* kept_side = nullptr) {
  Workspace& ws = st.ws;
  std::vector<int> order = ws.order;
  std::vector<int> hit(ws.cand_cost.size());
  std::vector<double> room(ws.cand_cost.size());
  for (const int c : order) {
    const StepStates steps = st.collisions.StepsOf(c, 0.0, 1.0);
    hit[c] = st.collisions.FirstCollision(steps, 0.0, 1.0, nullptr, false);
    room[c] = hit[c] > ws.n_steps ? ClearanceAt(ws, steps) : 0.0;
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (hit[a] != hit[b]) return hit[a] > hit[b];
    if (room[a] != room[b]) return room[a] > room[b];
    return Cheaper(ws, a, b);
  });
  const auto first_feasible = [&](bool lane_line, bool clear_only) {
    for (const int c : order) {
      if (clear_only && hit[c] <= ws.n_steps) continue;
      st.ws.FillTicks(ws.Candidate(c));
      if (st.limits.Violation(nullptr, lane_line) <= 0) return c;
    }
    return -1;
  };
  int c = first_feasible(true, true);
  if (c < 0 && ws.straddle_at_start > 0) {
    st.limits.SetStraddleLimit(st.cfg.check.last_resort_ticks);
    c = first_feasible(true, true);
    st.limits.SetStraddleLimit(kMaxStraddleTicks);
    if (last_resort != nullptr) *last_resort = c >= 0;
  }
  if (c < 0) {
    c = first_feasible(true, false);
    // Astride, the last winner's lane when a feasible move there meets a car at most 0.3 s
    // sooner (the latest such, then the cheapest).
    const int lane = ws.prev_lat_lane;
    if (c >= 0 && ws.straddle_at_start > 0 && lane >= 0 && ws.lat[ws.cand_lat[c]].lane != lane) {
      const int floor = hit[c] - 3;  // collision steps of 0.1 s
      int keep = -1;
      for (const int k : ws.order) {
        if (ws.lat[ws.cand_lat[k]].lane != lane || hit[k] < floor) continue;
        if (keep >= 0 && (hit[k] < hit[keep] || (hit[k] == hit[keep] && !Cheaper(ws, k, keep)))) {
          continue;
        }
        st.ws.FillTicks(ws.Candidate(k));
        if (st.limits.Violation(nullptr, true) <= 0) keep = k;
      }
      if (keep >= 0) {
        c = keep;
        if (kept_side != nullptr) *kept_side = true;
      }
    }
  }
  if (c < 0) c = first_feasible(false, false);
  return c;
}

TEST(SearchLeastHarmTest, ChoosesWhatTheWholeRankingChooses) {
  REQUIRE_UDACITY_MAP();
  // Also with check.side_clear, whose separations across BestClear bounds as the clearance
  // counts them.
  for (const double side : {0.0, 1.0}) {
    Stages st(RoomiestConfig(side));
    std::mt19937 rng(14);
    std::uniform_real_distribution<double> ahead(-25.0, 60.0), speed(5.0, 22.0);
    int chosen = 0, last_resorts = 0, kept_sides = 0;
    for (int scene = 0; scene < 48; ++scene) {
      // Traffic in every lane around the ego, denser scene by scene; the ego at various speeds
      // and offsets, and with the lane-line count near and past its limit (then once for each
      // lane the last winner may have gone to, and for none).
      std::vector<SceneCar> cars;
      for (int k = 0; k < 3 + scene / 2; ++k) {
        cars.push_back({kS + ahead(rng), st.ws.lane_center[k % 3], speed(rng)});
      }
      const bool astride = scene % 4 == 3;
      const double d0 = st.ws.lane_center[1] + (astride ? 1.6 : 0.0);
      for (int prev = -1; prev < (astride ? 3 : 0); ++prev) {
        Start(st, cars);
        st.Prepare({kS, 8.0 + scene % 12, 0, d0, 0, 0}, cars);
        // Near the limit, or with time left to leave the line either way.
        st.ws.straddle_at_start = !astride               ? 0
                                  : (scene / 4) % 2 == 0 ? 100 + 10 * (scene % 5)
                                                         : 20 + 20 * (scene % 5);
        st.ws.prev_lat_lane = prev;
        st.lattice.Generate();
        ASSERT_TRUE(st.scorer.Score());
        // Every other scene, Choose makes the costs exact itself, as far as it needs them.
        const bool lazy = scene % 2 == 1;
        if (!lazy) {
          ASSERT_TRUE(st.scorer.ResolveAll());
        }
        bool over_budget = false;
        // Every third scene says the last search found nothing passing (the candidates are then
        // visited in cost order without bounds until a clear one is found): the same choice.
        const bool ok = st.least_harm.Choose(&over_budget, scene % 3 == 0);
        ASSERT_TRUE(st.scorer.ResolveAll());
        bool last_resort = false, kept_side = false;
        const int expected = ReferenceChoice(st, &last_resort, &kept_side);
        last_resorts += last_resort;
        kept_sides += kept_side;
        EXPECT_FALSE(over_budget);
        EXPECT_EQ(ok, expected >= 0) << "scene " << scene << " prev " << prev;
        if (ok) {
          EXPECT_EQ(st.ws.winner_index, expected) << "scene " << scene << " prev " << prev;
        }
        chosen += ok;
      }
    }
    EXPECT_GT(chosen, 24);
    EXPECT_GT(last_resorts, 0) << "a way off the line within the simulator's count decided";
    EXPECT_GT(kept_sides, 0) << "the last winner's lane decided";
  }
}

// check.clear_enough: the cheapest candidate (exact cost, then index) whose bare boxes keep
// that far from every car and that breaks no limit, also after the lazy check's Advance calls
// moved bounds inside the scorer (a walk of the scorer's sorted order then went wrong: a dearer
// candidate than the cheapest could win).
TEST(SearchLeastHarmTest, ClearEnoughIsTheCheapestThatPassesAfterTheLazyCheck) {
  REQUIRE_UDACITY_MAP();
  Stages st(ClearEnoughConfig(0.5));
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> ahead(-25.0, 60.0), speed(5.0, 22.0), pick(0.0, 1.0);
  int chosen = 0;
  for (int scene = 0; scene < 48; ++scene) {
    std::vector<SceneCar> cars;
    for (int k = 0; k < 6 + scene / 3; ++k) {
      cars.push_back({kS + ahead(rng), st.ws.lane_center[k % 3], speed(rng)});
    }
    Start(st, cars);
    st.Prepare({kS, 8.0 + scene % 12, 0, st.ws.lane_center[1], 0, 0}, cars);
    st.lattice.Generate();
    ASSERT_TRUE(st.scorer.Score());
    // As Selection::CheapestPassing does: some bounds completed, some raised a term or more.
    for (const int c : st.ws.order) {
      if (pick(rng) < 0.5) st.scorer.Bound(c);
      if (pick(rng) < 0.5) st.scorer.Advance(c);
      if (pick(rng) < 0.5) st.scorer.Advance(c);
    }
    bool over_budget = false;
    const bool ok = st.least_harm.Choose(&over_budget);
    EXPECT_FALSE(over_budget);
    // The reference: every exact cost, the cheapest that passes the three tests.
    ASSERT_TRUE(st.scorer.ResolveAll());
    int expected = -1;
    for (const int c : st.ws.order) {
      if (expected >= 0 && !Cheaper(st.ws, c, expected)) continue;
      if (st.collisions.FirstCollision(st.collisions.StepsOf(c, 0.0, 1.0), 0.0, 1.0, nullptr,
                                       false) <= st.ws.n_steps) {
        continue;
      }
      const CollisionChecker::Rows rows = st.collisions.StepRows(c);
      if (!(ClearanceAbove(st.ws, rows.s, rows.d, 0.5) >= 0.5)) continue;
      if (st.limits.CandidateBreaksLimits(c)) continue;
      expected = c;
    }
    if (expected < 0) continue;  // then the harm ranking decides (tested above)
    ASSERT_TRUE(ok) << "scene " << scene;
    EXPECT_EQ(st.ws.winner_index, expected) << "scene " << scene;
    ++chosen;
  }
  EXPECT_GT(chosen, 16);
}

// Boxed in: a slow or stopped car ahead and cars alongside in the other lanes, so that every
// candidate collides, and the latest contacts come from braking hard, which often breaks a
// limit: the choice is then in an earlier contact group, which LatestContact reaches without
// every candidate's contact step (a step it hits at before the latest contact is enough until
// that group fails).
TEST(SearchLeastHarmTest, LatestFeasibleContactWhenTheLatestOnesBreakLimits) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> gap(6.0, 20.0), slow(0.0, 6.0), beside(-8.0, 8.0),
      ego_v(14.0, 22.0);
  int earlier_group = 0;  // scenes whose choice is not in the latest contact group
  for (int scene = 0; scene < 40; ++scene) {
    const double v = ego_v(rng);
    const std::vector<SceneCar> cars = {{kS + gap(rng), st.ws.lane_center[1], slow(rng)},
                                        {kS + beside(rng), st.ws.lane_center[0], v},
                                        {kS + beside(rng), st.ws.lane_center[2], v},
                                        {kS + 15 + beside(rng), st.ws.lane_center[0], v},
                                        {kS + 15 + beside(rng), st.ws.lane_center[2], v}};
    Start(st, cars);
    st.Prepare({kS, v, 0, st.ws.lane_center[1], 0, 0}, cars);
    st.lattice.Generate();
    ASSERT_TRUE(st.scorer.Score());
    bool over_budget = false;
    const bool ok = st.least_harm.Choose(&over_budget, scene % 2 == 0);
    ASSERT_TRUE(st.scorer.ResolveAll());
    const int expected = ReferenceChoice(st);
    EXPECT_FALSE(over_budget);
    ASSERT_EQ(ok, expected >= 0) << "scene " << scene;
    if (!ok) continue;
    EXPECT_EQ(st.ws.winner_index, expected) << "scene " << scene;
    // Whether a later contact than the choice's exists (among the colliding candidates).
    int latest = 0;
    for (const int c : st.ws.order) {
      const int hit = st.collisions.FirstCollision(st.collisions.StepsOf(c, 0.0, 1.0), 0.0, 1.0,
                                                   nullptr, false);
      if (hit <= st.ws.n_steps) latest = std::max(latest, hit);
    }
    const int chosen = st.collisions.FirstCollision(st.collisions.StepsOf(expected, 0.0, 1.0), 0.0,
                                                    1.0, nullptr, false);
    earlier_group += chosen <= st.ws.n_steps && chosen < latest;
  }
  EXPECT_GE(earlier_group, 5) << "the scenes do not reach an earlier contact group";
}

// check.clear_enough with no candidate that clear: CheapestClearEnough has tested every
// candidate on bare boxes, and the harm ranking reads those contacts instead of testing again
// (every one colliding: no visit at all). The choice is the whole ranking's, boxed in and in
// mixed traffic alike.
TEST(SearchLeastHarmTest, TheRankingAfterNoneIsClearEnoughIsTheWholeRankings) {
  REQUIRE_UDACITY_MAP();
  Stages st(ClearEnoughConfig(20));
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> ahead(-25.0, 60.0), speed(5.0, 22.0), gap(6.0, 20.0),
      slow(0.0, 6.0), beside(-8.0, 8.0);
  int compared = 0, boxed_in = 0;
  for (int scene = 0; scene < 80; ++scene) {
    std::vector<SceneCar> cars;
    const double v = 14.0 + scene % 8;
    if (scene % 2 == 0) {  // boxed in: every candidate collides
      cars = {{kS + gap(rng), st.ws.lane_center[1], slow(rng)},
              {kS + beside(rng), st.ws.lane_center[0], v},
              {kS + beside(rng), st.ws.lane_center[2], v},
              {kS + 15 + beside(rng), st.ws.lane_center[0], v},
              {kS + 15 + beside(rng), st.ws.lane_center[2], v},
              {kS - 12, st.ws.lane_center[1], v + 4}};  // and one closing from behind
    } else {
      for (int k = 0; k < 3 + scene / 4; ++k) {
        cars.push_back({kS + ahead(rng), st.ws.lane_center[k % 3], speed(rng)});
      }
    }
    Start(st, cars);
    st.Prepare({kS, v, 0, st.ws.lane_center[1], 0, 0}, cars);
    st.lattice.Generate();
    ASSERT_TRUE(st.scorer.Score());
    bool over_budget = false;
    const bool ok = st.least_harm.Choose(&over_budget, scene % 3 == 0);
    EXPECT_FALSE(over_budget);
    ASSERT_TRUE(st.scorer.ResolveAll());
    bool clear_enough = false, all_collide = true;
    for (const int c : st.ws.order) {
      if (st.collisions.FirstCollision(st.collisions.StepsOf(c, 0.0, 1.0), 0.0, 1.0, nullptr,
                                       false) <= st.ws.n_steps) {
        continue;
      }
      all_collide = false;
      const CollisionChecker::Rows rows = st.collisions.StepRows(c);
      clear_enough = clear_enough || ClearanceAbove(st.ws, rows.s, rows.d, 20.0) >= 20.0;
    }
    if (clear_enough) continue;  // the cheapest that clear wins (tested above)
    const int expected = ReferenceChoice(st);
    ASSERT_EQ(ok, expected >= 0) << "scene " << scene;
    if (ok) {
      EXPECT_EQ(st.ws.winner_index, expected) << "scene " << scene;
    }
    ++compared;
    boxed_in += all_collide;
  }
  EXPECT_GE(compared, 60);
  EXPECT_GE(boxed_in, 5) << "the scenes do not box the ego in";
  EXPECT_LT(boxed_in, compared) << "no scene has a collision-free candidate";
}

}  // namespace
}  // namespace frenetic::plan::search

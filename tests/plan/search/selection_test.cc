// The search planner's selection (Selection): the cheapest candidate that passes every check,
// whatever the hint about the last search.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "plan/search/selection.h"
#include "plan/search/stages_testing.h"
#include "plan/search/tracer.h"

namespace frenetic::plan::search {
namespace {

using testing::SceneCar;
using testing::Stages;
using testing::kS;

// Told that nothing passed last cycle, with check.clear_enough set (the least-harm choice
// then wants every candidate's contact on bare boxes), the selection tests the bare boxes
// first and the inflated ones only where those are clear: the same choice as without the hint,
// in scenes where nothing passes (boxed in) and where something does.
TEST(SelectionTest, TheBareContactsFirstChooseWhatTheFullChecksChoose) {
  REQUIRE_UDACITY_MAP();
  PlannerConfig config = testing::DefaultConfig();
  ASSERT_TRUE(config.Overlay("check:\n  clear_enough: 0.5\n", "test").ok());
  Stages st(config);
  Tracer tracer(st.cfg, st.ws, st.scorer, *st.costs, *st.line, *st.predictor);
  Selection selection(st.cfg, st.ws, st.scorer, st.limits, st.collisions, tracer, st.clock);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> ahead(-25.0, 60.0), speed(5.0, 22.0), gap(6.0, 20.0),
      slow(0.0, 6.0), beside(-8.0, 8.0);
  int none = 0, found = 0, bare_read = 0;
  for (int scene = 0; scene < 40; ++scene) {
    std::vector<SceneCar> cars;
    const double v = 14.0 + scene % 8;
    if (scene % 2 == 0) {  // boxed in
      cars = {{kS + gap(rng), st.ws.lane_center[1], slow(rng)},
              {kS + beside(rng), st.ws.lane_center[0], v},
              {kS + beside(rng), st.ws.lane_center[2], v},
              {kS - 12, st.ws.lane_center[1], v + 4}};
    } else {
      for (int k = 0; k < 3 + scene / 4; ++k) {
        cars.push_back({kS + ahead(rng), st.ws.lane_center[k % 3], speed(rng)});
      }
    }
    int winner[2] = {-1, -1};
    bool passed[2] = {false, false};
    for (const bool hint : {false, true}) {
      st.Prepare({kS, v, 0, st.ws.lane_center[1], 0, 0}, cars);
      st.lattice.Generate();
      ASSERT_TRUE(st.scorer.Score());
      PlanSummary sum;
      bool over_budget = false;
      passed[hint] = selection.Select(hint, &sum, &over_budget);
      EXPECT_FALSE(over_budget);
      winner[hint] = passed[hint] ? st.ws.winner_index : -1;
      if (hint) bare_read += st.collisions.BareContactKnown(st.ws.order.front());
    }
    ASSERT_EQ(passed[true], passed[false]) << "scene " << scene;
    EXPECT_EQ(winner[true], winner[false]) << "scene " << scene;
    none += !passed[false];
    found += passed[false];
  }
  EXPECT_GE(none, 5) << "no scene boxes the ego in";
  EXPECT_GE(found, 5) << "no scene has a candidate that passes";
  EXPECT_GE(bare_read, 30) << "the bare contacts were not measured first";
}

// After a box-in the lattice adds quicker lateral moves (grid.escape_lat_duration). With
// grid.escape_lat_least_harm they are the least harm's alone: the selection never takes one,
// in scenes where without the option it does.
TEST(SelectionTest, QuickEscapesForTheLeastHarmAloneAreNeverSelected) {
  REQUIRE_UDACITY_MAP();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> gap(10.0, 20.0), slower(4.0, 12.0), beside(-6.0, 6.0);
  int quick_taken[2] = {0, 0}, flagged[2] = {0, 0};
  for (const int only : {0, 1}) {
    PlannerConfig config = testing::DefaultConfig();
    ASSERT_TRUE(config.Set("grid.escape_lat_duration", 1.5).ok());
    ASSERT_TRUE(config.Set("grid.escape_lat_least_harm", only).ok());
    Stages st(config);
    Tracer tracer(st.cfg, st.ws, st.scorer, *st.costs, *st.line, *st.predictor);
    Selection selection(st.cfg, st.ws, st.scorer, st.limits, st.collisions, tracer, st.clock);
    rng.seed(5);
    for (int scene = 0; scene < 40; ++scene) {
      // Off the middle lane's centre toward the left one, a much slower car close ahead in the
      // middle lane, the left lane free and a car beside in the right one: braking comes too
      // late, a 2 s move left stays beside the slow car too long, a quicker one clears it.
      const double v = 18.0 + scene % 4;
      const std::vector<SceneCar> cars = {{kS + gap(rng), st.ws.lane_center[1], v - slower(rng)},
                                          {kS + beside(rng), st.ws.lane_center[2], v}};
      st.Prepare({kS, v, 0, st.ws.lane_center[1] - 0.8, 0, 0}, cars);
      st.ws.none_passed_last = true;
      st.lattice.Generate();
      for (const LatTraj& l : st.ws.lat) flagged[only] += l.least_harm_only;
      ASSERT_TRUE(st.scorer.Score());
      PlanSummary sum;
      bool over_budget = false;
      if (!selection.Select(true, &sum, &over_budget)) continue;
      const LatTraj& won = st.ws.lat[st.ws.winner_lat];
      EXPECT_FALSE(won.least_harm_only) << "scene " << scene;
      quick_taken[only] += won.traj.duration < 2.0;
    }
  }
  EXPECT_EQ(flagged[0], 0);
  EXPECT_GT(flagged[1], 0);
  EXPECT_GT(quick_taken[0], 0) << "no scene where the selection takes a quick move";
  EXPECT_EQ(quick_taken[1], 0);
}

}  // namespace
}  // namespace frenetic::plan::search

// The search planner's continuity: consumed points and lost sync, the kept points a search
// starts after, plan reuse and what stops it, the loop shift, and the NaN guard of the output.
#include <gtest/gtest.h>

#include <cmath>

#include "plan/search/stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::Stages;
using testing::kS;

// A stored plan from a search without kept points: steady 20 m/s in the middle lane.
PlanResult StorePlan(Stages& st) {
  st.Prepare({kS, 20, 0, 6.0, 0, 0});
  st.WriteTicks(kS, 20, 6.0, [](double) { return 0.0; });
  PlanResult plan;
  st.continuity.Store(plan);
  return plan;
}

// The telemetry after the simulator drove `consumed` points of `plan`.
Telemetry Driven(const PlanResult& plan, int consumed) {
  Telemetry t;
  t.x = plan.x[consumed - 1];
  t.y = plan.y[consumed - 1];
  t.speed = 20;
  t.previous_path_x.assign(plan.x.begin() + consumed, plan.x.end());
  t.previous_path_y.assign(plan.y.begin() + consumed, plan.y.end());
  return t;
}

TEST(SearchContinuityTest, FindsTheConsumedPointsAndNoticesALostSync) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  Telemetry none;
  EXPECT_FALSE(st.continuity.Synchronise(none, true, false).synced) << "no plan yet";
  const PlanResult plan = StorePlan(st);
  ASSERT_EQ(plan.x.size(), static_cast<size_t>(st.cfg.continuity.output_points));
  EXPECT_EQ(st.continuity.plan_n(), st.cfg.continuity.output_points);
  for (const int consumed : {1, 3, 40}) {
    const Continuity::Sync s = st.continuity.Synchronise(Driven(plan, consumed), true, true);
    EXPECT_TRUE(s.synced) << consumed;
    EXPECT_EQ(s.consumed, consumed);
  }
  Telemetry moved = Driven(plan, 3);
  moved.previous_path_x[0] += 1.0;  // not our path any more
  EXPECT_FALSE(st.continuity.Synchronise(moved, true, true).synced);
  Telemetry longer = Driven(plan, 1);
  longer.previous_path_x.insert(longer.previous_path_x.begin(), plan.x[0]);
  longer.previous_path_y.insert(longer.previous_path_y.begin(), plan.y[0]);
  longer.previous_path_x.push_back(0);
  longer.previous_path_y.push_back(0);
  EXPECT_FALSE(st.continuity.Synchronise(longer, true, true).synced) << "more than we sent";
  EXPECT_FALSE(st.continuity.Synchronise(Driven(plan, 3), false, true).synced);
  // An unusable pose with a plan to follow: one tick passed.
  const Continuity::Sync blind = st.continuity.Synchronise(none, true, false);
  EXPECT_TRUE(blind.synced);
  EXPECT_EQ(blind.consumed, 1);
}

TEST(SearchContinuityTest, KeepsPointsAndStartsFromTheLastKeptOne) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  const PlanResult plan = StorePlan(st);
  const Workspace& ws = st.ws;
  double elapsed = -1;
  // Plan point k was tick k + 1; 3 driven, 6 kept: the start is point 8.
  const traj::FrenetState start = st.continuity.KeepPoints(3, 6, &elapsed);
  EXPECT_EQ(start.s, ws.tk_s[9]);
  EXPECT_EQ(start.s_d, ws.tk_sd[9]);
  EXPECT_EQ(start.d, ws.tk_d[9]);
  EXPECT_EQ(elapsed, 9 * kTickSeconds) << "from the stored plan's start, before its point 0";
  EXPECT_EQ(st.continuity.plan_s(0), ws.tk_s[4]);
  EXPECT_EQ(ws.straddle_at_start, 0) << "centred in a lane";
  // The next plan begins with the kept points.
  st.ws.kept = 6;
  PlanResult next;
  st.continuity.Store(next);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(next.x[i], plan.x[3 + i]);
    EXPECT_EQ(next.y[i], plan.y[3 + i]);
  }
}

TEST(SearchContinuityTest, ReusesThePlanUntilTooManyPointsOrTheTrafficChanges) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  const PlanResult plan = StorePlan(st);
  const Telemetry searched = Driven(plan, 1);
  st.continuity.SearchDone(searched, /*can_reuse=*/true);
  EXPECT_TRUE(st.continuity.CanReuse(Driven(plan, 1), 1));
  EXPECT_FALSE(st.continuity.CanReuse(Driven(plan, 4), st.cfg.continuity.replan_min_ticks))
      << "replan_min_ticks points driven";
  PlanResult reused;
  st.continuity.ReusePlan(1, reused);
  ASSERT_EQ(reused.x.size(), plan.x.size() - 1);
  for (size_t i = 0; i < reused.x.size(); ++i) EXPECT_EQ(reused.x[i], plan.x[i + 1]);
  EXPECT_EQ(reused.summary.points_kept, static_cast<int>(plan.x.size()) - 1);
  EXPECT_EQ(reused.summary.candidates_generated, 0);
  // One tick since the search already: two more reach replan_min_ticks (4).
  EXPECT_TRUE(st.continuity.CanReuse(Driven(reused, 1), 2));
  EXPECT_FALSE(st.continuity.CanReuse(Driven(reused, 3), 3));

  // A car appearing nearby forces a search; one far away does not.
  Telemetry near = Driven(reused, 1);
  near.sensor_fusion.push_back(st.Row(7, {kS + 40, 2.0, 20}));
  EXPECT_FALSE(st.continuity.CanReuse(near, 1));
  Telemetry far = Driven(reused, 1);
  far.sensor_fusion.push_back(st.Row(7, {kS + 1500, 2.0, 20}));
  ASSERT_GT(std::hypot(far.sensor_fusion[0].x - far.x, far.sensor_fusion[0].y - far.y), 200);
  EXPECT_TRUE(st.continuity.CanReuse(far, 1));

  // A known car is reused while it moves as seen, not when it deviates.
  Telemetry with_car = Driven(plan, 1);
  with_car.sensor_fusion.push_back(st.Row(3, {kS + 30, 2.0, 18}));
  st.continuity.SearchDone(with_car, true);
  Telemetry as_seen = Driven(plan, 2);
  as_seen.sensor_fusion.push_back(st.Row(3, {kS + 30 + 18 * kTickSeconds, 2.0, 18}));
  EXPECT_TRUE(st.continuity.CanReuse(as_seen, 1));
  Telemetry swerved = as_seen;
  swerved.sensor_fusion[0] = st.Row(3, {kS + 30 + 18 * kTickSeconds, 3.0, 18});
  EXPECT_FALSE(st.continuity.CanReuse(swerved, 1));
  Telemetry vanished = Driven(plan, 2);
  EXPECT_FALSE(st.continuity.CanReuse(vanished, 1));

  // A search whose plan may not be reused.
  st.continuity.SearchDone(searched, /*can_reuse=*/false);
  EXPECT_FALSE(st.continuity.CanReuse(Driven(plan, 1), 1));
}

TEST(SearchContinuityTest, RebaseShiftsByWholeLoops) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  StorePlan(st);
  double elapsed = 0;
  st.continuity.KeepPoints(1, 6, &elapsed);
  const double L = st.line->length();
  const double kept_s = st.continuity.plan_s(0);
  st.ws.prev_traj.lon.poly.c[0] = 123;
  traj::FrenetState start{L + 5, 20, 0, 6, 0, 0};
  st.continuity.Rebase(start, 6);
  EXPECT_NEAR(start.s, 5, 1e-9);
  EXPECT_EQ(st.continuity.plan_s(0), kept_s - L);
  EXPECT_EQ(st.ws.prev_traj.lon.poly.c[0], 123 - L);
  traj::FrenetState behind{-5, 20, 0, 6, 0, 0};
  st.continuity.Rebase(behind, 0);
  EXPECT_NEAR(behind.s, L - 5, 1e-9);
}

TEST(SearchContinuityTest, StoresTheKeptPointsThenTheTicksInXy) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  const PlanResult first = StorePlan(st);
  for (int k = 0; k < st.cfg.continuity.output_points; ++k) {
    const map::CartesianPose p = st.line->ToCartesian(st.ws.tk_s[k + 1], st.ws.tk_d[k + 1]);
    ASSERT_EQ(first.x[k], p.x) << k;
    ASSERT_EQ(first.y[k], p.y) << k;
  }
  double elapsed = 0;
  st.continuity.KeepPoints(2, 6, &elapsed);
  st.ws.kept = 6;
  st.WriteTicks(kS + 50, 20, 2.0, [](double) { return 0.0; });
  PlanResult second;
  st.continuity.Store(second);
  ASSERT_EQ(second.x.size(), first.x.size());
  for (int k = 0; k < 6; ++k) EXPECT_EQ(second.x[k], first.x[k + 2]);
  const map::CartesianPose p = st.line->ToCartesian(st.ws.tk_s[1], st.ws.tk_d[1]);
  EXPECT_EQ(second.x[6], p.x);
  EXPECT_EQ(second.y[6], p.y);
  EXPECT_EQ(st.continuity.plan_n(), st.cfg.continuity.output_points);
}

}  // namespace
}  // namespace frenetic::plan::search

// record::Replica, the planner that traces a record's candidates: it must plan each cycle as the
// planner that drove did, including a cycle the caller planned with the least-harm choice off
// (the CommonRoad loop does so while its rescue holds a way).
#include "frenetic/record/replica.h"

#include <gtest/gtest.h>

#include <memory>
#include <utility>
#include <vector>

#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "plan/closed_loop_testing.h"

namespace frenetic::record {
namespace {

using plan::closed_loop::Loop;

std::unique_ptr<plan::Planner> SearchPlanner(const plan::PlannerConfig& config,
                                             std::shared_ptr<const map::ReferenceLine> line) {
  auto made = plan::MakePlanner("search", config, std::move(line));
  EXPECT_TRUE(made.ok()) << made.message();
  return made.ok() ? std::move(made.value()) : nullptr;
}

// Boxed in (a car at walking pace a few metres ahead in every lane): no candidate passes, and
// the path differs with the least-harm choice on and off.
TEST(Replica, TracesACycleThePlannerDroveWithTheLeastHarmOff) {
  REQUIRE_MAP(line);
  plan::PlannerConfig config = plan::closed_loop::Config();
  config.PinDeadlines();
  auto driver = SearchPlanner(config, line);
  ASSERT_NE(driver, nullptr);
  Loop loop(line, driver.get(), 1500, 6.0, 20.0, 7);
  loop.cars.push_back({0, 1508, 2.0, 2.0});
  loop.cars.push_back({1, 1508, 6.0, 2.0});
  loop.cars.push_back({2, 1508, 10.0, 2.0});
  const plan::Telemetry t = loop.Make();
  driver->set_least_harm(false);
  const plan::PlanResult off = driver->Plan(t);
  ASSERT_EQ(off.status, plan::PlanStatus::kFallbackUsed);

  // Told the least harm was off, the replica plans the same path and traces its candidates.
  {
    Replica replica(SearchPlanner(config, line), 40, "off");
    plan::PlanSummary summary = off.summary;
    std::vector<plan::CandidateTrace> candidates;
    EXPECT_TRUE(replica.Trace(&t, off.x, off.y, 0, &summary, &candidates, false));
    EXPECT_TRUE(replica.active());
    EXPECT_FALSE(candidates.empty());
    EXPECT_EQ(summary.candidates_generated, off.summary.candidates_generated);
  }
  // Not told, it plans the least-harm path, not the one sent, and stops tracing.
  {
    Replica replica(SearchPlanner(config, line), 40, "on");
    plan::PlanSummary summary = off.summary;
    std::vector<plan::CandidateTrace> candidates;
    EXPECT_FALSE(replica.Trace(&t, off.x, off.y, 0, &summary, &candidates));
    EXPECT_FALSE(replica.active());
    EXPECT_TRUE(candidates.empty());
  }
}

}  // namespace
}  // namespace frenetic::record

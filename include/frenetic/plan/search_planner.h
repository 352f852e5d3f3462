// The `search` planner: a Frenet lattice after Werling, Ziegler, Kammel and Thrun, "Optimal
// Trajectory Generation for Dynamic Street Scenarios in a Frenet Frame", ICRA 2010 — quartic
// velocity keeping, quintic following (constant time-gap law) and stopping, quintic lateral
// moves to lane centres, every lon x lat pair scored by the weighted cost set, then checked
// lazily in cost order on the XY path, refined with NLopt, with a keep-lane braking fallback.
// Between searches (fewer than continuity.replan_min_ticks points driven and no material change
// in traffic) Plan() re-sends the previous plan minus the consumed points: such a cycle reports
// candidates_generated == 0 with status ok. Set continuity.replan_min_ticks to 1 to search on
// every call (e.g. to benchmark the search itself).
#pragma once

#include <functional>
#include <memory>

#include "frenetic/cost/cost_set.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::plan {

// Milliseconds from an arbitrary origin, increasing: what the deadline (budget_ms) is measured
// with. Tests inject a fake one to trip the deadline in a chosen stage without depending on the
// machine's speed; the default is std::chrono::steady_clock.
using PlannerClock = std::function<double()>;

std::unique_ptr<Planner> MakeSearchPlanner(const PlannerConfig& config,
                                           std::shared_ptr<const map::Road> road,
                                           std::shared_ptr<const cost::CostSet> costs,
                                           PlannerClock clock = nullptr);
// On the configured uniform road along `line` (ConfiguredRoad).
std::unique_ptr<Planner> MakeSearchPlanner(const PlannerConfig& config,
                                           std::shared_ptr<const map::ReferenceLine> line,
                                           std::shared_ptr<const cost::CostSet> costs,
                                           PlannerClock clock = nullptr);

std::unique_ptr<Planner> MakeBaselinePlanner(const PlannerConfig& config,
                                             std::shared_ptr<const map::ReferenceLine> line);

}  // namespace frenetic::plan

#include "frenetic/plan/planner.h"

#include "frenetic/plan/planner_config.h"
#include "plan/search_planner.h"

namespace frenetic::plan {

const char* ToString(PlanStatus status) {
  switch (status) {
    case PlanStatus::kOk: return "ok";
    case PlanStatus::kFallbackUsed: return "fallback_used";
    case PlanStatus::kInvalidInput: return "invalid_input";
    case PlanStatus::kOverBudget: return "over_budget";
  }
  return "unknown";
}

const char* ToString(PlanSummary::Stage stage) {
  switch (stage) {
    case PlanSummary::Stage::kNone: return "none";
    case PlanSummary::Stage::kScore: return "score";
    case PlanSummary::Stage::kCheck: return "check";
    case PlanSummary::Stage::kRefine: return "refine";
  }
  return "unknown";
}

const char* ToString(Reject reason) {
  switch (reason) {
    case Reject::kSpeed: return "speed";
    case Reject::kAcceleration: return "acceleration";
    case Reject::kJerk: return "jerk";
    case Reject::kOffRoad: return "off_road";
    case Reject::kCollision: return "collision";
    case Reject::kLaneLine: return "lane_line";
    case Reject::kCount: break;
  }
  return "unknown";
}

std::vector<std::string> PlannerNames() { return {"search", "baseline"}; }

StatusOr<std::unique_ptr<Planner>> MakePlanner(std::string_view name, const PlannerConfig& config,
                                               std::shared_ptr<const map::ReferenceLine> line) {
  if (line == nullptr) return Status::Error("MakePlanner: no reference line");
  if (name == "search") {
    auto costs = cost::CostSet::Build(config.cost_terms());
    if (!costs.ok()) return Status::Error(config.source() + ": " + costs.message());
    return MakeSearchPlanner(config, std::move(line), std::move(costs.value()));
  }
  if (name == "baseline") return MakeBaselinePlanner(config, std::move(line));
  return Status::Error("unknown planner '" + std::string(name) + "' (known: search, baseline)");
}

}  // namespace frenetic::plan

#include "frenetic/plan/planner.h"

#include "frenetic/plan/planner_config.h"
#include "frenetic/plan/search_planner.h"

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

std::shared_ptr<const map::Road> ConfiguredRoad(const PlannerConfig& config,
                                                std::shared_ptr<const map::ReferenceLine> line) {
  return map::Road::Uniform(std::move(line), config.int_value("road.num_lanes"),
                            config.value("road.lane_width"));
}

StatusOr<std::unique_ptr<Planner>> MakePlanner(std::string_view name, const PlannerConfig& config,
                                               std::shared_ptr<const map::Road> road) {
  if (road == nullptr) return Status::Error("MakePlanner: no road");
  if (name == "search") {
    auto costs = cost::CostSet::Build(config.cost_terms());
    if (!costs.ok()) return Status::Error(config.source() + ": " + costs.message());
    return MakeSearchPlanner(config, std::move(road), std::move(costs.value()));
  }
  if (name == "baseline") return MakeBaselinePlanner(config, road->line_ptr());
  return Status::Error("unknown planner '" + std::string(name) + "' (known: search, baseline)");
}

StatusOr<std::unique_ptr<Planner>> MakePlanner(std::string_view name, const PlannerConfig& config,
                                               std::shared_ptr<const map::ReferenceLine> line) {
  if (line == nullptr) return Status::Error("MakePlanner: no reference line");
  return MakePlanner(name, config, ConfiguredRoad(config, std::move(line)));
}

}  // namespace frenetic::plan

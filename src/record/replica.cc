#include "frenetic/record/replica.h"

#include <spdlog/spdlog.h>

#include <utility>

namespace frenetic::record {

Replica::Replica(std::unique_ptr<plan::Planner> planner, int max_candidates, std::string label)
    : planner_(std::move(planner)), label_(std::move(label)) {
  if (planner_) {
    planner_->Reset();
    planner_->set_trace(&trace_, max_candidates);
  }
}

bool Replica::Trace(const plan::Telemetry* telemetry, const std::vector<double>& path_x,
                    const std::vector<double>& path_y, int cycle, plan::PlanSummary* summary,
                    std::vector<plan::CandidateTrace>* candidates, bool least_harm) {
  if (!planner_) return false;
  const plan::PlanResult* r = nullptr;
  if (telemetry != nullptr) {
    trace_.candidates.clear();
    planner_->set_least_harm(least_harm);
    r = &planner_->Plan(*telemetry);
  }
  if (r == nullptr || r->x != path_x || r->y != path_y) {
    spdlog::warn(
        "record {}: the replica that traces the candidates planned cycle {} otherwise than the "
        "planner that drove{}; candidates are left out from there on",
        label_, cycle, r == nullptr ? " (its telemetry did not parse)" : "");
    planner_.reset();
    return false;
  }
  // The counts of the traced search; the timings stay the driving planner's.
  plan::PlanSummary traced = r->summary;
  traced.ms_prepare = summary->ms_prepare;
  traced.ms_generate = summary->ms_generate;
  traced.ms_score = summary->ms_score;
  traced.ms_check = summary->ms_check;
  traced.ms_refine = summary->ms_refine;
  traced.ms_output = summary->ms_output;
  traced.ms_total = summary->ms_total;
  traced.deadline_stage = summary->deadline_stage;
  *summary = std::move(traced);
  candidates->swap(trace_.candidates);
  return true;
}

}  // namespace frenetic::record

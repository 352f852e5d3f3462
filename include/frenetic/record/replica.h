// The planner that traces a record's candidates: a replica of the one that drives, planning
// every cycle again on the record's writer thread, so that the planner that drives needs no
// trace (tracing costs it ~13% of its time) and its planning times stay those of a run without a
// record. Needs a deterministic planner (wall-clock deadlines pinned); should the replica ever
// plan otherwise, a warning is logged and candidates are left out from there on.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "frenetic/plan/planner.h"

namespace frenetic::record {

class Replica {
 public:
  // `planner` is made as the one that drives (Reset() here) and traces up to `max_candidates`;
  // `label` names the record in warnings.
  Replica(std::unique_ptr<plan::Planner> planner, int max_candidates, std::string label);
  Replica(const Replica&) = delete;
  Replica& operator=(const Replica&) = delete;

  // Plans `telemetry` (null: it could not be read) again. When the replica sends the path the
  // planner that drove sent (path_x, path_y), *summary takes the replica's counts, keeping its
  // own times and deadline stage, *candidates the traced candidates, and it returns true.
  // Otherwise it warns, naming `cycle`, and stays inactive: false from then on. `least_harm`:
  // whether the planner that drove had its least-harm choice on this cycle
  // (plan::Planner::set_least_harm; the CommonRoad loop turns it off while the rescue holds a way).
  bool Trace(const plan::Telemetry* telemetry, const std::vector<double>& path_x,
             const std::vector<double>& path_y, int cycle, plan::PlanSummary* summary,
             std::vector<plan::CandidateTrace>* candidates, bool least_harm = true);
  bool active() const { return planner_ != nullptr; }

 private:
  std::unique_ptr<plan::Planner> planner_;  // null once it planned otherwise
  plan::CycleTrace trace_;
  std::string label_;
};

}  // namespace frenetic::record

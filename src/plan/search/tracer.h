// What a traced cycle shows (Planner::set_trace): the first candidates in cost order, each with
// its path, its costs term by term and why it was rejected (the car and the time of a
// collision). Off unless a trace is attached; nothing here runs in an untraced cycle.
#pragma once

#include <vector>

#include "frenetic/cost/cost_set.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/plan/planner.h"
#include "plan/predictor.h"
#include "plan/search/scoring.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

class Tracer {
 public:
  // Every argument must outlive this.
  Tracer(const Settings& cfg, const Workspace& ws, Scorer& scorer, const cost::CostSet& costs,
         const map::ReferenceLine& line, const Predictor& predictor);

  // Traces into `trace` (nullptr: off), at most max_candidates a cycle.
  void Attach(CycleTrace* trace, int max_candidates) {
    trace_ = trace;
    max_ = max_candidates;
  }
  bool on() const { return trace_ != nullptr; }
  int max_candidates() const { return max_; }
  // Whether the ranks [0, max_candidates()) have all been traced this cycle (true when off).
  bool full() const {
    return trace_ == nullptr || static_cast<int>(trace_->candidates.size()) >= max_;
  }
  // A new cycle: the last one's candidates go.
  void Clear() {
    if (trace_ != nullptr) trace_->candidates.clear();
  }
  // The candidate of cost rank `rank`: the winner, rejected for Reject `reject` (-1: neither,
  // it ranks after the winner) against context car `car` (-1: none) at time t (s). Nothing
  // once full().
  void Add(int rank, bool winner, int reject, int car = -1, double t = 0);

 private:
  const Settings& cfg_;
  const Workspace& ws_;
  Scorer& scorer_;
  const cost::CostSet& costs_;
  const map::ReferenceLine& line_;
  const Predictor& predictor_;
  CycleTrace* trace_ = nullptr;
  int max_ = 0;
  std::vector<double> per_term_;  // unweighted term values
};

}  // namespace frenetic::plan::search

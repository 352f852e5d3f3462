#include "plan/search_least_harm.h"

#include <algorithm>
#include <cmath>

#include "frenetic/plan/planner.h"
#include "plan/search_scoring.h"

namespace frenetic::plan::search {

double Clearance(const Settings& cfg, const Workspace& ws, const traj::FrenetTrajectory& tr) {
  return ClearanceAt(cfg, ws, [&](int i) { return tr.At(i * kTickSeconds); });
}

LeastHarm::LeastHarm(const Settings& cfg, Workspace& ws, Checker& checker, const CycleClock& clock)
    : cfg_(cfg), ws_(ws), checker_(checker), clock_(clock) {
  first_hit_.reserve(ws_.order.capacity());
  clearance_.reserve(ws_.order.capacity());
}

bool LeastHarm::Choose(bool* over_budget) {
  std::vector<int>& order = ws_.order;
  const int n = static_cast<int>(order.size());
  first_hit_.resize(n);
  clearance_.resize(n);
  for (int r = 0; r < n; ++r) {
    if ((r & 31) == 31 && clock_.Elapsed() > 0.85 * cfg_.budget_ms) {
      *over_budget = true;
      return false;
    }
    const int c = order[r];
    const StepStates steps = checker_.StepsOf(c, 0.0, 1.0);
    first_hit_[c] = checker_.FirstCollision(steps, 0.0, 1.0, nullptr, false);
    clearance_[c] = first_hit_[c] > ws_.n_steps ? ClearanceAt(cfg_, ws_, steps) : 0.0;
  }
  // Latest contact first, then most room; the cost order breaks ties (a strict total order:
  // std::stable_sort would allocate).
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (first_hit_[a] != first_hit_[b]) return first_hit_[a] > first_hit_[b];
    if (clearance_[a] != clearance_[b]) return clearance_[a] > clearance_[b];
    return Cheaper(ws_, a, b);
  });
  ws_.sorted = n;
  // Feasible first; then ignoring the lane-line timer (an incident, but not a crash).
  for (const bool lane_line : {true, false}) {
    for (int r = 0; r < n; ++r) {
      if ((r & 7) == 7 && clock_.Elapsed() > 0.85 * cfg_.budget_ms) {
        *over_budget = true;
        return false;
      }
      const int c = order[r];
      checker_.FillTicks(ws_.Candidate(c));
      if (checker_.Violation(nullptr, lane_line) > 0) continue;
      ws_.TakeWinner(c);
      return true;
    }
  }
  return false;
}

}  // namespace frenetic::plan::search

#include "plan/search_least_harm.h"

#include <algorithm>
#include <cmath>

#include "frenetic/plan/planner.h"
#include "plan/search_scoring.h"

namespace frenetic::plan::search {

double Clearance(const Settings& cfg, const Workspace& ws, const traj::FrenetTrajectory& tr) {
  double worst = 1e9;
  for (int j = 1; j <= ws.n_steps; ++j) {
    const traj::FrenetState st = tr.At(j * ws.collision_step * kTickSeconds);
    for (int c = 0; c < ws.ctx.num_cars; ++c) {
      const int at = c * (ws.n_steps + 1) + j;
      const double sep = std::max(std::abs(ws.step_s[at] - st.s) - cfg.car_length,
                                  std::abs(ws.step_d[at] - st.d) - cfg.car_width);
      worst = std::min(worst, sep);
    }
  }
  return worst;
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
    const traj::FrenetTrajectory tr = ws_.Candidate(c);
    first_hit_[c] =
        checker_.FirstCollision([&](int i) { return tr.At(i * kTickSeconds); }, 0.0, 1.0,
                                nullptr, false);
    clearance_[c] = first_hit_[c] > ws_.n_steps ? Clearance(cfg_, ws_, tr) : 0.0;
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

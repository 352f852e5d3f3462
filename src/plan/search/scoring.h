// Scoring of the search planner's candidates: the broad-phase masks of the cost terms, the
// CostInput of a candidate (or of any trajectory, sampled like the bundles), the weighted cost
// of every candidate in generation order, and the lazy sort into cost order (ties by index).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "frenetic/cost/cost_set.h"
#include "frenetic/cost/cost_term.h"
#include "frenetic/traj/frenet.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// Broad phase of the cost terms (cost::CostInput::near_lat, near_lon): which of the context's
// cars are within each reach of d[k] (near[0..n) and near[n..2n)), and of s[k]; n = n_samples.
inline void NearLat(const Workspace& ws, const double* d, std::uint64_t* near) {
  cost::FillNearMasks(d, ws.n_samples, ws.ctx.num_cars, cost::kNearLateral, ws.car_d.data(),
                      ws.n_samples, near);
}
inline void NearLon(const Workspace& ws, const double* s, std::uint64_t* near) {
  cost::FillNearMasks(s, ws.n_samples, ws.ctx.num_cars, cost::kNearLongitudinal, ws.car_s.data(),
                      ws.n_samples, near);
}
// Points a cost input at a trajectory's masks (each 2 * n_samples words, as Near* fill them).
inline void SetNear(const Workspace& ws, cost::CostInput& in, const std::uint64_t* lat,
                    const std::uint64_t* lon) {
  in.near_lat[0] = lat;
  in.near_lat[1] = lat + ws.n_samples;
  in.near_lon[0] = lon;
  in.near_lon[1] = lon + ws.n_samples;
}

// Restores the heap [first, last) (std::make_heap's, by `less`) after its top's key moved
// down the order (a bound completed: never smaller): one sift down, where std::pop_heap and
// std::push_heap take two passes. The keys of the planner's heaps are total orders (ties
// break by index), so the order they come off in is the same either way.
template <typename It, typename Less>
void SiftDownTop(It first, It last, Less less) {
  const std::ptrdiff_t n = last - first;
  std::ptrdiff_t i = 0;
  auto v = std::move(first[0]);
  for (;;) {
    std::ptrdiff_t child = 2 * i + 1;
    if (child >= n) break;
    if (child + 1 < n && less(first[child], first[child + 1])) ++child;
    if (!less(v, first[child])) break;
    first[i] = std::move(first[child]);
    i = child;
  }
  first[i] = std::move(v);
}

// Cost order, ties by index: a strict total order on candidates.
inline bool Cheaper(const Workspace& ws, int a, int b) {
  return ws.cand_cost[a] < ws.cand_cost[b] || (ws.cand_cost[a] == ws.cand_cost[b] && a < b);
}

class Scorer {
 public:
  // `costs`, `ws` and `clock` must outlive the scorer.
  Scorer(const Settings& cfg, const cost::CostSet& costs, Workspace& ws, const CycleClock& clock);

  // Scores every candidate and sets ws.order to the candidates, unsorted. False when the
  // deadline (half of budget_ms) stopped it early: the candidates scored so far, in generation
  // order, are the cycle's candidates then. Lazy: only a coarse lower bound of each cost (the
  // terms that are neither Expensive() nor Sampled(), CostSet::CoarseLowerBound) is computed
  // here, made the cheap terms' bound (CostSet::LowerBound, Bound) only for the candidates that
  // need it; ws.cand_cost[c] (the cost set's value, a non-finite cost counting as 1e300) is
  // exact for the ranks SortUpTo has sorted, and for every candidate after ResolveAll.
  bool Score();
  // Sorts ws.order lazily: ranks up to `rank` are in cost order afterwards. Evaluates the
  // expensive terms of just the candidates whose lower bound could rank them that early, in
  // bound order (best first): the result is the one a full sort by exact cost would give.
  // False when the deadline (85% of budget_ms, the checks' share) stopped that evaluation
  // first: then `rank` may not be sorted yet.
  bool SortUpTo(int rank);
  // Makes every ws.cand_cost exact (for an order over all candidates). False when the deadline
  // (85% of budget_ms, the checks' share) stopped it early.
  bool ResolveAll();
  // Candidate c's exact cost (ws.cand_cost[c]), evaluated now if Score() left only its bound;
  // the lazy sort's result is unchanged. Costs set without Score() are taken as exact.
  double ExactCost(int c);
  // Candidate c's lower bound, the cheap terms' (CostSet::LowerBound; completed now if Score()
  // left it coarse): its exact cost is never below it.
  double Bound(int c) {
    Tighten(c);
    return bound_[c];
  }
  // Candidate c's lower bound as far as it is known: Bound(c) when that is complete
  // (BoundComplete), else the coarse one, never above it.
  double KnownBound(int c) const { return bound_[c]; }
  // In place of Score(), for costs set directly in ws.cand_cost (tests): each is exact and its
  // own bound, for the candidates of ws.order.
  void TakeCostsAsExact();
  bool BoundComplete(int c) const { return complete_[c] != 0; }
  // Whether candidate c's ws.cand_cost is exact (ExactCost would evaluate nothing).
  bool Resolved(int c) const {
    return c >= static_cast<int>(resolved_.size()) || resolved_[c] != 0;
  }
  // Candidate c's cost a step closer to exact: its bound completed (Bound), and one more of the
  // expensive terms evaluated (those with the largest values in the last cycle first). A lower
  // bound of its exact cost, never below the last one Advance or Bound gave, and the exact cost
  // (ExactCost) once every expensive term is in. A caller that ranks candidates by it, advancing
  // the one that comes first until it is exact, ranks them as by exact cost while evaluating
  // fewer terms: a term whose candidate falls behind without it is never evaluated.
  double Advance(int c);

  // The cost input of bundle pair (lon i, lat j), reading the bundles' samples and masks.
  cost::CostInput InputFor(int i, int j);
  // The same without the broad-phase masks (null): for the cheap terms of the lower bound,
  // which read none.
  cost::CostInput BoundInputFor(int i, int j) const;
  // Samples `tr` on the scoring grid into this scorer's own buffers and points a cost input at
  // them; lbase and dbase give the family and target lane. Valid until the next call.
  cost::CostInput SampleForCost(const traj::FrenetTrajectory& tr, const LonTraj& lbase,
                                const LatTraj& dbase);
  // Weighted cost of a trajectory sampled like the bundles (1e300 when not finite).
  double CostOf(const traj::FrenetTrajectory& tr, const LonTraj& lbase, const LatTraj& dbase);

 private:
  const Settings& cfg_;
  const cost::CostSet& costs_;
  Workspace& ws_;
  const CycleClock& clock_;
  // Heap order of pending_: smallest bound first, then smallest index.
  struct ByBound {
    const Scorer* scorer;
    bool operator()(int a, int b) const {
      const double ba = scorer->bound_[a], bb = scorer->bound_[b];
      return bb < ba || (bb == ba && b < a);
    }
  };
  // Completes candidate c's bound (Bound) when Score() left it coarse.
  void Tighten(int c);
  // The exact cost of candidate c into ws.cand_cost[c].
  void Resolve(int c);
  // Evaluates the next expensive term of candidate c (exp_order_[stage_[c]]) of input `in` into
  // cheap_, and counts its weighted value in exp_sum_.
  void EvaluateNextExpensive(int c, const cost::CostInput& in);
  // Moves candidate c to rank ws.sorted of ws.order.
  void Emit(int c);

  std::vector<double> ref_s_, ref_sd_, ref_sdd_, ref_d_, ref_dd_, ref_ddd_;
  // Lazy sort: each candidate's lower bound, its index in ws.order, the candidates whose exact
  // cost is still unknown (a heap by bound, then index) and those known but not yet ranked (a
  // heap by cost, then index). Sized once (capacity of ws.order).
  std::vector<double> bound_;
  std::vector<int> pos_, pending_, ready_;
  std::vector<char> resolved_;  // per candidate: ws.cand_cost is exact
  std::vector<char> complete_;  // per candidate: bound_ is the cheap terms' (not the coarse one)
  // Per candidate, the cheap terms' values computed for its bound ([c * terms + t]; the
  // Sampled() ones once it is complete; the expensive ones' LowerBound then, their values as
  // Advance evaluates them): Resolve() evaluates only the expensive ones still missing.
  std::vector<double> cheap_;
  // Advance: per candidate, how many of the expensive terms (in exp_order_) are in cheap_; the
  // order, and the weighted values of each term evaluated this cycle (exp_sum_, by term index),
  // which order the next cycle's. Off (empty order: Resolve evaluates them all at once) when
  // there are more than stage_ counts.
  std::vector<std::uint8_t> stage_;
  std::vector<int> exp_order_;
  std::vector<double> exp_sum_;
  cost::CostSet::LaneMemo lane_memo_;  // Score()'s lane-only terms, per target lane
  std::vector<std::uint64_t> ref_near_lat_, ref_near_lon_;
};

}  // namespace frenetic::plan::search

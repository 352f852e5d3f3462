// Scoring of the search planner's candidates: the broad-phase masks of the cost terms, the
// CostInput of a candidate (or of any trajectory, sampled like the bundles), the weighted cost
// of every candidate in generation order, and the lazy sort into cost order (ties by index).
#pragma once

#include <cstdint>
#include <vector>

#include "frenetic/cost/cost_set.h"
#include "frenetic/cost/cost_term.h"
#include "frenetic/traj/frenet.h"
#include "plan/search_settings.h"
#include "plan/search_workspace.h"

namespace frenetic::plan::search {

// Broad phase of the cost terms (cost::CostInput::near_lat, near_lon): which of the context's
// cars are within each reach of d[k] (near[0..n) and near[n..2n)), and of s[k]; n = n_samples.
inline void NearLat(const Workspace& ws, const double* d, std::uint64_t* near) {
  cost::FillNearMasks(
      d, ws.n_samples, ws.ctx.num_cars, cost::kNearLateral,
      [&ws](int c, int k) { return ws.car_d[c * ws.n_samples + k]; }, near);
}
inline void NearLon(const Workspace& ws, const double* s, std::uint64_t* near) {
  cost::FillNearMasks(
      s, ws.n_samples, ws.ctx.num_cars, cost::kNearLongitudinal,
      [&ws](int c, int k) { return ws.car_s[c * ws.n_samples + k]; }, near);
}
// Points a cost input at a trajectory's masks (each 2 * n_samples words, as Near* fill them).
inline void SetNear(const Workspace& ws, cost::CostInput& in, const std::uint64_t* lat,
                    const std::uint64_t* lon) {
  in.near_lat[0] = lat;
  in.near_lat[1] = lat + ws.n_samples;
  in.near_lon[0] = lon;
  in.near_lon[1] = lon + ws.n_samples;
}

// Cost order, ties by index: a strict total order on candidates.
inline bool Cheaper(const Workspace& ws, int a, int b) {
  return ws.cand_cost[a] < ws.cand_cost[b] || (ws.cand_cost[a] == ws.cand_cost[b] && a < b);
}

class Scorer {
 public:
  // `costs`, `ws` and `clock` must outlive the scorer.
  Scorer(const Settings& cfg, const cost::CostSet& costs, Workspace& ws, const CycleClock& clock);

  // Scores every candidate into ws.cand_cost (a non-finite cost counts as 1e300) and sets
  // ws.order to the candidates, unsorted. False when the deadline (half of budget_ms) stopped
  // it early: the candidates scored so far, in generation order, are the cycle's candidates then.
  bool Score();
  // Sorts ws.order lazily: ranks up to `rank` are in cost order afterwards.
  void SortUpTo(int rank);

  // The cost input of bundle pair (lon i, lat j), reading the bundles' samples and masks.
  cost::CostInput InputFor(int i, int j) const;
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
  std::vector<double> ref_s_, ref_sd_, ref_sdd_, ref_d_, ref_dd_, ref_ddd_;
  std::vector<std::uint64_t> ref_near_lat_, ref_near_lon_;
};

}  // namespace frenetic::plan::search

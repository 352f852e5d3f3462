#include "plan/search_scoring.h"

#include <algorithm>

namespace frenetic::plan::search {
namespace {

// Share of budget_ms after which scoring stops (the rest of the budget is for the checks).
constexpr double kScoreShare = 0.5;

}  // namespace

Scorer::Scorer(const Settings& cfg, const cost::CostSet& costs, Workspace& ws,
               const CycleClock& clock)
    : cfg_(cfg), costs_(costs), ws_(ws), clock_(clock) {
  ref_near_lat_.assign(2 * ws_.n_samples, 0);
  ref_near_lon_.assign(2 * ws_.n_samples, 0);
  for (auto* v : {&ref_s_, &ref_sd_, &ref_sdd_, &ref_d_, &ref_dd_, &ref_ddd_}) {
    v->assign(ws_.n_samples, 0.0);
  }
}

cost::CostInput Scorer::InputFor(int i, int j) const {
  cost::CostInput in;
  const int oi = i * ws_.n_samples, oj = j * ws_.n_samples;
  in.s = ws_.lon_s.data() + oi;
  in.s_d = ws_.lon_sd.data() + oi;
  in.s_dd = ws_.lon_sdd.data() + oi;
  in.d = ws_.lat_d.data() + oj;
  in.d_d = ws_.lat_dd.data() + oj;
  in.d_dd = ws_.lat_ddd.data() + oj;
  in.lon_duration = ws_.lon[i].traj.duration;
  in.lat_duration = ws_.lat[j].traj.duration;
  in.lon_jerk_squared = ws_.lon[i].jerk2;
  in.lat_jerk_squared = ws_.lat[j].jerk2;
  in.end_speed = ws_.lon[i].traj.poly.V(ws_.lon[i].traj.duration);
  in.end_d = ws_.lat_d[oj + ws_.n_samples - 1];
  in.target_lane = ws_.lat[j].lane;
  in.kind = ws_.lon[i].kind;
  SetNear(ws_, in, ws_.lat_near.data() + 2 * oj, ws_.lon_near.data() + 2 * oi);
  return in;
}

bool Scorer::Score() {
  const int n = static_cast<int>(ws_.cand_lon.size());
  ws_.cand_cost.resize(n);
  ws_.order.resize(n);
  ws_.sorted = 0;
  for (int c = 0; c < n; ++c) {
    if ((c & 63) == 63 && clock_.Elapsed() > kScoreShare * cfg_.budget_ms) {
      ws_.order.resize(c);
      return false;
    }
    const double v = costs_.Evaluate(ws_.ctx, InputFor(ws_.cand_lon[c], ws_.cand_lat[c]));
    ws_.cand_cost[c] = Finite(v) ? v : 1e300;
    ws_.order[c] = c;
  }
  return true;
}

// The lazy check mostly looks at the first few candidates, so a full sort would be wasted;
// each call at least doubles the sorted prefix.
void Scorer::SortUpTo(int rank) {
  const int n = static_cast<int>(ws_.order.size());
  if (rank < ws_.sorted || ws_.sorted >= n) return;
  const int upto = std::min(n, std::max(rank + 1, 2 * ws_.sorted + 32));
  const Workspace& ws = ws_;
  std::partial_sort(ws_.order.begin() + ws_.sorted, ws_.order.begin() + upto, ws_.order.end(),
                    [&ws](int a, int b) { return Cheaper(ws, a, b); });
  ws_.sorted = upto;
}

cost::CostInput Scorer::SampleForCost(const traj::FrenetTrajectory& tr, const LonTraj& lbase,
                                      const LatTraj& dbase) {
  for (int k = 0; k < ws_.n_samples; ++k) {
    const traj::FrenetState st = tr.At(k * cfg_.score_dt);
    ref_s_[k] = st.s;
    ref_sd_[k] = st.s_d;
    ref_sdd_[k] = st.s_dd;
    ref_d_[k] = st.d;
    ref_dd_[k] = st.d_d;
    ref_ddd_[k] = st.d_dd;
  }
  cost::CostInput in;
  in.s = ref_s_.data();
  in.s_d = ref_sd_.data();
  in.s_dd = ref_sdd_.data();
  in.d = ref_d_.data();
  in.d_d = ref_dd_.data();
  in.d_dd = ref_ddd_.data();
  in.lon_duration = tr.lon.duration;
  in.lat_duration = tr.lat.duration;
  in.lon_jerk_squared = tr.lon.poly.JerkSquaredIntegral(tr.lon.duration);
  in.lat_jerk_squared = tr.lat.poly.JerkSquaredIntegral(tr.lat.duration);
  in.end_speed = tr.lon.poly.V(tr.lon.duration);
  in.end_d = ref_d_[ws_.n_samples - 1];
  in.target_lane = dbase.lane;
  in.kind = lbase.kind;
  NearLat(ws_, ref_d_.data(), ref_near_lat_.data());
  NearLon(ws_, ref_s_.data(), ref_near_lon_.data());
  SetNear(ws_, in, ref_near_lat_.data(), ref_near_lon_.data());
  return in;
}

double Scorer::CostOf(const traj::FrenetTrajectory& tr, const LonTraj& lbase,
                      const LatTraj& dbase) {
  const double v = costs_.Evaluate(ws_.ctx, SampleForCost(tr, lbase, dbase));
  return Finite(v) ? v : 1e300;
}

}  // namespace frenetic::plan::search

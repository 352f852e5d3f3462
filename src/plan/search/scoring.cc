#include "plan/search/scoring.h"

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
  const std::size_t cap = ws_.order.capacity();
  bound_.reserve(cap);
  pos_.reserve(cap);
  pending_.reserve(cap);
  ready_.reserve(cap);
  resolved_.assign(cap, 1);
  complete_.assign(cap, 1);
  cheap_.assign(cap * costs_.size(), 0.0);
  stage_.assign(cap, 0);
  exp_order_ = costs_.expensive_terms();
  exp_sum_.assign(costs_.size(), 0.0);
  if (exp_order_.size() > 255) {
    exp_order_.clear();
  }
}

cost::CostInput Scorer::InputFor(int i, int j) {
  if (!ws_.lon_near_have[i]) {
    NearLon(ws_, ws_.lon_s.data() + i * ws_.n_samples, ws_.lon_near.data() + 2 * i * ws_.n_samples);
    ws_.lon_near_have[i] = 1;
  }
  cost::CostInput in = BoundInputFor(i, j);
  SetNear(ws_, in, ws_.lat_near.data() + 2 * j * ws_.n_samples,
          ws_.lon_near.data() + 2 * i * ws_.n_samples);
  return in;
}

cost::CostInput Scorer::BoundInputFor(int i, int j) const {
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
  return in;
}

bool Scorer::Score() {
  const int n = static_cast<int>(ws_.cand_lon.size());
  ws_.cand_cost.resize(n);
  ws_.order.resize(n);
  bound_.resize(n);
  pos_.resize(n);
  if (resolved_.size() < static_cast<std::size_t>(n)) resolved_.resize(n);
  if (complete_.size() < static_cast<std::size_t>(n)) complete_.resize(n);
  if (cheap_.size() < static_cast<std::size_t>(n) * costs_.size()) {
    cheap_.resize(static_cast<std::size_t>(n) * costs_.size());
  }
  std::fill(resolved_.begin(), resolved_.begin() + n, 0);
  std::fill(complete_.begin(), complete_.begin() + n, 0);
  if (stage_.size() < static_cast<std::size_t>(n)) stage_.resize(n);
  std::fill(stage_.begin(), stage_.begin() + n, 0);
  // The expensive term that added most last cycle first (an insertion sort: stable, ties keep
  // their order, and no allocation, which std::stable_sort may make).
  for (std::size_t i = 1; i < exp_order_.size(); ++i) {
    const int t = exp_order_[i];
    std::size_t j = i;
    for (; j > 0 && exp_sum_[exp_order_[j - 1]] < exp_sum_[t]; --j)
      exp_order_[j] = exp_order_[j - 1];
    exp_order_[j] = t;
  }
  std::fill(exp_sum_.begin(), exp_sum_.end(), 0.0);
  ws_.sorted = 0;
  pending_.clear();
  ready_.clear();
  lane_memo_.Clear();  // a new context
  int scored = n;
  for (int c = 0; c < n; ++c) {
    if ((c & 63) == 63 && clock_.Elapsed() > kScoreShare * cfg_.budget_ms) {
      scored = c;
      break;
    }
    // Resolve() makes the cost 1e300 when it is not finite: never below this bound.
    const double b =
        costs_.CoarseLowerBound(ws_.ctx, BoundInputFor(ws_.cand_lon[c], ws_.cand_lat[c]),
                                &cheap_[static_cast<std::size_t>(c) * costs_.size()], &lane_memo_);
    bound_[c] = Finite(b) ? std::min(b, 1e300) : 1e300;
    ws_.order[c] = c;
    pos_[c] = c;
    pending_.push_back(c);
  }
  ws_.order.resize(scored);
  std::make_heap(pending_.begin(), pending_.end(), ByBound{this});
  return scored == n;
}

double Scorer::ExactCost(int c) {
  if (c < static_cast<int>(resolved_.size())) Resolve(c);
  return ws_.cand_cost[c];
}

void Scorer::TakeCostsAsExact() {
  const int n = static_cast<int>(ws_.cand_cost.size());
  bound_.assign(ws_.cand_cost.begin(), ws_.cand_cost.end());
  std::fill(resolved_.begin(), resolved_.begin() + std::min<int>(n, resolved_.size()), 1);
  std::fill(complete_.begin(), complete_.begin() + std::min<int>(n, complete_.size()), 1);
}

void Scorer::Tighten(int c) {
  if (complete_[c]) return;
  complete_[c] = 1;
  const double b =
      costs_.CompleteLowerBound(ws_.ctx, BoundInputFor(ws_.cand_lon[c], ws_.cand_lat[c]),
                                &cheap_[static_cast<std::size_t>(c) * costs_.size()]);
  bound_[c] = Finite(b) ? std::min(b, 1e300) : 1e300;
}

void Scorer::Resolve(int c) {
  if (resolved_[c]) return;
  resolved_[c] = 1;
  Tighten(c);
  double* values = &cheap_[static_cast<std::size_t>(c) * costs_.size()];
  const cost::CostInput in = InputFor(ws_.cand_lon[c], ws_.cand_lat[c]);
  if (exp_order_.empty()) {
    const double v = costs_.EvaluateWithCheap(ws_.ctx, in, values);
    ws_.cand_cost[c] = Finite(v) ? v : 1e300;
    return;
  }
  // The expensive terms Advance has not evaluated yet, then EvaluateWithCheap's sum.
  while (stage_[c] < static_cast<int>(exp_order_.size())) EvaluateNextExpensive(c, in);
  const double v = costs_.SumOf(values);
  ws_.cand_cost[c] = Finite(v) ? v : 1e300;
}

void Scorer::EvaluateNextExpensive(int c, const cost::CostInput& in) {
  const int t = exp_order_[stage_[c]++];
  double& value = cheap_[static_cast<std::size_t>(c) * costs_.size() + t];
  value = costs_.term(t).Evaluate(ws_.ctx, in);
  exp_sum_[t] += costs_.weight(t) * value;
}

double Scorer::Advance(int c) {
  if (resolved_[c]) return ws_.cand_cost[c];
  Tighten(c);
  const int e = static_cast<int>(exp_order_.size());
  if (stage_[c] + 1 >= e) {  // the last one (or none left to stage): exact
    Resolve(c);
    return ws_.cand_cost[c];
  }
  EvaluateNextExpensive(c, InputFor(ws_.cand_lon[c], ws_.cand_lat[c]));
  // The terms not evaluated yet count with their lower bounds (Tighten put them in cheap_).
  const double b = costs_.SumOf(&cheap_[static_cast<std::size_t>(c) * costs_.size()]);
  // Not finite: the exact cost is 1e300 (a term is NaN or infinite); never above it.
  return Finite(b) ? std::min(b, 1e300) : (Resolve(c), ws_.cand_cost[c]);
}

void Scorer::Emit(int c) {
  const int r = ws_.sorted++;
  const int other = ws_.order[r];
  std::swap(ws_.order[r], ws_.order[pos_[c]]);
  pos_[other] = pos_[c];
  pos_[c] = r;
}

// The lazy check mostly looks at the first few candidates, so a full sort would be wasted.
// While some costs are unknown: the best known cost is final once it ranks before the smallest
// bound of the unknown ones (an exact cost is never below its bound, and ties break by index
// either way); else the candidate with that bound is costed. A coarse bound there is completed
// first and the candidate queued again: the candidates costed, and the order they are costed
// and ranked in, are those of complete bounds throughout (a coarse bound is never above its
// complete one, so the smallest complete bound comes up before any larger one). Once every cost
// is known, a partial sort, each call at least doubling the sorted prefix.
bool Scorer::SortUpTo(int rank) {
  const int n = static_cast<int>(ws_.order.size());
  if (rank < ws_.sorted || ws_.sorted >= n) return true;
  const Workspace& ws = ws_;
  const auto cheaper = [&ws](int a, int b) { return Cheaper(ws, b, a); };  // min-heap
  for (int resolved = 0; !pending_.empty() && ws_.sorted <= rank;) {
    const int p = pending_.front();
    if (!ready_.empty()) {
      const int r = ready_.front();
      const double cr = ws_.cand_cost[r], bp = bound_[p];
      if (cr < bp || (cr == bp && r < p)) {
        std::pop_heap(ready_.begin(), ready_.end(), cheaper);
        ready_.pop_back();
        Emit(r);
        continue;
      }
    }
    if (!complete_[p]) {
      Tighten(p);
      SiftDownTop(pending_.begin(), pending_.end(), ByBound{this});
      continue;
    }
    if ((++resolved & 63) == 0 && clock_.ChecksOver(cfg_.budget_ms)) return false;
    std::pop_heap(pending_.begin(), pending_.end(), ByBound{this});
    pending_.pop_back();
    Resolve(p);
    ready_.push_back(p);
    std::push_heap(ready_.begin(), ready_.end(), cheaper);
  }
  if (!pending_.empty()) return true;
  ready_.clear();  // every cost known: the unranked ones are ws.order[sorted, n)
  if (rank < ws_.sorted || ws_.sorted >= n) return true;
  const int upto = std::min(n, std::max(rank + 1, 2 * ws_.sorted + 32));
  std::partial_sort(ws_.order.begin() + ws_.sorted, ws_.order.begin() + upto, ws_.order.end(),
                    [&ws](int a, int b) { return Cheaper(ws, a, b); });
  ws_.sorted = upto;
  return true;
}

bool Scorer::ResolveAll() {
  for (int k = 0; !pending_.empty(); ++k) {
    if ((k & 63) == 63 && clock_.ChecksOver(cfg_.budget_ms)) return false;
    std::pop_heap(pending_.begin(), pending_.end(), ByBound{this});
    const int p = pending_.back();
    pending_.pop_back();
    Resolve(p);
    ready_.push_back(p);
    std::push_heap(ready_.begin(), ready_.end(),
                   [this](int a, int b) { return Cheaper(ws_, b, a); });
  }
  ready_.clear();
  return true;
}

cost::CostInput Scorer::SampleForCost(const traj::FrenetTrajectory& tr, const LonTraj& lbase,
                                      const LatTraj& dbase) {
  for (int k = 0; k < ws_.n_samples; ++k) {
    const traj::FrenetState st = tr.At(k * cfg_.score.dt);
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
  in.lat_jerk_squared = tr.lat.JerkSquared();
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

#include "plan/search/tracer.h"

#include <utility>

#include "frenetic/traj/frenet.h"

namespace frenetic::plan::search {

Tracer::Tracer(const Settings& cfg, const Workspace& ws, Scorer& scorer, const cost::CostSet& costs,
               const map::ReferenceLine& line, const Predictor& predictor)
    : cfg_(cfg), ws_(ws), scorer_(scorer), costs_(costs), line_(line), predictor_(predictor) {
  per_term_.assign(costs_.size(), 0.0);
}

void Tracer::Add(int rank, bool winner, int reject, int car, double t) {
  if (full()) return;
  const int c = ws_.order[rank];
  CandidateTrace ct;
  ct.lane = ws_.lat[ws_.cand_lat[c]].lane;
  const LonTraj& lt = ws_.lon[ws_.cand_lon[c]];
  ct.end_speed = lt.traj.poly.V(lt.traj.duration);
  ct.duration = lt.traj.duration;
  ct.total_cost = ws_.cand_cost[c];
  ct.checked = winner || reject >= 0;
  ct.winner = winner;
  ct.reject = reject;
  if (car >= 0) {
    ct.reject_car = predictor_.cars()[ws_.car_index[car]].id;
    ct.reject_time = t;
  }
  const traj::FrenetTrajectory tr = ws_.Candidate(c);
  for (double tt = 0; tt <= cfg_.score.horizon + 1e-9; tt += 0.25) {
    const traj::FrenetState st = tr.At(tt);
    const map::CartesianPose p = line_.ToCartesian(st.s, st.d);
    ct.x.push_back(p.x);
    ct.y.push_back(p.y);
  }
  costs_.Evaluate(ws_.ctx, scorer_.InputFor(ws_.cand_lon[c], ws_.cand_lat[c]), per_term_.data());
  for (int i = 0; i < costs_.size(); ++i) {
    ct.costs.push_back({costs_.name(i), costs_.weight(i), per_term_[i]});
  }
  trace_->candidates.push_back(std::move(ct));
}

}  // namespace frenetic::plan::search

#include "plan/search/continuity.h"

#include <algorithm>
#include <cmath>

namespace frenetic::plan::search {
namespace {

// m: cars closer than this (map frame) decide whether the last plan may be reused. Farther cars
// cannot reach the ego's path within the few ticks a reused plan covers before the next search.
constexpr double kRelevantRange = 120.0;

}  // namespace

Continuity::Continuity(const Settings& cfg, const map::ReferenceLine& line, Workspace& ws,
                       const CycleClock& clock)
    : cfg_(cfg), line_(line), ws_(ws), clock_(clock) {
  for (auto* v :
       {&plan_s_, &plan_sd_, &plan_sdd_, &plan_d_, &plan_dd_, &plan_ddd_, &plan_x_, &plan_y_}) {
    v->assign(cfg_.continuity.output_points + 1, 0.0);
  }
  hist_x_.assign(kHistory, 0.0);
  hist_y_.assign(kHistory, 0.0);
}

void Continuity::Reset() {
  have_plan_ = false;
  plan_n_ = 0;
  plan_start_index_ = 0;
  hist_n_ = 0;
  ticks_since_search_ = 0;
  can_reuse_ = false;
  snap_n_ = 0;
}

Continuity::Sync Continuity::Synchronise(const Telemetry& t, bool prev_ok, bool ego_ok) const {
  Sync r;
  const int n_prev = prev_ok ? static_cast<int>(t.previous_path_x.size()) : -1;
  if (have_plan_ && n_prev > 0 && n_prev <= plan_n_) {
    r.consumed = plan_n_ - n_prev;
    const double tol = cfg_.continuity.resync_tolerance;
    r.synced = std::abs(t.previous_path_x[0] - plan_x_[r.consumed]) < tol &&
               std::abs(t.previous_path_y[0] - plan_y_[r.consumed]) < tol &&
               std::abs(t.previous_path_x[n_prev - 1] - plan_x_[plan_n_ - 1]) < tol &&
               std::abs(t.previous_path_y[n_prev - 1] - plan_y_[plan_n_ - 1]) < tol;
  }
  if (!r.synced && !ego_ok && have_plan_ && plan_n_ > cfg_.continuity.keep_points + 1) {
    // Unusable telemetry: carry on along our own plan as if one tick passed.
    r.consumed = 1;
    r.synced = true;
  }
  return r;
}

// Remembers the traffic the last full search saw, in the map frame (no Frenet conversion:
// this runs every cycle and must stay O(cars)).
void Continuity::Snapshot(const Telemetry& t) {
  snap_n_ = 0;
  snap_ego_x_ = t.x;
  snap_ego_y_ = t.y;
  for (const SensorCar& c : t.sensor_fusion) {
    if (snap_n_ == kMaxSnap) break;
    snap_[snap_n_++] = {c.id, c.x, c.y, c.vx, c.vy};
  }
}

// Whether a car is near enough to the ego to matter for the next few ticks' decision.
bool Continuity::Relevant(double x, double y, double ego_x, double ego_y) const {
  const double dx = x - ego_x, dy = y - ego_y;
  return dx * dx + dy * dy < kRelevantRange * kRelevantRange;
}

// The previous plan can be re-sent minus the consumed points when fewer than
// replan_min_ticks points were driven since the last full search (the real simulator
// consumes ~3 points per message, lockstep only 1: searching every tick would re-decide the
// same thing 15,000 times a lap) and nothing changed materially: no relevant car appeared or
// vanished, and every relevant car is where constant velocity put it (position error plus
// one second of velocity error below replan_deviation). Any doubt replans.
bool Continuity::CanReuse(const Telemetry& t, int consumed) const {
  if (!can_reuse_ || cfg_.continuity.replan_min_ticks <= 1) return false;
  const int ticks = ticks_since_search_ + consumed;
  if (ticks >= cfg_.continuity.replan_min_ticks) return false;
  if (plan_n_ - consumed < std::max(kMinPathPoints, cfg_.continuity.keep_points + 1)) return false;
  const double dt = ticks * kTickSeconds;
  for (const SensorCar& c : t.sensor_fusion) {
    if (!Finite(c.x) || !Finite(c.y) || !Finite(c.vx) || !Finite(c.vy)) return false;
    const bool relevant_now = Relevant(c.x, c.y, t.x, t.y);
    const SnapCar* old = nullptr;
    for (int i = 0; i < snap_n_ && old == nullptr; ++i) {
      if (snap_[i].id == c.id) old = &snap_[i];
    }
    if (old == nullptr) {
      if (relevant_now) return false;  // a new car nearby
      continue;
    }
    if (!relevant_now && !Relevant(old->x, old->y, snap_ego_x_, snap_ego_y_)) continue;
    const double ex = c.x - (old->x + old->vx * dt), ey = c.y - (old->y + old->vy * dt);
    const double evx = c.vx - old->vx, evy = c.vy - old->vy;
    const double error = std::hypot(ex, ey) + std::hypot(evx, evy) * 1.0;
    if (!(error < cfg_.continuity.replan_deviation)) return false;
  }
  // A relevant car of the snapshot that is no longer reported vanished.
  for (int i = 0; i < snap_n_; ++i) {
    bool present = false;
    for (const SensorCar& c : t.sensor_fusion) present = present || c.id == snap_[i].id;
    if (!present && Relevant(snap_[i].x, snap_[i].y, snap_ego_x_, snap_ego_y_)) return false;
  }
  return true;
}

void Continuity::ReusePlan(int consumed, PlanResult& result) {
  PlanSummary& sum = result.summary;
  PushHistory(consumed);
  const int n = plan_n_ - consumed;
  for (auto* v :
       {&plan_s_, &plan_sd_, &plan_sdd_, &plan_d_, &plan_dd_, &plan_ddd_, &plan_x_, &plan_y_}) {
    std::copy(v->begin() + consumed, v->begin() + plan_n_, v->begin());
  }
  plan_n_ = n;
  // The stored trajectory's start moved `consumed` points closer to the front; the next
  // search's elapsed time (consistency, lane-change timer) is measured from it.
  plan_start_index_ -= consumed;
  ticks_since_search_ += consumed;
  for (int k = 0; k < n; ++k) {
    result.x.push_back(plan_x_[k]);
    result.y.push_back(plan_y_[k]);
  }
  // No search ran: the candidate counters stay 0 (that is how a reused cycle shows in the
  // summary) and the winner fields describe the last search's winner.
  sum.points_kept = n;
  sum.winner_lane = reuse_lane_;
  sum.winner_end_speed = reuse_end_speed_;
  sum.winner_duration = reuse_duration_;
  sum.ms_total = clock_.Elapsed();
}

void Continuity::PushHistory(int consumed) {
  // Keep the last kHistory driven points, oldest first.
  for (int i = 0; i < consumed; ++i) {
    straddle_ticks_ = Straddles(cfg_, line_, plan_s_[i], plan_s_[i], plan_d_[i], plan_d_[i])
                          ? straddle_ticks_ + 1
                          : 0;
    if (hist_n_ == kHistory) {
      std::copy(hist_x_.begin() + 1, hist_x_.end(), hist_x_.begin());
      std::copy(hist_y_.begin() + 1, hist_y_.end(), hist_y_.begin());
      --hist_n_;
    }
    hist_x_[hist_n_] = plan_x_[i];
    hist_y_[hist_n_] = plan_y_[i];
    ++hist_n_;
  }
}

traj::FrenetState Continuity::KeepPoints(int consumed, int kept, double* elapsed) {
  // The driven points feed the jerk windows of the XY check.
  PushHistory(consumed);
  // Move the kept points to the front (destination before source: a forward copy is safe).
  for (auto* v :
       {&plan_s_, &plan_sd_, &plan_sdd_, &plan_d_, &plan_dd_, &plan_ddd_, &plan_x_, &plan_y_}) {
    std::copy(v->begin() + consumed, v->begin() + consumed + kept, v->begin());
  }
  const int k = kept - 1;
  const traj::FrenetState start{plan_s_[k], plan_sd_[k], plan_sdd_[k],
                                plan_d_[k], plan_dd_[k], plan_ddd_[k]};
  int straddle = straddle_ticks_;
  for (int i = 0; i < kept; ++i) {
    straddle =
        Straddles(cfg_, line_, plan_s_[i], plan_s_[i], plan_d_[i], plan_d_[i]) ? straddle + 1 : 0;
  }
  ws_.straddle_at_start = straddle;
  *elapsed = (consumed + kept - plan_start_index_ - 1) * kTickSeconds;
  return start;
}

void Continuity::Desync() {
  hist_n_ = 0;
  straddle_ticks_ = 0;
  ws_.straddle_at_start = 0;
}

void Continuity::Rebase(traj::FrenetState& start, int kept) {
  // Whole loops only: the reference line wraps s for free.
  const double L = line_.length();
  const double shift = std::floor(start.s / L) * L;
  start.s -= shift;
  for (int i = 0; i < kept; ++i) plan_s_[i] -= shift;
  ws_.prev_traj.lon.poly.c[0] -= shift;
}

void Continuity::SetXyPrefix(LimitChecker& limits) const {
  limits.SetXyPrefix(hist_x_.data(), hist_y_.data(), hist_n_, plan_x_.data(), plan_y_.data(),
                     ws_.kept);
}

void Continuity::Store(PlanResult& result) {
  const int kept = ws_.kept;
  const int new_points = cfg_.continuity.output_points - kept;
  for (int i = 1; i <= new_points; ++i) {
    const int k = kept + i - 1;
    plan_s_[k] = ws_.tk_s[i];
    plan_sd_[k] = ws_.tk_sd[i];
    plan_sdd_[k] = ws_.tk_sdd[i];
    plan_d_[k] = ws_.tk_d[i];
    plan_dd_[k] = ws_.tk_dd[i];
    plan_ddd_[k] = ws_.tk_ddd[i];
    const map::CartesianPose p = line_.ToCartesian(ws_.tk_s[i], ws_.tk_d[i]);
    plan_x_[k] = p.x;
    plan_y_[k] = p.y;
  }
  plan_n_ = cfg_.continuity.output_points;
  plan_start_index_ = kept > 0 ? kept - 1 : -1;
  // Last resort against NaN from anywhere: repeat the last finite point.
  double lx = 0, ly = 0;
  bool have = false;
  for (int k = 0; k < plan_n_; ++k) {
    if (Finite(plan_x_[k]) && Finite(plan_y_[k])) {
      lx = plan_x_[k];
      ly = plan_y_[k];
      have = true;
    }
  }
  for (int k = 0; k < plan_n_; ++k) {
    if (!Finite(plan_x_[k]) || !Finite(plan_y_[k])) {
      plan_x_[k] = have ? lx : 0.0;
      plan_y_[k] = have ? ly : 0.0;
    }
    result.x.push_back(plan_x_[k]);
    result.y.push_back(plan_y_[k]);
  }
  have_plan_ = true;
}

void Continuity::SearchDone(const Telemetry& t, bool can_reuse) {
  can_reuse_ = can_reuse;
  ticks_since_search_ = 0;
  Snapshot(t);
}

traj::FrenetState Continuity::MeasuredStart(const Telemetry& t, bool ego_ok) const {
  traj::FrenetState start;
  if (ego_ok) {
    const double hint = have_plan_ ? plan_s_[0] : t.s;
    const map::FrenetPoint f = line_.ToFrenet(t.x, t.y, hint);
    const map::RefSample c = line_.At(f.s);
    const double rel = t.yaw - c.heading;
    const double v = std::max(t.speed, 0.0);
    // The measured speed is the XY one: on a path at offset d the XY speed is
    // s' (1 + kappa d) (d to the right, kappa positive to the left), so on a bend's outer
    // lane s' is below it. Taking s' as the XY speed started every candidate there a few
    // percent too fast, over the speed limit near it (a previous path not ours, on a bend).
    const double stretch = 1.0 + c.kappa * f.d;
    const double along = std::isfinite(stretch) && stretch > 0.5 ? 1.0 / stretch : 1.0;
    start = {f.s, v * std::cos(rel) * along, 0.0, f.d, -v * std::sin(rel), 0.0};
  } else {
    start = {0.0, 0.0, 0.0, ws_.lane_center[std::min(1, cfg_.road.num_lanes - 1)], 0.0, 0.0};
  }
  if (!start.IsFinite()) start = {0.0, 0.0, 0.0, ws_.lane_center[0], 0.0, 0.0};
  // s' and d' from the measured heading can be off on the very first tick; the lattice
  // starts from rest in d' to avoid sweeping across the road.
  start.d_d = std::clamp(start.d_d, -2.0, 2.0);
  start.s_d = std::clamp(start.s_d, 0.0, cfg_.limits.max_speed);
  return start;
}

}  // namespace frenetic::plan::search

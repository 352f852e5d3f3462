#include "plan/search_strategy.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "plan/search_context.h"
#include "plan/search_workspace.h"

namespace frenetic::plan::search {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint8_t kNoLane = 0xff;
// m between a car's front bumper and the rear of the car ahead in its lane that the rolled-out
// traffic keeps (the simulator's cars brake within 10-20 m of their leader, udacity-sim.md §8.3).
constexpr double kQueueGap = 15.0;
// m a car's body must reach into a neighbour lane to count in it (mid lane change).
constexpr double kLaneOverlap = 0.5;
// The ego's intelligent driver model: acceleration and comfortable deceleration (m/s^2), and
// the strongest braking a rollout uses (m/s^2).
constexpr double kIdmAccel = 4.0, kIdmDecel = 3.0, kMaxDecel = 6.0;
// s: the closing speed a gap ahead must absorb while the lane change is under way.
constexpr double kCloseTime = 1.5;
// m/s^2: a plan's second lane change starts only when it lets the ego accelerate this much
// more than staying (the incentive criterion of MOBIL, Kesting, Treiber, Helbing 2007).
constexpr double kIncentive = 0.2;
// s between a plan's two lane changes.
constexpr double kHoldBetween = 1.0;
// s: a plan whose first lane change starts later than this also counts for the candidates that
// stay in the lane meanwhile.
constexpr double kWaitMin = 1.0;
// Cars of the next lane a plan may drop back behind (centre from kDropBehind m behind the ego
// to kDropAhead ahead) or get ahead of (kSpeedBehind behind to kSpeedAhead ahead), m; the
// nearest strategy.gap_cars (at most kGapCars) of each.
constexpr double kDropBehind = 35.0, kDropAhead = 25.0, kSpeedBehind = 25.0, kSpeedAhead = 10.0;
constexpr int kGapCars = 2;
// The rolled-out traffic follows the predictor this long (s; its braking and lane changes),
// then drives at each car's cruising speed at least (a car braking now does not brake for 20 s),
// which forgets kCruiseDecay m/s per second.
constexpr double kTrustPrediction = 2.0, kCruiseDecay = 0.5;

}  // namespace

Strategy::Strategy(const Settings& cfg, const Predictor& predictor, Workspace& ws)
    : cfg_(cfg), predictor_(predictor), ws_(ws) {
  dt_ = cfg_.strategy_dt;
  steps_ = std::max(1, static_cast<int>(std::ceil(cfg_.strategy_horizon / dt_ - 1e-9)));
  const std::size_t rows = static_cast<std::size_t>(steps_ + 1);
  tr_s_.assign(rows * kMaxCars, 0.0);
  tr_v_.assign(rows * kMaxCars, 0.0);
  tr_lane_.assign(rows * kMaxCars, kNoLane);
  lane_list_.assign(rows * cost::kMaxLanes * kMaxCars, 0);
  lane_count_.assign(rows * cost::kMaxLanes, 0);
}

void Strategy::LanesOf(double d, double hw, int* primary, int* secondary) const {
  *primary = *secondary = -1;
  if (!std::isfinite(d)) return;
  double best = 0.75 * cfg_.lane_width;
  for (int l = 0; l < cfg_.num_lanes; ++l) {
    if (!ws_.lane_exists[l]) continue;
    const double off = std::abs(d - ws_.lane_center[l]);
    if (off < best) {
      best = off;
      *primary = l;
    }
  }
  if (*primary < 0) return;
  const int side = d > ws_.lane_center[*primary] ? 1 : -1;
  const int nb = *primary + side;
  if (nb < 0 || nb >= cfg_.num_lanes || !ws_.lane_exists[nb]) return;
  if (std::abs(d - ws_.lane_center[nb]) < 0.5 * cfg_.lane_width + hw - kLaneOverlap)
    *secondary = nb;
}

void Strategy::UpdateCruise(double elapsed) {
  const double forget = kCruiseDecay * std::max(elapsed, 0.0);
  int n = 0;
  for (const TrackedCar& car : predictor_.cars()) {
    if (car.ghost || n >= kMaxCars) continue;
    double v = car.v_s;
    for (int i = 0; i < num_cruise_; ++i) {
      if (cruise_[i].id == car.id) v = std::max(v, cruise_[i].v - forget);
    }
    cruise_next_[n++] = {car.id, std::isfinite(v) ? v : 0.0};
  }
  cruise_.swap(cruise_next_);
  num_cruise_ = n;
}

double Strategy::CruiseOf(int id) const {
  for (int i = 0; i < num_cruise_; ++i) {
    if (cruise_[i].id == id) return cruise_[i].v;
  }
  return 0.0;
}

void Strategy::RollOutTraffic() {
  const auto cars = predictor_.cars();
  num_cars_ = std::min(static_cast<int>(cars.size()), kMaxCars);
  const double s0 = ws_.start.s;
  int second[kMaxCars];
  double cruise[kMaxCars];
  for (int c = 0; c < num_cars_; ++c) cruise[c] = cars[c].recorded ? 0.0 : CruiseOf(cars[c].id);
  for (int k = 0; k <= steps_; ++k) {
    double* s = &tr_s_[static_cast<std::size_t>(k) * kMaxCars];
    double* v = &tr_v_[static_cast<std::size_t>(k) * kMaxCars];
    std::uint8_t* lane = &tr_lane_[static_cast<std::size_t>(k) * kMaxCars];
    const double t = ws_.t_keep + k * dt_;
    for (int c = 0; c < num_cars_; ++c) {
      const Predictor::Prediction p = predictor_.Predict(c, t);
      if (k == 0) {
        half_length_[c] = 0.5 * cars[c].length;
        half_width_[c] = 0.5 * cars[c].width;
        car_id_[c] = cars[c].id;
        s[c] = s0 + p.s;
      } else {
        // The predicted displacement over the step, from where the queue left the car.
        double step = p.s - disp_[c];
        if (k * dt_ > kTrustPrediction) step = std::max(step, cruise[c] * dt_);
        s[c] = s[c - kMaxCars] + step;
      }
      disp_[c] = p.s;
      v[c] = std::max(p.v, 0.0);
      int primary = -1;
      LanesOf(p.d, half_width_[c], &primary, &second[c]);
      lane[c] = primary < 0 ? kNoLane : static_cast<std::uint8_t>(primary);
      if (!std::isfinite(s[c])) lane[c] = kNoLane, second[c] = -1;
    }
    // Each lane's cars in s order (insertion sort: a dozen cars, mostly in order already).
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      std::int8_t* list =
          &lane_list_[(static_cast<std::size_t>(k) * cost::kMaxLanes + l) * kMaxCars];
      int count = 0;
      for (int c = 0; c < num_cars_; ++c) {
        if (lane[c] != l && second[c] != l) continue;
        int j = count++;
        while (j > 0 && s[list[j - 1]] > s[c]) {
          list[j] = list[j - 1];
          --j;
        }
        list[j] = static_cast<std::int8_t>(c);
      }
      lane_count_[k * cost::kMaxLanes + l] = count;
    }
    if (k == 0) continue;
    // Queues: from the front, every car stays kQueueGap behind the car ahead in its own lane
    // (a car moving in counts there; a ghost and the car it stands for are one car), never
    // moving backwards.
    const double* s_prev = s - kMaxCars;
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      const std::int8_t* list =
          &lane_list_[(static_cast<std::size_t>(k) * cost::kMaxLanes + l) * kMaxCars];
      const int count = lane_count_[k * cost::kMaxLanes + l];
      for (int j = count - 2; j >= 0; --j) {
        const int c = list[j];
        if (lane[c] != l) continue;
        int lead = -1;
        for (int i = j + 1; i < count && lead < 0; ++i) {
          if (car_id_[list[i]] != car_id_[c]) lead = list[i];
        }
        if (lead < 0) continue;
        const double limit = s[lead] - (half_length_[c] + half_length_[lead] + kQueueGap);
        if (s[c] > limit) {
          s[c] = std::max(limit, s_prev[c]);
          v[c] = std::min(v[c], std::max(v[lead], (s[c] - s_prev[c]) / dt_));
        }
      }
    }
    // The queues may have reordered a lane's cars a little.
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      std::int8_t* list =
          &lane_list_[(static_cast<std::size_t>(k) * cost::kMaxLanes + l) * kMaxCars];
      const int count = lane_count_[k * cost::kMaxLanes + l];
      for (int j = 1; j < count; ++j) {
        const std::int8_t c = list[j];
        int i = j;
        while (i > 0 && s[list[i - 1]] > s[c]) {
          list[i] = list[i - 1];
          --i;
        }
        list[i] = c;
      }
    }
  }
}

double Strategy::Idm(double v, double v0, double gap, double v_lead) const {
  const double free = 1.0 - std::pow(v / std::max(v0, 0.1), 4);
  double a = kIdmAccel * free;
  if (std::isfinite(gap)) {
    const double s_min = std::max(1.0, cfg_.follow_d0 - 0.5 * (cfg_.ego_length + cfg_.car_length));
    const double s_star =
        s_min + std::max(0.0, v * cfg_.follow_tau +
                                  v * (v - v_lead) / (2.0 * std::sqrt(kIdmAccel * kIdmDecel)));
    const double ratio = s_star / std::max(gap, 0.1);
    a -= kIdmAccel * ratio * ratio;
  }
  return std::clamp(a, -kMaxDecel, kIdmAccel);
}

int Strategy::LeaderAt(int k, int lane, double s) const {
  if (lane < 0) return -1;
  const std::int8_t* list =
      &lane_list_[(static_cast<std::size_t>(k) * cost::kMaxLanes + lane) * kMaxCars];
  const int count = lane_count_[k * cost::kMaxLanes + lane];
  const double* cs = &tr_s_[static_cast<std::size_t>(k) * kMaxCars];
  for (int j = 0; j < count; ++j) {
    if (cs[list[j]] > s) return list[j];
  }
  return -1;
}

bool Strategy::Accept(const Policy& p, bool first, int k, int lane, int from, double s,
                      double v) const {
  if (lane < 0 || lane >= cfg_.num_lanes || !ws_.lane_exists[lane]) return false;
  const std::int8_t* list =
      &lane_list_[(static_cast<std::size_t>(k) * cost::kMaxLanes + lane) * kMaxCars];
  const int count = lane_count_[k * cost::kMaxLanes + lane];
  const double* cs = &tr_s_[static_cast<std::size_t>(k) * kMaxCars];
  const double* cv = &tr_v_[static_cast<std::size_t>(k) * kMaxCars];
  const double ego_hl = 0.5 * cfg_.ego_length;
  int front = -1, rear = -1;
  for (int j = 0; j < count; ++j) {
    const int c = list[j];
    const double bumpers = std::abs(cs[c] - s) - (ego_hl + half_length_[c]);
    if (bumpers < 0.5) return false;  // alongside
    if (cs[c] > s) {
      if (front < 0) front = c;
    } else {
      rear = c;
    }
  }
  double gap_front = kInf, v_front = 0;
  if (front >= 0) {
    gap_front = cs[front] - s - (ego_hl + half_length_[front]);
    v_front = cv[front];
    const double need =
        cfg_.margin_s + cfg_.headway_min * v + kCloseTime * std::max(0.0, v - v_front);
    if (gap_front < need) return false;
  }
  if (rear >= 0) {
    const double gap = s - cs[rear] - (ego_hl + half_length_[rear]);
    if (gap < cfg_.margin_behind + cfg_.behind_time * std::max(0.0, cv[rear] - v)) return false;
  }
  if (first && p.mode == StrategyPlan::Mode::kDropBack) return front == p.car;
  if (first && p.mode == StrategyPlan::Mode::kSpeedUp) return rear == p.car;
  if (first) return true;
  // A later change only when it pays: the new lane's leader lets the ego speed up more.
  const double a_new = Idm(v, ws_.ctx.lane_speed_limit[lane], gap_front, v_front);
  const int lead = LeaderAt(k, from, s);
  const double gap_old = lead < 0 ? kInf : cs[lead] - s - (ego_hl + half_length_[lead]);
  const double a_old = Idm(v, ws_.ctx.lane_speed_limit[from], gap_old, lead < 0 ? 0 : cv[lead]);
  return a_new > a_old + kIncentive;
}

void Strategy::Simulate(const Policy& p, Outcome* out) const {
  *out = Outcome();
  const double ego_hl = 0.5 * cfg_.ego_length;
  double s = ws_.start.s, v = std::max(ws_.start.s_d, 0.0);
  int lane = current_lane_, from = -1, next = 0;
  double change_end = 0, t_last = -kInf;
  // Mid lane change: the rest of it, behind the leaders of both lanes.
  const int at = LaneOf(cfg_, ws_, ws_.start.d);
  const double off = std::abs(ws_.start.d - ws_.lane_center[lane]);
  if (at != lane && off > 0.25 * cfg_.lane_width) {
    from = at;
    change_end = cfg_.strategy_change_time * std::min(1.0, off / cfg_.lane_width);
  }
  double s_horizon = kInf;  // s at the scoring horizon
  double xy_progress = 0, xy_end = 1;
  for (int k = 0; k < steps_; ++k) {
    const double t = k * dt_;
    if (t <= cfg_.score_horizon + 1e-9) s_horizon = s;
    if (from >= 0 && t >= change_end - 1e-9) from = -1;
    if (from < 0 && next < p.count && (next == 0 || t - t_last >= kHoldBetween - 1e-9) &&
        Accept(p, next == 0, k, p.lanes[next], lane, s, v)) {
      out->t_change[next] = t;
      if (next == 0) out->s_ref = s;
      from = lane;
      lane = p.lanes[next];
      change_end = t + cfg_.strategy_change_time;
      t_last = t;
      ++next;
    }
    const double* cs = &tr_s_[static_cast<std::size_t>(k) * kMaxCars];
    const double* cv = &tr_v_[static_cast<std::size_t>(k) * kMaxCars];
    const double v0 = ws_.ctx.lane_speed_limit[lane];
    // The leaders: the lane's, the old lane's for the first half of a change, and the car to
    // drop back behind until the change.
    int leads[3] = {LeaderAt(k, lane, s), -1, -1};
    if (from >= 0 && t < change_end - 0.5 * cfg_.strategy_change_time)
      leads[1] = LeaderAt(k, from, s);
    if (p.mode == StrategyPlan::Mode::kDropBack && next == 0 && p.car >= 0) leads[2] = p.car;
    double a = Idm(v, v0, kInf, 0);
    for (const int c : leads) {
      if (c < 0) continue;
      a = std::min(a, Idm(v, v0, cs[c] - s - (ego_hl + half_length_[c]), cv[c]));
    }
    double v_new = std::max(0.0, v + a * dt_);
    double s_new = s + 0.5 * (v + v_new) * dt_;
    // Progress as the XY distance it stands for: at a lane's limit the ego drives at the speed
    // cap in XY whatever the lane (an inner lane of a bend has less s to cover, not more time).
    const double xy = cfg_.max_speed / std::max(v0, 0.1);
    // Never through a leader of the lanes it is in (the car to drop back behind is in another).
    const double* ns = &tr_s_[static_cast<std::size_t>(k + 1) * kMaxCars];
    const double* nv = &tr_v_[static_cast<std::size_t>(k + 1) * kMaxCars];
    for (int i = 0; i < 2; ++i) {
      const int c = leads[i];
      if (c < 0) continue;
      const double limit = ns[c] - (ego_hl + half_length_[c]) - 1.0;
      if (s_new > limit) {
        s_new = std::max(s, limit);
        v_new = std::min(v_new, nv[c]);
      }
    }
    xy_progress += (s_new - s) * xy;
    s = s_new;
    v = v_new;
    xy_end = xy;
  }
  out->changes = next;
  out->progress = xy_progress;
  out->value =
      xy_progress + cfg_.strategy_terminal_time * v * xy_end - cfg_.strategy_change_cost * next;
  if (!std::isfinite(s_horizon)) s_horizon = s;
  if (next == 0) {
    out->s_ref = s_horizon;
    out->t_ref = std::min(cfg_.score_horizon, steps_ * dt_);
  } else {
    out->t_ref = std::min(out->t_change[0], cfg_.score_horizon);
    if (out->t_change[0] > cfg_.score_horizon) out->s_ref = s_horizon;
  }
}

void Strategy::Emit(const Policy& p, const Outcome& o, double regret) {
  auto add = [&](int lane, double t, double lo, double hi) {
    if (scratch_count_ >= static_cast<int>(scratch_.size())) return;
    cost::StrategyOption& opt = scratch_[scratch_count_++];
    opt.lane = lane;
    opt.regret = regret;
    opt.t = t;
    opt.s_lo = lo;
    opt.s_hi = hi;
  };
  if (o.changes == 0) {
    add(current_lane_, 0.0, -kInf, kInf);
    return;
  }
  double lo = -kInf, hi = kInf;
  if (p.mode == StrategyPlan::Mode::kDropBack) hi = o.s_ref + cfg_.strategy_window;
  if (p.mode == StrategyPlan::Mode::kSpeedUp) lo = o.s_ref - cfg_.strategy_window;
  add(p.lanes[0], o.t_ref, lo, hi);
  if (o.t_change[0] >= kWaitMin) add(current_lane_, o.t_ref, lo, hi);
  if (o.changes == 2 && p.lanes[1] != current_lane_) add(p.lanes[1], o.t_ref, lo, hi);
}

void Strategy::Decide(double elapsed, StrategySummary* summary) {
  cost::StrategyGoal& goal = ws_.strategy_goal;
  goal.num_options = 0;
  summary->num_plans = 0;
  summary->chosen = -1;
  ws_.ctx.strategy = nullptr;
  if (!cfg_.strategy) return;
  UpdateCruise(elapsed);
  const int committed = ws_.prev_target_lane;
  current_lane_ = committed >= 0 && committed < cfg_.num_lanes && ws_.lane_exists[committed]
                      ? committed
                      : ws_.ctx.current_lane;
  RollOutTraffic();

  // The plans: stay; for each neighbour lane, there, on to the lane beyond, or there and back;
  // each first change as soon as a gap opens, behind a car of that lane or ahead of one.
  int np = 0;
  policies_[np++] = Policy();
  const int c = current_lane_;
  const double* cs = tr_s_.data();
  for (const int dir : {-1, 1}) {
    const int n = c + dir;
    if (n < 0 || n >= cfg_.num_lanes || !ws_.lane_exists[n]) continue;
    const int beyond = n + dir;
    const bool has_beyond = beyond >= 0 && beyond < cfg_.num_lanes && ws_.lane_exists[beyond];
    // The next lane's cars near the ego at the start, nearest first.
    int drop[kGapCars], speed[kGapCars];
    int n_drop = 0, n_speed = 0;
    const std::int8_t* list = &lane_list_[static_cast<std::size_t>(n) * kMaxCars];
    const int count = lane_count_[n];
    for (int pass = 0; pass < 2; ++pass) {
      const double lo = pass == 0 ? -kDropBehind : -kSpeedBehind;
      const double hi = pass == 0 ? kDropAhead : kSpeedAhead;
      int* out = pass == 0 ? drop : speed;
      int& m = pass == 0 ? n_drop : n_speed;
      for (int taken = 0; taken < std::min(cfg_.strategy_gap_cars, kGapCars); ++taken) {
        int best = -1;
        for (int j = 0; j < count; ++j) {
          const int car = list[j];
          const double ds = cs[car] - ws_.start.s;
          if (ds < lo || ds > hi) continue;
          bool used = false;
          for (int i = 0; i < m; ++i) used = used || out[i] == car;
          if (used) continue;
          if (best < 0 || std::abs(ds) < std::abs(cs[best] - ws_.start.s)) best = car;
        }
        if (best < 0) break;
        out[m++] = best;
      }
    }
    const int seqs[3][2] = {{n, -1}, {n, has_beyond ? beyond : -1}, {n, c}};
    for (int q = 0; q < 3; ++q) {
      if (q == 1 && !has_beyond) continue;
      Policy base;
      base.lanes = {seqs[q][0], seqs[q][1]};
      base.count = seqs[q][1] < 0 ? 1 : 2;
      for (int m = 0; m < 1 + n_drop + n_speed && np < kMaxPolicies; ++m) {
        Policy pol = base;
        if (m > 0 && m <= n_drop) {
          pol.mode = StrategyPlan::Mode::kDropBack;
          pol.car = drop[m - 1];
        } else if (m > n_drop) {
          pol.mode = StrategyPlan::Mode::kSpeedUp;
          pol.car = speed[m - 1 - n_drop];
        }
        policies_[np++] = pol;
      }
    }
  }

  // Roll each out; the best value wins (ties: the first). A plan for the lane the last
  // decision aimed at gets strategy.hold, and as much again when it also reaches its gap the
  // same way (behind or ahead of the same car): a plan is followed through, not redecided on
  // every swing of the traffic.
  int best = 0;
  for (int i = 0; i < np; ++i) {
    Simulate(policies_[i], &outcomes_[i]);
    const Policy& p = policies_[i];
    const int final_lane = outcomes_[i].changes > 0 ? p.lanes[outcomes_[i].changes - 1] : c;
    if (final_lane == last_final_lane_) {
      outcomes_[i].value += cfg_.strategy_hold;
      if (p.mode == last_mode_ && p.mode != StrategyPlan::Mode::kKeep &&
          car_id_[p.car] == last_car_) {
        outcomes_[i].value += cfg_.strategy_hold;
      }
    }
    if (outcomes_[i].value > outcomes_[best].value) best = i;
  }
  const double top = outcomes_[best].value;
  // One-sided (strategy.one_sided): no plan is charged more than keeping the lane (policy 0),
  // so the layer can only pull the ego out of a lane that will be slow, never hold it back
  // from a change the lattice finds worth it (the rollouts' queues see few gaps in dense
  // traffic, where every change then looked a loss).
  const double ceiling = cfg_.strategy_one_sided ? top - outcomes_[0].value : kInf;
  scratch_count_ = 0;
  for (int i = 0; i < np; ++i) {
    Emit(policies_[i], outcomes_[i], std::min(top - outcomes_[i].value, ceiling));
  }
  // The options, least regret first; one is kept only when no option for the same lane
  // without a window has as little regret (that one serves every candidate as well).
  // (A stable insertion sort: std::stable_sort takes a heap buffer, and the cycle must not
  // allocate; there are at most 3 * kMaxPolicies options.)
  for (int i = 1; i < scratch_count_; ++i) {
    const cost::StrategyOption o = scratch_[i];
    int j = i;
    while (j > 0 && scratch_[j - 1].regret > o.regret) {
      scratch_[j] = scratch_[j - 1];
      --j;
    }
    scratch_[j] = o;
  }
  bool open[cost::kMaxLanes] = {};
  for (int i = 0; i < scratch_count_ && goal.num_options < cost::kMaxStrategyOptions; ++i) {
    const cost::StrategyOption& o = scratch_[i];
    if (o.lane < 0 || o.lane >= cost::kMaxLanes || open[o.lane]) continue;
    if (!std::isfinite(o.s_lo) && !std::isfinite(o.s_hi)) open[o.lane] = true;
    goal.options[goal.num_options++] = o;
  }
  ws_.ctx.strategy = &goal;
  const Policy& chosen = policies_[best];
  last_final_lane_ = outcomes_[best].changes > 0 ? chosen.lanes[outcomes_[best].changes - 1] : c;
  last_mode_ = chosen.mode;
  last_car_ = chosen.car >= 0 ? car_id_[chosen.car] : -1;

  // The summary: the best plan of each lane sequence, in the order first weighed.
  for (int i = 0; i < np; ++i) {
    const Policy& p = policies_[i];
    int slot = -1;
    for (int j = 0; j < summary->num_plans && slot < 0; ++j) {
      const StrategyPlan& e = summary->plans[j];
      const int e_count = e.lanes[1] >= 0 ? 2 : (e.lanes[0] >= 0 ? 1 : 0);
      if (e_count == p.count && e.lanes[0] == p.lanes[0] && e.lanes[1] == p.lanes[1]) slot = j;
    }
    if (slot < 0) {
      if (summary->num_plans >= StrategySummary::kMaxPlans) continue;
      slot = summary->num_plans++;
    } else if (!(i == best || outcomes_[i].value > summary->plans[slot].value) ||
               summary->chosen == slot) {
      continue;
    }
    StrategyPlan& e = summary->plans[slot];
    e.lanes = {p.count > 0 ? p.lanes[0] : -1, p.count > 1 ? p.lanes[1] : -1};
    e.mode = p.mode;
    e.car = p.car >= 0 ? car_id_[p.car] : -1;
    e.t_change = outcomes_[i].t_change[0];
    e.progress = outcomes_[i].progress;
    e.value = outcomes_[i].value;
    if (i == best) summary->chosen = slot;
  }
}

}  // namespace frenetic::plan::search

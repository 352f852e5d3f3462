// The `search` planner. Werling, Ziegler, Kammel, Thrun, "Optimal Trajectory Generation for
// Dynamic Street Scenarios in a Frenet Frame", ICRA 2010: 1-D longitudinal and lateral bundles,
// every pair scored, lazy hard checks in cost order, a backup that always exists.
#include "plan/search_planner.h"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>

#include "frenetic/plan/feasibility.h"
#include "frenetic/plan/predictor.h"
#include "frenetic/traj/box.h"
#include "frenetic/traj/frenet.h"

namespace frenetic::plan {
namespace {

using Clock = std::chrono::steady_clock;
using traj::FrenetState;
using traj::FrenetTrajectory;
using traj::Polynomial5;
using traj::Trajectory1d;

constexpr double kMphToMps = 0.44704;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kHistory = 110;  // driven points kept for the jerk windows (> 2 s of blocks)
// m: cars closer than this (map frame) decide whether the last plan may be reused. Farther cars
// cannot reach the ego's path within the few ticks a reused plan covers before the next search.
constexpr double kRelevantRange = 120.0;
constexpr int kMaxCars = 64;
// Share of budget_ms after which scoring stops (the rest of the budget is for the checks).
constexpr double kScoreShare = 0.5;
// m: a car behind within this lateral offset is following the ego (the simulator's traffic sees
// a leader within 2 m and brakes for it).
constexpr double kFollowerLateral = 1.0;
// m along s: a car in another lane this close is alongside (a lane change must yield to it).
constexpr double kAlongside = 20.0;
// The simulator times a car whose d is within 0.8 m of a lane line and flags it after 150 ticks
// (udacity-sim.md §7.4). Lane centres keep a little more room; the hard check allows a little
// less time.
constexpr double kStraddle = 0.8;       // m
constexpr double kLaneLineBand = 0.9;   // m
constexpr int kMaxStraddleTicks = 135;  // ticks

double SteadyMs() {
  return std::chrono::duration<double, std::milli>(Clock::now().time_since_epoch()).count();
}

bool Finite(double v) { return std::isfinite(v); }

// One longitudinal trajectory of the bundle.
struct LonTraj {
  Trajectory1d traj;
  cost::LonKind kind = cost::LonKind::kVelocityKeeping;
  int lane = -1;  // -1: usable in every lane; else only with this lane's lateral moves
  // End speed (velocity keeping), extra gap (following), distance (stop), deceleration (braking).
  double param = 0;
  int lead = -1;  // following: the leader's index in the predictor's cars of this cycle
  double jerk2 = 0;
};

struct LatTraj {
  Trajectory1d traj;
  int lane = 0;
  double offset = 0;
  double jerk2 = 0;
};

struct Settings {
  double max_speed, max_accel, max_jerk, d_min, d_max;
  double lane_width, outer_inset;
  int num_lanes;
  int keep_points, output_points;
  double resync_tolerance;
  int replan_min_ticks;
  double replan_deviation;
  int speeds, durations;
  double min_duration, max_duration;
  int follow_gaps;
  double follow_d0, follow_tau, follow_tau_step;
  bool stop;
  int brake_decels, brake_targets;
  double brake_min_decel, brake_max_decel;
  int lat_durations;
  double lat_min_duration, lat_max_duration;
  int lat_offsets;
  double lat_offset_step;
  int lat_delays;
  double lat_delay_step;
  double score_dt, score_horizon;
  double check_horizon, collision_dt, car_length, car_width, margin_s, margin_d, margin_behind;
  double headway_min, behind_time;
  bool refine;
  int refine_iterations;
  double refine_budget_ms;
  double fallback_decel, fallback_jerk, fallback_lat_duration;
  double budget_ms;

  explicit Settings(const PlannerConfig& c) {
    max_speed = c.value("limits.max_speed_mph") * kMphToMps;
    max_accel = c.value("limits.max_accel");
    max_jerk = c.value("limits.max_jerk");
    d_min = c.value("limits.d_min");
    d_max = c.value("limits.d_max");
    lane_width = c.value("road.lane_width");
    outer_inset = c.value("road.outer_lane_inset");
    num_lanes = std::clamp(c.int_value("road.num_lanes"), 1, cost::kMaxLanes);
    keep_points = c.int_value("continuity.keep_points");
    output_points = c.int_value("continuity.output_points");
    resync_tolerance = c.value("continuity.resync_tolerance");
    replan_min_ticks = c.int_value("continuity.replan_min_ticks");
    replan_deviation = c.value("continuity.replan_deviation");
    speeds = c.int_value("grid.speeds");
    durations = c.int_value("grid.durations");
    min_duration = c.value("grid.min_duration");
    max_duration = c.value("grid.max_duration");
    follow_gaps = c.int_value("grid.follow_gaps");
    follow_d0 = c.value("grid.follow_d0");
    follow_tau = c.value("grid.follow_tau");
    follow_tau_step = c.value("grid.follow_tau_step");
    stop = c.int_value("grid.stop") != 0;
    brake_decels = c.int_value("grid.brake_decels");
    brake_targets = c.int_value("grid.brake_targets");
    brake_min_decel = c.value("grid.brake_min_decel");
    brake_max_decel = c.value("grid.brake_max_decel");
    lat_durations = c.int_value("grid.lat_durations");
    lat_min_duration = c.value("grid.lat_min_duration");
    lat_max_duration = c.value("grid.lat_max_duration");
    lat_offsets = c.int_value("grid.lat_offsets");
    lat_offset_step = c.value("grid.lat_offset_step");
    lat_delays = c.int_value("grid.lat_delays");
    lat_delay_step = c.value("grid.lat_delay_step");
    score_dt = c.value("score.dt");
    score_horizon = c.value("score.horizon");
    check_horizon = c.value("check.horizon");
    collision_dt = c.value("check.collision_dt");
    car_length = c.value("check.car_length");
    car_width = c.value("check.car_width");
    margin_s = c.value("check.margin_s");
    margin_d = c.value("check.margin_d");
    margin_behind = c.value("check.margin_behind");
    headway_min = c.value("check.headway_min");
    behind_time = c.value("check.behind_time");
    refine = c.int_value("refine.enabled") != 0;
    refine_iterations = c.int_value("refine.max_iterations");
    // A pinned deadline never fires (PlannerConfig::PinDeadlines).
    refine_budget_ms = c.refine_budget_pinned() ? kInf : c.value("refine.budget_ms");
    fallback_decel = c.value("fallback.decel");
    fallback_jerk = c.value("fallback.jerk");
    fallback_lat_duration = c.value("fallback.lat_duration");
    budget_ms = c.budget_pinned() ? kInf : c.budget_ms();
  }
};

double Linspace(double lo, double hi, int count, int i) {
  return count <= 1 ? hi : lo + (hi - lo) * i / (count - 1);
}

class SearchPlanner : public Planner {
 public:
  SearchPlanner(const PlannerConfig& config, std::shared_ptr<const map::ReferenceLine> line,
                std::shared_ptr<const cost::CostSet> costs, PlannerClock clock)
      : clock_ms_(clock ? std::move(clock) : PlannerClock(SteadyMs)),
        cfg_(config),
        line_(std::move(line)),
        costs_(std::move(costs)),
        checker_(kHistory + 64 + static_cast<int>(std::ceil(cfg_.check_horizon / kTickSeconds)) +
                 cfg_.output_points) {
    PredictorOptions po;
    po.range = config.value("prediction.range");
    po.d_min = config.value("prediction.d_min");
    po.d_max = config.value("prediction.d_max");
    po.max_speed = config.value("prediction.max_speed");
    po.spike_ratio = config.value("prediction.spike_ratio");
    po.brake_threshold = config.value("prediction.brake_threshold");
    po.brake_horizon = config.value("prediction.brake_horizon");
    po.lateral_threshold = config.value("prediction.lateral_threshold");
    po.lane_width = cfg_.lane_width;
    po.num_lanes = cfg_.num_lanes;
    predictor_ = config.int_value("prediction.manoeuvres") != 0
                     ? MakeManoeuvrePredictor(line_, po)
                     : MakeConstantVelocityPredictor(line_, po);
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      lane_nominal_[l] = lane_center_[l] = (l + 0.5) * cfg_.lane_width;
    }
    if (cfg_.num_lanes > 1) {
      lane_nominal_[cfg_.num_lanes - 1] -= cfg_.outer_inset;
      lane_center_[cfg_.num_lanes - 1] -= cfg_.outer_inset;
    }

    n_samples_ = static_cast<int>(std::floor(cfg_.score_horizon / cfg_.score_dt + 1e-9)) + 1;
    n_ticks_ = static_cast<int>(std::ceil(cfg_.check_horizon / kTickSeconds));
    n_ticks_ = std::max(n_ticks_, cfg_.output_points);
    const int max_lon = cfg_.speeds * cfg_.durations + cfg_.durations +
                        2 * cfg_.num_lanes * cfg_.follow_gaps * cfg_.durations +
                        cfg_.brake_decels * cfg_.brake_targets + 8;
    const int max_lat =
        cfg_.num_lanes * (cfg_.lat_durations + 1 + cfg_.lat_delays) * cfg_.lat_offsets + 8;
    lon_.reserve(max_lon);
    lat_.reserve(max_lat);
    for (auto* v : {&lon_s_, &lon_sd_, &lon_sdd_}) v->assign(max_lon * n_samples_, 0.0);
    for (auto* v : {&lat_d_, &lat_dd_, &lat_ddd_}) v->assign(max_lat * n_samples_, 0.0);
    cand_lon_.reserve(max_lon * max_lat);
    cand_lat_.reserve(max_lon * max_lat);
    cand_cost_.reserve(max_lon * max_lat);
    order_.reserve(max_lon * max_lat);
    first_hit_.reserve(max_lon * max_lat);
    clearance_.reserve(max_lon * max_lat);
    for (auto* v : {&car_s_, &car_d_, &car_v_}) v->assign(kMaxCars * n_samples_, 0.0);
    car_index_.assign(kMaxCars, 0);
    car_s0_.assign(kMaxCars, 0.0);
    car_d0_.assign(kMaxCars, 0.0);
    collision_step_ = std::max(1, static_cast<int>(std::lround(cfg_.collision_dt / kTickSeconds)));
    n_steps_ = n_ticks_ / collision_step_;
    for (auto* v : {&step_s_, &step_d_, &step_v_, &step_vd_}) {
      v->assign(kMaxCars * (n_steps_ + 1), 0.0);
    }
    lat_near_.assign(2 * max_lat * n_samples_, 0);
    lon_near_.assign(2 * max_lon * n_samples_, 0);
    ref_near_lat_.assign(2 * n_samples_, 0);
    ref_near_lon_.assign(2 * n_samples_, 0);
    prev_s_.assign(n_samples_, 0.0);
    prev_d_.assign(n_samples_, 0.0);
    for (auto* v : {&ref_s_, &ref_sd_, &ref_sdd_, &ref_d_, &ref_dd_, &ref_ddd_}) {
      v->assign(n_samples_, 0.0);
    }
    for (auto* v : {&tk_s_, &tk_sd_, &tk_sdd_, &tk_d_, &tk_dd_, &tk_ddd_}) {
      v->assign(n_ticks_ + 1, 0.0);
    }
    const int path_cap = kHistory + cfg_.output_points + n_ticks_ + 8;
    chk_x_.assign(path_cap, 0.0);
    chk_y_.assign(path_cap, 0.0);
    for (auto* v :
         {&plan_s_, &plan_sd_, &plan_sdd_, &plan_d_, &plan_dd_, &plan_ddd_, &plan_x_, &plan_y_}) {
      v->assign(cfg_.output_points + 1, 0.0);
    }
    hist_x_.assign(kHistory, 0.0);
    hist_y_.assign(kHistory, 0.0);
    per_term_.assign(costs_->size(), 0.0);
    result_.x.reserve(cfg_.output_points + 1);
    result_.y.reserve(cfg_.output_points + 1);
    result_.summary.winner_costs.resize(costs_->size());
    for (int i = 0; i < costs_->size(); ++i) {
      result_.summary.winner_costs[i].name = costs_->name(i);
      result_.summary.winner_costs[i].weight = costs_->weight(i);
    }
    opt_ = nlopt_create(AlgorithmFromName(config.refine_algorithm()), 4);
    if (opt_ != nullptr) {
      nlopt_set_min_objective(opt_, &SearchPlanner::RefineObjective, this);
      constraints_ok_ = nlopt_add_inequality_constraint(opt_, &SearchPlanner::RefineConstraint,
                                                        this, 1e-6) == NLOPT_SUCCESS;
      nlopt_set_maxeval(opt_, cfg_.refine_iterations);
    }
    Reset();
  }

  ~SearchPlanner() override {
    if (opt_ != nullptr) nlopt_destroy(opt_);
  }

  std::string_view name() const override { return "search"; }

  void set_trace(CycleTrace* trace, int max_candidates) override {
    trace_ = trace;
    trace_max_ = max_candidates;
  }

  void Reset() override {
    have_plan_ = false;
    plan_n_ = 0;
    plan_start_index_ = 0;
    hist_n_ = 0;
    have_prev_traj_ = false;
    prev_target_lane_ = -1;
    lane_before_change_ = -1;
    time_since_change_ = 1e9;
    ticks_since_search_ = 0;
    can_reuse_ = false;
    snap_n_ = 0;
    clock_ = NAN;
    predictor_->Reset();
  }

  const PlanResult& Plan(const Telemetry& t) override {
    t0_ = clock_ms_();
    PlanSummary& sum = result_.summary;
    ResetSummary(sum);
    result_.status = PlanStatus::kOk;
    result_.x.clear();
    result_.y.clear();
    if (trace_ != nullptr) trace_->candidates.clear();

    const bool ego_ok = Finite(t.x) && Finite(t.y) && Finite(t.yaw) && Finite(t.speed) &&
                        std::abs(t.x) < 1e6 && std::abs(t.y) < 1e6 && t.speed > -1 && t.speed < 100;
    bool prev_ok = t.previous_path_x.size() == t.previous_path_y.size();
    for (size_t i = 0; prev_ok && i < t.previous_path_x.size(); ++i) {
      prev_ok = Finite(t.previous_path_x[i]) && Finite(t.previous_path_y[i]);
    }
    bool invalid = !ego_ok || !prev_ok;

    // Continuity: learn how many points were consumed and whether previous_path is ours.
    int consumed = 0;
    bool synced = false;
    const int n_prev = prev_ok ? static_cast<int>(t.previous_path_x.size()) : -1;
    if (have_plan_ && n_prev > 0 && n_prev <= plan_n_) {
      consumed = plan_n_ - n_prev;
      const double tol = cfg_.resync_tolerance;
      synced = std::abs(t.previous_path_x[0] - plan_x_[consumed]) < tol &&
               std::abs(t.previous_path_y[0] - plan_y_[consumed]) < tol &&
               std::abs(t.previous_path_x[n_prev - 1] - plan_x_[plan_n_ - 1]) < tol &&
               std::abs(t.previous_path_y[n_prev - 1] - plan_y_[plan_n_ - 1]) < tol;
    }
    if (!synced && !ego_ok && have_plan_ && plan_n_ > cfg_.keep_points + 1) {
      // Unusable telemetry: carry on along our own plan as if one tick passed.
      consumed = 1;
      synced = true;
    }
    // Simulated time of this message: it dates the traffic readings for the predictor's
    // acceleration estimates. Unknown after a resynchronisation.
    clock_ = synced ? (std::isnan(clock_) ? 0.0 : clock_) + consumed * kTickSeconds : NAN;
    if (synced && ego_ok && CanReuse(t, consumed)) {
      ReusePlan(consumed);
      return result_;
    }
    FrenetState start;
    int kept = 0;
    double elapsed = 0;  // s between the previous start state and this one
    if (synced) {
      kept = std::min(cfg_.keep_points, plan_n_ - consumed);
      // The driven points feed the jerk windows of the XY check.
      PushHistory(consumed);
      // Move the kept points to the front (destination before source: a forward copy is safe).
      for (auto* v :
           {&plan_s_, &plan_sd_, &plan_sdd_, &plan_d_, &plan_dd_, &plan_ddd_, &plan_x_, &plan_y_}) {
        std::copy(v->begin() + consumed, v->begin() + consumed + kept, v->begin());
      }
      const int k = kept - 1;
      start = {plan_s_[k], plan_sd_[k], plan_sdd_[k], plan_d_[k], plan_dd_[k], plan_ddd_[k]};
      straddle_at_start_ = straddle_ticks_;
      for (int i = 0; i < kept; ++i) {
        straddle_at_start_ =
            Straddles(plan_s_[i], plan_s_[i], plan_d_[i], plan_d_[i]) ? straddle_at_start_ + 1 : 0;
      }
      elapsed = (consumed + kept - plan_start_index_ - 1) * kTickSeconds;
    } else {
      hist_n_ = 0;
      straddle_ticks_ = straddle_at_start_ = 0;
      have_prev_traj_ = false;
      if (ego_ok) {
        const map::FrenetPoint f = line_->ToFrenet(t.x, t.y, have_plan_ ? plan_s_[0] : t.s);
        const double heading = line_->At(f.s).heading;
        const double rel = t.yaw - heading;
        const double v = std::max(t.speed, 0.0);
        start = {f.s, v * std::cos(rel), 0.0, f.d, -v * std::sin(rel), 0.0};
      } else {
        start = {0.0, 0.0, 0.0, lane_center_[std::min(1, cfg_.num_lanes - 1)], 0.0, 0.0};
      }
      if (!start.IsFinite()) start = {0.0, 0.0, 0.0, lane_center_[0], 0.0, 0.0};
      // s' and d' from the measured heading can be off on the very first tick; the lattice
      // starts from rest in d' to avoid sweeping across the road.
      start.d_d = std::clamp(start.d_d, -2.0, 2.0);
      start.s_d = std::clamp(start.s_d, 0.0, cfg_.max_speed);
      invalid = invalid || !ego_ok;
    }
    if (start.s >= line_->length() || start.s < 0) Rebase(start, kept);
    sum.points_kept = kept;
    kept_ = kept;
    start_ = start;
    t_keep_ = kept * kTickSeconds;
    time_since_change_ += elapsed;
    if (have_prev_traj_) prev_elapsed_ = prev_base_ + elapsed;

    // Prediction (relative to the start state's s; the observation is "now").
    predictor_->Observe(t.sensor_fusion, start.s, clock_);
    BuildContext();
    SetXyPrefix();
    sum.ms_prepare = Elapsed();

    bool found = false;       // a candidate passed every check
    bool least_harm = false;  // none did: the least harmful feasible one was taken instead
    bool over_budget = false;
    if (!invalid || synced) {
      GenerateBundles();
      sum.candidates_generated = static_cast<int>(cand_lon_.size());
      sum.ms_generate = Elapsed() - sum.ms_prepare;
      const double t_score = Elapsed();
      if (!Score()) {
        over_budget = true;
        sum.deadline_stage = PlanSummary::Stage::kScore;
      }
      sum.candidates_scored = static_cast<int>(order_.size());
      sum.ms_score = Elapsed() - t_score;
      const double t_check = Elapsed();
      bool check_cut = false;
      found = CheckLazily(&check_cut);
      if (!found && !check_cut) least_harm = LeastHarm(&check_cut);
      if (check_cut) {
        over_budget = true;
        sum.deadline_stage = PlanSummary::Stage::kCheck;
      }
      sum.ms_check = Elapsed() - t_check;
      if (found && cfg_.refine && opt_ != nullptr) {
        // A pinned (infinite) cycle budget always leaves room; a pinned refinement budget
        // asks for none beyond the cycle's.
        const double refine_ms = std::isfinite(cfg_.refine_budget_ms) ? cfg_.refine_budget_ms : 0;
        if (Elapsed() + refine_ms < 0.8 * cfg_.budget_ms) {
          const double t_ref = Elapsed();
          Refine();
          sum.ms_refine = Elapsed() - t_ref;
        } else if (sum.deadline_stage == PlanSummary::Stage::kNone) {
          // Not enough time left: the unrefined winner goes out, on time.
          sum.deadline_stage = PlanSummary::Stage::kRefine;
        }
      }
    }
    const double t_out = Elapsed();
    if (found || least_harm) {
      FillTicks(winner_);
      sum.winner_lane = lat_[winner_lat_].lane;
      sum.winner_end_speed = winner_.lon.At(winner_.lon.duration).v;
      sum.winner_duration = winner_.lon.duration;
      RecordDecision(sum.winner_lane);
      reuse_lane_ = sum.winner_lane;
      reuse_end_speed_ = sum.winner_end_speed;
      reuse_duration_ = sum.winner_duration;
      EvaluateWinnerCosts();
    } else if (over_budget && ContinuePrevious()) {
      // Cut short (a loaded machine): last cycle's winner, still collision-free, is a better
      // answer than braking, which invites the car behind into the ego's boot.
      sum.winner_lane = prev_target_lane_;
    } else {
      BuildFallback();
      have_prev_traj_ = false;
    }
    Output();
    // Only a clean search result may be re-sent without searching: a fallback, an invalid
    // input or a cut-short search replans at the next message.
    can_reuse_ = found && !invalid && !over_budget;
    ticks_since_search_ = 0;
    Snapshot(t);
    sum.ms_output = Elapsed() - t_out;
    sum.ms_total = Elapsed();
    if (invalid) {
      result_.status = PlanStatus::kInvalidInput;
    } else if (over_budget) {
      result_.status = PlanStatus::kOverBudget;
    } else if (!found) {
      result_.status = PlanStatus::kFallbackUsed;
    }
    return result_;
  }

 private:
  // ms since the start of the cycle.
  double Elapsed() const { return clock_ms_() - t0_; }

  static nlopt_algorithm AlgorithmFromName(const std::string& name) {
    const nlopt_algorithm a = nlopt_algorithm_from_string(name.c_str());
    return static_cast<int>(a) < 0 ? NLOPT_LN_COBYLA : a;
  }

  static void ResetSummary(PlanSummary& s) {
    s.candidates_generated = s.candidates_scored = s.candidates_checked = 0;
    s.candidates_feasible = 0;
    s.rejections.fill(0);
    for (auto& c : s.winner_costs) c.value = 0;
    s.winner_total_cost = 0;
    s.winner_lane = -1;
    s.winner_end_speed = s.winner_duration = 0;
    s.refine_iterations = 0;
    s.refine_cost_before = s.refine_cost_after = 0;
    s.points_kept = 0;
    s.deadline_stage = PlanSummary::Stage::kNone;
    s.ms_prepare = s.ms_generate = s.ms_score = s.ms_check = s.ms_refine = s.ms_output = 0;
    s.ms_total = 0;
  }

  // ---- Plan reuse ---------------------------------------------------------------------------

  // Remembers the traffic the last full search saw, in the map frame (no Frenet conversion:
  // this runs every cycle and must stay O(cars)).
  void Snapshot(const Telemetry& t) {
    snap_n_ = 0;
    snap_ego_x_ = t.x;
    snap_ego_y_ = t.y;
    for (const SensorCar& c : t.sensor_fusion) {
      if (snap_n_ == kMaxSnap) break;
      snap_[snap_n_++] = {c.id, c.x, c.y, c.vx, c.vy};
    }
  }

  // Whether a car is near enough to the ego to matter for the next few ticks' decision.
  bool Relevant(double x, double y, double ego_x, double ego_y) const {
    const double dx = x - ego_x, dy = y - ego_y;
    return dx * dx + dy * dy < kRelevantRange * kRelevantRange;
  }

  // The previous plan can be re-sent minus the consumed points when fewer than
  // replan_min_ticks points were driven since the last full search (the real simulator
  // consumes ~3 points per message, lockstep only 1: searching every tick would re-decide the
  // same thing 15,000 times a lap) and nothing changed materially: no relevant car appeared or
  // vanished, and every relevant car is where constant velocity put it (position error plus
  // one second of velocity error below replan_deviation). Any doubt replans.
  bool CanReuse(const Telemetry& t, int consumed) const {
    if (!can_reuse_ || cfg_.replan_min_ticks <= 1) return false;
    const int ticks = ticks_since_search_ + consumed;
    if (ticks >= cfg_.replan_min_ticks) return false;
    if (plan_n_ - consumed < std::max(kMinPathPoints, cfg_.keep_points + 1)) return false;
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
      if (!(error < cfg_.replan_deviation)) return false;
    }
    // A relevant car of the snapshot that is no longer reported vanished.
    for (int i = 0; i < snap_n_; ++i) {
      bool present = false;
      for (const SensorCar& c : t.sensor_fusion) present = present || c.id == snap_[i].id;
      if (!present && Relevant(snap_[i].x, snap_[i].y, snap_ego_x_, snap_ego_y_)) return false;
    }
    return true;
  }

  // Re-sends the stored plan minus the consumed points: O(path), no allocation, no search.
  void ReusePlan(int consumed) {
    PlanSummary& sum = result_.summary;
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
      result_.x.push_back(plan_x_[k]);
      result_.y.push_back(plan_y_[k]);
    }
    // No search ran: the candidate counters stay 0 (that is how a reused cycle shows in the
    // summary) and the winner fields describe the last search's winner.
    sum.points_kept = n;
    sum.winner_lane = reuse_lane_;
    sum.winner_end_speed = reuse_end_speed_;
    sum.winner_duration = reuse_duration_;
    sum.ms_total = Elapsed();
  }

  void PushHistory(int consumed) {
    // Keep the last kHistory driven points, oldest first.
    for (int i = 0; i < consumed; ++i) {
      straddle_ticks_ =
          Straddles(plan_s_[i], plan_s_[i], plan_d_[i], plan_d_[i]) ? straddle_ticks_ + 1 : 0;
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

  // Whether the simulator may read d within kStraddle of a lane line for a point with s in
  // [s0, s1] and d in [d0, d1] (it reads d from chords: ReferenceLine::ChordOffset).
  bool Straddles(double s0, double s1, double d0, double d1) const {
    const map::ReferenceLine::OffsetRange r = line_->ChordOffset(s0, s1, 0.5 * (d0 + d1));
    return StraddlesRead(d0 + r.lo, d1 + r.hi);
  }
  bool StraddlesRead(double lo, double hi) const {
    for (int l = 1; l < cfg_.num_lanes; ++l) {
      const double line = l * cfg_.lane_width;
      if (hi > line - kStraddle && lo < line + kStraddle) return true;
    }
    return false;
  }

  // Keeps s in [0, L): shifts everything stored by whole loops (wrap is free for the line).
  void Rebase(FrenetState& start, int kept) {
    const double L = line_->length();
    const double shift = std::floor(start.s / L) * L;
    start.s -= shift;
    for (int i = 0; i < kept; ++i) plan_s_[i] -= shift;
    prev_traj_.lon.poly.c[0] -= shift;
  }

  int LaneOf(double d) const {
    int best = 0;
    for (int l = 1; l < cfg_.num_lanes; ++l) {
      if (std::abs(d - lane_center_[l]) < std::abs(d - lane_center_[best])) best = l;
    }
    return best;
  }

  // The lanes' centres for this cycle: the nominal ones, moved just enough that the simulator,
  // which measures d from the chords between waypoints (up to ~1.3 m outward mid-segment on
  // left bends, udacity-sim.md §5.3 and §9.3), reads the ego inside its lane over the next
  // stretch: clear of the lane lines' +-0.8 m bands (the 3 s timer) and of the road edges.
  void LaneCentres() {
    const double ahead = std::max(start_.s_d, 10.0) * cfg_.score_horizon + 20.0;
    const int last = cfg_.num_lanes - 1;
    for (int l = 0; l <= last; ++l) {
      const map::ReferenceLine::OffsetRange r =
          line_->ChordOffset(start_.s - 10.0, start_.s + ahead, lane_nominal_[l]);
      const double lo_read = l == 0 ? cfg_.d_min : l * cfg_.lane_width + kLaneLineBand;
      const double hi_read = l == last ? cfg_.d_max : (l + 1) * cfg_.lane_width - kLaneLineBand;
      const double lo = lo_read - r.lo, hi = hi_read - r.hi;
      lane_center_[l] = lo <= hi ? std::clamp(lane_nominal_[l], lo, hi) : 0.5 * (lo + hi);
    }
  }

  void BuildContext() {
    cost::CostContext& c = ctx_;
    c.num_samples = n_samples_;
    c.dt = cfg_.score_dt;
    c.lane_width = cfg_.lane_width;
    c.num_lanes = cfg_.num_lanes;
    c.car_length = cfg_.car_length;
    c.car_width = cfg_.car_width;
    c.start_s = start_.s;
    c.start_d = start_.d;
    c.start_speed = start_.s_d;
    c.current_lane = LaneOf(start_.d);
    c.previous_target_lane = prev_target_lane_;
    c.time_since_lane_change = time_since_change_;
    c.lane_before_change = lane_before_change_;
    LaneCentres();
    // Lane speed limits: the XY speed of an offset curve is s' (1 + kappa d) with d to the right
    // and kappa positive to the left, so the outer lane of a left bend is faster in XY.
    const double reach = cfg_.max_speed * cfg_.score_horizon + 20;
    double kmax = 0, kmin = 0;
    for (double ds = -10; ds <= reach; ds += 2.0) {
      const double k = line_->At(start_.s + ds).kappa;
      if (Finite(k)) {
        kmax = std::max(kmax, k);
        kmin = std::min(kmin, k);
      }
    }
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      c.lane_center[l] = lane_center_[l];
      const double d = lane_center_[l];
      const double factor = std::max({1.0, 1.0 + kmax * d, 1.0 + kmin * d});
      // A little below the cap: lateral motion and the splice add a few cm/s in XY.
      c.lane_speed_limit[l] = cfg_.max_speed / factor - 0.05;
    }
    // Previous choice at this cycle's sample times.
    if (have_prev_traj_) {
      for (int k = 0; k < n_samples_; ++k) {
        const FrenetState p = prev_traj_.At(k * cfg_.score_dt + prev_elapsed_);
        prev_s_[k] = p.s;
        prev_d_[k] = p.d;
      }
      c.previous_s = prev_s_.data();
      c.previous_d = prev_d_.data();
    } else {
      c.previous_s = c.previous_d = nullptr;
    }
    // Traffic: relevant cars only. A car right behind the ego in its lane is its follower's
    // problem (the simulator's traffic brakes for the car ahead) — but only once the ego is
    // squarely in front of it: mid lane change the car may not have seen the ego yet.
    // Predictions are sampled once here: at the scoring samples and at the collision-check
    // steps, t_keep_ after the observation.
    const auto cars = predictor_->cars();
    int nc = 0;
    for (int i = 0; i < static_cast<int>(cars.size()) && nc < kMaxCars; ++i) {
      const TrackedCar& car = cars[i];
      if (car.s < -cfg_.car_length && std::abs(car.d - start_.d) < kFollowerLateral) continue;
      car_index_[nc] = i;
      const Predictor::Prediction at_start = predictor_->Predict(i, t_keep_);
      car_s0_[nc] = start_.s + at_start.s;  // at the start instant, in the start's s frame
      car_d0_[nc] = at_start.d;
      for (int k = 0; k < n_samples_; ++k) {
        const Predictor::Prediction p = predictor_->Predict(i, t_keep_ + k * cfg_.score_dt);
        car_s_[nc * n_samples_ + k] = start_.s + p.s;
        car_d_[nc * n_samples_ + k] = p.d;
        car_v_[nc * n_samples_ + k] = p.v;
      }
      const int row = nc * (n_steps_ + 1);
      for (int j = 1; j <= n_steps_; ++j) {
        const Predictor::Prediction p =
            predictor_->Predict(i, t_keep_ + j * collision_step_ * kTickSeconds);
        step_s_[row + j] = start_.s + p.s;
        step_d_[row + j] = p.d;
        step_v_[row + j] = p.v;
        step_vd_[row + j] = p.v_d;
      }
      ++nc;
    }
    c.num_cars = nc;
    c.max_car_speed = 0;
    for (int i = 0; i < nc * n_samples_; ++i)
      c.max_car_speed = std::max(c.max_car_speed, car_v_[i]);
    c.near_lateral[0] = cost::kNearLateral[0];
    c.near_lateral[1] = cost::kNearLateral[1];
    c.near_longitudinal[0] = cost::kNearLongitudinal[0];
    c.near_longitudinal[1] = cost::kNearLongitudinal[1];
    c.car_s = car_s_.data();
    c.car_d = car_d_.data();
    c.car_v = car_v_.data();
  }

  // ---- Generation ---------------------------------------------------------------------------

  void AddLon(const LonTraj& l) {
    if (!l.traj.poly.IsFinite()) return;
    const int i = static_cast<int>(lon_.size());
    lon_.push_back(l);
    lon_.back().jerk2 = l.traj.poly.JerkSquaredIntegral(l.traj.duration);
    for (int k = 0; k < n_samples_; ++k) {
      const traj::State1d st = l.traj.At(k * cfg_.score_dt);
      lon_s_[i * n_samples_ + k] = st.p;
      lon_sd_[i * n_samples_ + k] = st.v;
      lon_sdd_[i * n_samples_ + k] = st.a;
    }
    NearLon(lon_s_.data() + i * n_samples_, lon_near_.data() + 2 * i * n_samples_);
  }

  void AddLat(const LatTraj& l) {
    if (!l.traj.poly.IsFinite()) return;
    const int i = static_cast<int>(lat_.size());
    lat_.push_back(l);
    lat_.back().jerk2 = l.traj.poly.JerkSquaredIntegral(l.traj.duration);
    for (int k = 0; k < n_samples_; ++k) {
      const traj::State1d st = l.traj.At(k * cfg_.score_dt);
      lat_d_[i * n_samples_ + k] = st.p;
      lat_dd_[i * n_samples_ + k] = st.v;
      lat_ddd_[i * n_samples_ + k] = st.a;
    }
    NearLat(lat_d_.data() + i * n_samples_, lat_near_.data() + 2 * i * n_samples_);
  }

  // Broad phase of the cost terms (cost::CostInput::near_lat, near_lon): which cars are within
  // each reach of d[k] (near[0..n) and near[n..2n)), and of s[k].
  void NearLat(const double* d, std::uint64_t* near) const {
    cost::FillNearMasks(d, n_samples_, ctx_.num_cars, cost::kNearLateral,
                        [this](int c, int k) { return car_d_[c * n_samples_ + k]; }, near);
  }
  // Points a cost input at a trajectory's masks (each 2 * n_samples_ words, as Near* fill them).
  void SetNear(cost::CostInput& in, const std::uint64_t* lat, const std::uint64_t* lon) const {
    in.near_lat[0] = lat;
    in.near_lat[1] = lat + n_samples_;
    in.near_lon[0] = lon;
    in.near_lon[1] = lon + n_samples_;
  }
  void NearLon(const double* s, std::uint64_t* near) const {
    cost::FillNearMasks(s, n_samples_, ctx_.num_cars, cost::kNearLongitudinal,
                        [this](int c, int k) { return car_s_[c * n_samples_ + k]; }, near);
  }

  LonTraj MakeLon(cost::LonKind kind, int lane, double param, double T, int lead = -1) const {
    LonTraj l;
    l.kind = kind;
    l.lane = lane;
    l.param = param;
    l.lead = lead;
    l.traj.duration = T;
    const FrenetState& s0 = start_;
    switch (kind) {
      case cost::LonKind::kVelocityKeeping:
        l.traj.poly = traj::SolveQuartic(s0.s, s0.s_d, s0.s_dd, std::max(param, 0.0), 0.0, T);
        break;
      case cost::LonKind::kFollowing: {
        // Constant time-gap law on the leader's predicted state at T:
        // s_target = s_lead(T) - (D0 + tau v_lead(T)), minus `param` more.
        const Predictor::Prediction lead_at = predictor_->Predict(lead, t_keep_ + T);
        const double s_lead = start_.s + lead_at.s;
        const double target = s_lead - (cfg_.follow_d0 + cfg_.follow_tau * lead_at.v) - param;
        l.traj.poly = traj::SolveQuintic(s0.s, s0.s_d, s0.s_dd, target, lead_at.v, 0.0, T);
        break;
      }
      case cost::LonKind::kStopping:
        l.traj.poly =
            traj::SolveQuintic(s0.s, s0.s_d, s0.s_dd, s0.s + std::max(param, 0.0), 0.0, 0.0, T);
        break;
      case cost::LonKind::kBraking:
        // Decelerate at `param` at once for T, then hold the speed reached (the trajectory's
        // constant-velocity continuation): s0 + v0 t - param t^2 / 2.
        l.traj.poly = {};
        l.traj.poly.c[0] = s0.s;
        l.traj.poly.c[1] = s0.s_d;
        l.traj.poly.c[2] = -0.5 * param;
        break;
    }
    return l;
  }

  LatTraj MakeLat(int lane, double offset, double T, double delay = 0) const {
    LatTraj l;
    l.lane = lane;
    l.offset = offset;
    l.traj.duration = T;
    l.traj.delay = delay;
    const double target =
        std::clamp(lane_center_[lane] + offset, 0.0, cfg_.num_lanes * cfg_.lane_width);
    // A delayed move holds still first (only offered when the ego is nearly at rest laterally).
    l.traj.poly = delay > 0
                      ? traj::SolveQuintic(start_.d, 0.0, 0.0, target, 0.0, 0.0, T)
                      : traj::SolveQuintic(start_.d, start_.d_d, start_.d_dd, target, 0.0, 0.0, T);
    return l;
  }

  // The nearest car ahead in `lane` at the start instant (context index), or -1.
  int Leader(int lane) const {
    int best = -1;
    double best_s = 1e18;
    for (int c = 0; c < ctx_.num_cars; ++c) {
      if (std::abs(car_d0_[c] - lane_center_[lane]) > 0.6 * cfg_.lane_width) continue;
      if (car_s0_[c] <= start_.s) continue;
      if (car_s0_[c] < best_s) {
        best_s = car_s0_[c];
        best = c;
      }
    }
    return best;
  }

  // Constant-deceleration braking, each level to a few lower speeds (fractions of the current
  // one): the quick, strong braking a quintic cannot start with.
  void AddBraking() {
    const double v0 = std::max(start_.s_d, 0.0);
    if (v0 < 1.0) return;
    for (int bi = 0; bi < cfg_.brake_decels; ++bi) {
      const double a = Linspace(cfg_.brake_min_decel, cfg_.brake_max_decel, cfg_.brake_decels, bi);
      for (int ti = 0; ti < cfg_.brake_targets; ++ti) {
        // Target speeds from standstill up to (but not including) the current speed.
        const double target = v0 * ti / cfg_.brake_targets;
        AddLon(MakeLon(cost::LonKind::kBraking, -1, a, (v0 - target) / a));
      }
    }
  }

  // The car in `lane` nearest to the ego along s within kAlongside at the start instant (context
  // index), or -1: the one a lane change into that lane must pass behind or in front of.
  int Alongside(int lane) const {
    int best = -1;
    double best_ds = kAlongside;
    for (int c = 0; c < ctx_.num_cars; ++c) {
      if (std::abs(car_d0_[c] - lane_center_[lane]) > 0.6 * cfg_.lane_width) continue;
      const double ds = std::abs(car_s0_[c] - start_.s);
      if (ds < best_ds) {
        best_ds = ds;
        best = c;
      }
    }
    return best;
  }

  void GenerateBundles() {
    lon_.clear();
    lat_.clear();
    cand_lon_.clear();
    cand_lat_.clear();
    // Lanes within reach: the current one and its neighbours.
    bool reachable[cost::kMaxLanes] = {};
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      reachable[l] = std::abs(lane_center_[l] - start_.d) <= 2.5 * cfg_.lane_width;
    }
    for (int di = 0; di < cfg_.durations; ++di) {
      const double T = Linspace(cfg_.min_duration, cfg_.max_duration, cfg_.durations, di);
      for (int vi = 0; vi < cfg_.speeds; ++vi) {
        // Velocity keeping to end speeds from 0 to the fastest lane's limit.
        double vmax = 0;
        for (int l = 0; l < cfg_.num_lanes; ++l) vmax = std::max(vmax, ctx_.lane_speed_limit[l]);
        AddLon(MakeLon(cost::LonKind::kVelocityKeeping, -1, Linspace(0, vmax, cfg_.speeds, vi), T));
      }
      if (cfg_.stop) {
        AddLon(MakeLon(cost::LonKind::kStopping, -1, 0.5 * start_.s_d * T, T));
      }
      if (di == 0) AddBraking();
      for (int l = 0; l < cfg_.num_lanes; ++l) {
        if (!reachable[l]) continue;
        // Follow the lane's leader, and yield to (drop behind) the car alongside, which the
        // delayed lane changes below need to pass behind it (Apollo's yield samples).
        const int targets[2] = {Leader(l), Alongside(l)};
        for (int k = 0; k < 2; ++k) {
          const int lead = targets[k];
          if (lead < 0 || (k == 1 && lead == targets[0])) continue;
          for (int g = 0; g < cfg_.follow_gaps; ++g) {
            // Longer time gaps are extra distance on top of the base law.
            const double extra = g * cfg_.follow_tau_step * car_v_[lead * n_samples_];
            AddLon(MakeLon(cost::LonKind::kFollowing, l, extra, T, car_index_[lead]));
          }
        }
      }
    }
    // Laterally at rest (keeping a lane): one duration stands for all for the own lane (they
    // coincide), and lane changes may also wait before they start.
    const bool at_rest = std::abs(start_.d_d) < 0.2 && std::abs(start_.d_dd) < 0.5;
    for (int l = 0; l < cfg_.num_lanes; ++l) {
      if (!reachable[l]) continue;
      const bool own = std::abs(lane_center_[l] - start_.d) < 0.5 * cfg_.lane_width;
      const bool centred = own && at_rest && std::abs(lane_center_[l] - start_.d) < 0.1;
      for (int ti = 0; ti < (centred ? 1 : cfg_.lat_durations); ++ti) {
        const double T =
            Linspace(cfg_.lat_min_duration, cfg_.lat_max_duration, cfg_.lat_durations, ti);
        for (int oi = 0; oi < cfg_.lat_offsets; ++oi) {
          const double off = (oi - cfg_.lat_offsets / 2) * cfg_.lat_offset_step;
          AddLat(MakeLat(l, off, T));
        }
      }
      if (!own && at_rest) {
        const double T = Linspace(cfg_.lat_min_duration, cfg_.lat_max_duration, 3, 1);
        for (int k = 1; k <= cfg_.lat_delays; ++k)
          AddLat(MakeLat(l, 0.0, T, k * cfg_.lat_delay_step));
      }
      // The lateral move under way, to its planned end time: replanning with full durations
      // every cycle would stretch a lane change indefinitely (more time astride the line), and
      // a waiting one would never start.
      if (have_prev_traj_ && l == prev_lat_lane_) {
        const traj::Trajectory1d& prev = prev_traj_.lat;
        const double wait = prev.delay - prev_elapsed_;
        const double remaining = prev.end_time() - prev_elapsed_;
        if (wait > 0.05) {
          AddLat(MakeLat(l, prev_lat_offset_, prev.duration, wait));
        } else if (remaining > 0.3 && remaining < cfg_.lat_min_duration - 0.05) {
          AddLat(MakeLat(l, prev_lat_offset_, remaining));
        }
      }
    }
    for (int i = 0; i < static_cast<int>(lon_.size()); ++i) {
      for (int j = 0; j < static_cast<int>(lat_.size()); ++j) {
        if (lon_[i].lane >= 0 && lon_[i].lane != lat_[j].lane) continue;
        cand_lon_.push_back(i);
        cand_lat_.push_back(j);
      }
    }
  }

  // ---- Scoring ------------------------------------------------------------------------------

  cost::CostInput InputFor(int i, int j) const {
    cost::CostInput in;
    const int oi = i * n_samples_, oj = j * n_samples_;
    in.s = lon_s_.data() + oi;
    in.s_d = lon_sd_.data() + oi;
    in.s_dd = lon_sdd_.data() + oi;
    in.d = lat_d_.data() + oj;
    in.d_d = lat_dd_.data() + oj;
    in.d_dd = lat_ddd_.data() + oj;
    in.lon_duration = lon_[i].traj.duration;
    in.lat_duration = lat_[j].traj.duration;
    in.lon_jerk_squared = lon_[i].jerk2;
    in.lat_jerk_squared = lat_[j].jerk2;
    in.end_speed = lon_[i].traj.poly.V(lon_[i].traj.duration);
    in.end_d = lat_d_[oj + n_samples_ - 1];
    in.target_lane = lat_[j].lane;
    in.kind = lon_[i].kind;
    SetNear(in, lat_near_.data() + 2 * oj, lon_near_.data() + 2 * oi);
    return in;
  }

  // Scores every candidate; false when the deadline stopped it early (the candidates scored so
  // far, in generation order, are the cycle's candidates then).
  bool Score() {
    const int n = static_cast<int>(cand_lon_.size());
    cand_cost_.resize(n);
    order_.resize(n);
    sorted_ = 0;
    for (int c = 0; c < n; ++c) {
      if ((c & 63) == 63 && Elapsed() > kScoreShare * cfg_.budget_ms) {
        order_.resize(c);
        return false;
      }
      const double v = costs_->Evaluate(ctx_, InputFor(cand_lon_[c], cand_lat_[c]));
      cand_cost_[c] = Finite(v) ? v : 1e300;
      order_[c] = c;
    }
    return true;
  }

  // Cost order, ties by index: a strict total order.
  bool Cheaper(int a, int b) const {
    return cand_cost_[a] < cand_cost_[b] || (cand_cost_[a] == cand_cost_[b] && a < b);
  }
  // Sorts order_ lazily: the lazy check mostly looks at the first few candidates, so a full sort
  // would be wasted; ranks up to `rank` are in cost order afterwards.
  void SortUpTo(int rank) {
    const int n = static_cast<int>(order_.size());
    if (rank < sorted_ || sorted_ >= n) return;
    const int upto = std::min(n, std::max(rank + 1, 2 * sorted_ + 32));
    std::partial_sort(order_.begin() + sorted_, order_.begin() + upto, order_.end(),
                      [this](int a, int b) { return Cheaper(a, b); });
    sorted_ = upto;
  }

  // ---- Hard checks --------------------------------------------------------------------------

  // Samples a trajectory at every tick of the check horizon into the tick buffers.
  void FillTicks(const FrenetTrajectory& tr) {
    for (int i = 1; i <= n_ticks_; ++i) {
      const FrenetState st = tr.At(i * kTickSeconds);
      tk_s_[i] = st.s;
      tk_sd_[i] = st.s_d;
      tk_sdd_[i] = st.s_dd;
      tk_d_[i] = st.d;
      tk_dd_[i] = st.d_d;
      tk_ddd_[i] = st.d_dd;
    }
  }

  // The XY path's part common to every candidate of the cycle, history | kept, measured once.
  void SetXyPrefix() {
    int n = 0;
    for (int i = 0; i < hist_n_; ++i, ++n) {
      chk_x_[n] = hist_x_[i];
      chk_y_[n] = hist_y_[i];
    }
    for (int i = 0; i < kept_; ++i, ++n) {
      chk_x_[n] = plan_x_[i];
      chk_y_[n] = plan_y_[i];
    }
    first_new_ = n;
    checker_.SetPrefix(chk_x_.data(), chk_y_.data(), n);
  }

  // Appends the ticks to the XY prefix; returns the path length.
  int BuildXyPath() {
    int n = first_new_;
    for (int i = 1; i <= n_ticks_; ++i, ++n) {
      const map::CartesianPose p = line_->ToCartesian(tk_s_[i], tk_d_[i]);
      chk_x_[n] = p.x;
      chk_y_[n] = p.y;
    }
    return n;
  }

  // The worst normalised excess over all limits (<= 0: feasible), and the first reason.
  // lane_line: include the lane-line timer (LeastHarm may drop it: a collision is worse).
  double Violation(Reject* reason, bool lane_line = true) {
    double worst = -1e9;
    Reject why = Reject::kCount;
    auto take = [&](double v, Reject r) {
      if (!(v <= worst)) {  // NaN counts as a violation
        worst = Finite(v) ? v : 1e9;
        why = r;
      }
    };
    // d as the simulator reads it (from chords), bounded every 5 ticks over the s swept since
    // the previous check point.
    // The lane-line timer runs on, from the start state's count, while the read d may be astride
    // a line; a trajectory still astride at its end would stay there.
    double dmin = 1e9, dmax = -1e9, sdmin = 1e9;
    int straddle = straddle_at_start_, worst_straddle = straddle;
    for (int i = 1; i <= n_ticks_; ++i) sdmin = std::min(sdmin, tk_sd_[i]);
    for (int prev = 1, i = std::min(5, n_ticks_); n_ticks_ >= 1;
         prev = i, i = std::min(i + 5, n_ticks_)) {
      const double d_lo = std::min(tk_d_[prev], tk_d_[i]), d_hi = std::max(tk_d_[prev], tk_d_[i]);
      const map::ReferenceLine::OffsetRange r = line_->ChordOffset(
          std::min(tk_s_[prev], tk_s_[i]), std::max(tk_s_[prev], tk_s_[i]), 0.5 * (d_lo + d_hi));
      dmin = std::min(dmin, d_lo + r.lo);
      dmax = std::max(dmax, d_hi + r.hi);
      straddle = StraddlesRead(d_lo + r.lo, d_hi + r.hi) ? straddle + (i - prev) + (prev == 1) : 0;
      worst_straddle = std::max(worst_straddle, straddle);
      if (i == n_ticks_) break;
    }
    if (straddle > 0) worst_straddle = 1 << 20;
    take(std::max(cfg_.d_min - dmin, dmax - cfg_.d_max) / cfg_.lane_width, Reject::kOffRoad);
    if (lane_line) {
      take(static_cast<double>(worst_straddle - kMaxStraddleTicks) / kMaxStraddleTicks,
           Reject::kLaneLine);
    }
    take(-sdmin - 0.05, Reject::kSpeed);  // never backwards
    if (worst > 0) {                      // already infeasible: skip the XY conversion
      if (reason != nullptr) *reason = why;
      return worst;
    }
    const int n = BuildXyPath();
    const XyMeasure m = checker_.MeasureWithPrefix(chk_x_.data(), chk_y_.data(), n, first_new_);
    take(m.max_speed / cfg_.max_speed - 1.0, Reject::kSpeed);
    take(m.max_accel / cfg_.max_accel - 1.0, Reject::kAcceleration);
    take(m.max_jerk / cfg_.max_jerk - 1.0, Reject::kJerk);
    if (reason != nullptr) *reason = worst > 0 ? why : Reject::kCount;
    return worst;
  }

  // Oriented-box overlap with every relevant car over the check horizon (inflated boxes).
  bool Collides() const {
    return FirstCollision(
               [this](int i) {
                 return FrenetState{tk_s_[i], tk_sd_[i], 0.0, tk_d_[i], tk_dd_[i], 0.0};
               },
               1.0) <= n_steps_;
  }
  // The first collision step (1..n_steps_) of `state_at` (state at a tick index), or
  // n_steps_ + 1 when none. The safety margins are scaled by margin_scale (0: bare boxes),
  // except the room kept for a car behind in another lane, scaled by behind_scale: that car
  // does not see the ego until it is in front of it (the simulator's traffic only brakes for a
  // car within 2 m laterally), so moving into its way is never safe.
  template <typename StateAt>
  int FirstCollision(StateAt state_at, double margin_scale, double behind_scale = 1.0,
                     int* car_hit = nullptr) const {
    const double hl = 0.5 * cfg_.car_length, hw = 0.5 * cfg_.car_width;
    for (int j = 1; j <= n_steps_; ++j) {
      const FrenetState st = state_at(j * collision_step_);
      const double vs = std::max(st.s_d, 0.5), vd = st.d_d;
      const double inv = 1.0 / std::sqrt(vs * vs + vd * vd);
      const traj::OrientedBox ego{st.s, st.d, 0.0, hl, hw};
      for (int c = 0; c < ctx_.num_cars; ++c) {
        const int at = c * (n_steps_ + 1) + j;
        const double cs = step_s_[at], cd = step_d_[at];
        // A car behind in another lane than the start's is one the ego would cut in front of:
        // the simulator's traffic brakes hard when its gap falls below 10-20 m, so entering
        // its lane needs more room than a mere non-overlap (the seeds' rule: 15 m behind).
        // A car ahead needs room to brake behind it: headway_min at the ego's speed.
        const bool behind_other_lane =
            cs < ego.cx && std::abs(car_d0_[c] - start_.d) > 0.5 * cfg_.lane_width;
        // A car behind in another lane needs room to react and brake when it closes in.
        const double closing = std::max(0.0, step_v_[at] - st.s_d);
        // The headway to a car ahead is kept in full while the ego is in its lane and tapers
        // to margin_s as the ego moves out of it (pulling out from behind a car is how a
        // lane change starts).
        const double inside = std::clamp(
            (cfg_.car_width - std::abs(cd - st.d)) / (cfg_.car_width - kFollowerLateral), 0.0, 1.0);
        const double margin =
            cs >= ego.cx
                ? margin_scale * std::max(cfg_.margin_s, inside * cfg_.headway_min * st.s_d)
            : behind_other_lane ? behind_scale * (cfg_.margin_behind + cfg_.behind_time * closing)
                                : margin_scale * cfg_.margin_s;
        if (std::abs(cs - ego.cx) > 8 + margin || std::abs(cd - ego.cy) > 5) continue;
        // The car's heading from its predicted velocity (a lane change turns it).
        const double cv = std::max(step_v_[at], 0.5), cvd = step_vd_[at];
        const double cinv = 1.0 / std::sqrt(cv * cv + cvd * cvd);
        const traj::OrientedBox car{cs, cd, 0.0, hl + margin, hw + margin_scale * cfg_.margin_d};
        if (traj::Overlap(ego, vs * inv, vd * inv, car, cv * cinv, cvd * cinv)) {
          if (car_hit != nullptr) *car_hit = c;
          return j;
        }
      }
    }
    return n_steps_ + 1;
  }

  // The smallest separation (m) of the bare boxes from any car over the check horizon, in the
  // Frenet frame with the boxes aligned to the lane: max(|ds| - length, |dd| - width), < 0 on
  // overlap. Ranks the least harmful trajectories.
  double Clearance(const FrenetTrajectory& tr) const {
    double worst = 1e9;
    for (int j = 1; j <= n_steps_; ++j) {
      const FrenetState st = tr.At(j * collision_step_ * kTickSeconds);
      for (int c = 0; c < ctx_.num_cars; ++c) {
        const int at = c * (n_steps_ + 1) + j;
        const double sep = std::max(std::abs(step_s_[at] - st.s) - cfg_.car_length,
                                    std::abs(step_d_[at] - st.d) - cfg_.car_width);
        worst = std::min(worst, sep);
      }
    }
    return worst;
  }

  FrenetTrajectory Candidate(int c) const {
    return {lon_[cand_lon_[c]].traj, lat_[cand_lat_[c]].traj};
  }

  bool CheckLazily(bool* over_budget) {
    PlanSummary& sum = result_.summary;
    const int n = static_cast<int>(order_.size());
    for (int r = 0; r < n; ++r) {
      if ((r & 7) == 7 && Elapsed() > 0.85 * cfg_.budget_ms) {
        *over_budget = true;
        return false;
      }
      SortUpTo(r);
      const int c = order_[r];
      ++sum.candidates_checked;
      // Cheapest first: the Frenet-only collision test skips the tick sampling and the XY
      // conversion for the many candidates that run into traffic.
      const FrenetTrajectory tr = Candidate(c);
      int hit_car = -1;
      const int hit =
          FirstCollision([&tr](int i) { return tr.At(i * kTickSeconds); }, 1.0, 1.0, &hit_car);
      if (hit <= n_steps_) {
        ++sum.rejections[static_cast<int>(Reject::kCollision)];
        Trace(r, false, static_cast<int>(Reject::kCollision), hit_car,
              hit * collision_step_ * kTickSeconds);
        continue;
      }
      FillTicks(Candidate(c));
      Reject why = Reject::kCount;
      if (Violation(&why) > 0) {
        ++sum.rejections[static_cast<int>(why)];
        Trace(r, false, static_cast<int>(why));
        continue;
      }
      ++sum.candidates_feasible;
      TakeWinner(c);
      Trace(r, true, -1);
      for (int rr = r + 1;
           rr < n && trace_ != nullptr && static_cast<int>(trace_->candidates.size()) < trace_max_;
           ++rr) {
        SortUpTo(rr);
        Trace(rr, false, -1);
      }
      return true;
    }
    return false;
  }

  void TakeWinner(int c) {
    winner_index_ = c;
    winner_ = Candidate(c);
    winner_lon_ = cand_lon_[c];
    winner_lat_ = cand_lat_[c];
    winner_cost_ = cand_cost_[c];
  }

  // When no candidate is feasible and clear of traffic with the safety margins: the least
  // harmful feasible one, judged on bare car boxes (but still never cutting in front of a car
  // behind in another lane) — among the collision-free ones the one that keeps farthest from
  // every car, else the one whose first contact comes latest (more time for the others to react,
  // and for the next cycles to find a way out). False when none is even feasible.
  bool LeastHarm(bool* over_budget) {
    const int n = static_cast<int>(order_.size());
    first_hit_.resize(n);
    clearance_.resize(n);
    for (int r = 0; r < n; ++r) {
      if ((r & 31) == 31 && Elapsed() > 0.85 * cfg_.budget_ms) {
        *over_budget = true;
        return false;
      }
      const int c = order_[r];
      const FrenetTrajectory tr = Candidate(c);
      first_hit_[c] = FirstCollision([&](int i) { return tr.At(i * kTickSeconds); }, 0.0, 1.0);
      clearance_[c] = first_hit_[c] > n_steps_ ? Clearance(tr) : 0.0;
    }
    // Latest contact first, then most room; the cost order breaks ties (a strict total order:
    // std::stable_sort would allocate).
    std::sort(order_.begin(), order_.end(), [&](int a, int b) {
      if (first_hit_[a] != first_hit_[b]) return first_hit_[a] > first_hit_[b];
      if (clearance_[a] != clearance_[b]) return clearance_[a] > clearance_[b];
      return Cheaper(a, b);
    });
    sorted_ = n;
    // Feasible first; then ignoring the lane-line timer (an incident, but not a crash).
    for (const bool lane_line : {true, false}) {
      for (int r = 0; r < n; ++r) {
        if ((r & 7) == 7 && Elapsed() > 0.85 * cfg_.budget_ms) {
          *over_budget = true;
          return false;
        }
        const int c = order_[r];
        FillTicks(Candidate(c));
        if (Violation(nullptr, lane_line) > 0) continue;
        TakeWinner(c);
        return true;
      }
    }
    return false;
  }

  // car: context index of the car a collision rejection is against (-1: none), at time t.
  void Trace(int rank, bool winner, int reject, int car = -1, double t = 0) {
    if (trace_ == nullptr || static_cast<int>(trace_->candidates.size()) >= trace_max_) return;
    const int c = order_[rank];
    CandidateTrace ct;
    ct.lane = lat_[cand_lat_[c]].lane;
    const LonTraj& lt = lon_[cand_lon_[c]];
    ct.end_speed = lt.traj.poly.V(lt.traj.duration);
    ct.duration = lt.traj.duration;
    ct.total_cost = cand_cost_[c];
    ct.checked = winner || reject >= 0;
    ct.winner = winner;
    ct.reject = reject;
    if (car >= 0) {
      ct.reject_car = predictor_->cars()[car_index_[car]].id;
      ct.reject_time = t;
    }
    const FrenetTrajectory tr = Candidate(c);
    for (double tt = 0; tt <= cfg_.score_horizon + 1e-9; tt += 0.25) {
      const FrenetState st = tr.At(tt);
      const map::CartesianPose p = line_->ToCartesian(st.s, st.d);
      ct.x.push_back(p.x);
      ct.y.push_back(p.y);
    }
    costs_->Evaluate(ctx_, InputFor(cand_lon_[c], cand_lat_[c]), per_term_.data());
    for (int i = 0; i < costs_->size(); ++i) {
      ct.costs.push_back({costs_->name(i), costs_->weight(i), per_term_[i]});
    }
    trace_->candidates.push_back(std::move(ct));
  }

  // ---- Refinement ---------------------------------------------------------------------------

  // Builds the trajectory for refinement parameters x = [param, T, T_lat, offset].
  FrenetTrajectory FromParams(const double* x) const {
    const LonTraj& base = lon_[winner_lon_];
    const LatTraj& lbase = lat_[winner_lat_];
    LonTraj l = MakeLon(base.kind, base.lane, x[0], x[1], base.lead);
    LatTraj d = MakeLat(lbase.lane, x[3], x[2]);
    return {l.traj, d.traj};
  }

  // Weighted cost of a trajectory (samples it like the bundles).
  // Samples `tr` on the scoring grid into the ref_* buffers and points a CostInput at them.
  cost::CostInput SampleForCost(const FrenetTrajectory& tr, const LonTraj& lbase,
                                const LatTraj& dbase) {
    for (int k = 0; k < n_samples_; ++k) {
      const FrenetState st = tr.At(k * cfg_.score_dt);
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
    in.end_d = ref_d_[n_samples_ - 1];
    in.target_lane = dbase.lane;
    in.kind = lbase.kind;
    NearLat(ref_d_.data(), ref_near_lat_.data());
    NearLon(ref_s_.data(), ref_near_lon_.data());
    SetNear(in, ref_near_lat_.data(), ref_near_lon_.data());
    return in;
  }

  double CostOf(const FrenetTrajectory& tr, const LonTraj& lbase, const LatTraj& dbase) {
    const double v = costs_->Evaluate(ctx_, SampleForCost(tr, lbase, dbase));
    return Finite(v) ? v : 1e300;
  }

  static double RefineObjective(unsigned n, const double* x, double* grad, void* data) {
    (void)n;
    (void)grad;  // derivative-free
    auto* self = static_cast<SearchPlanner*>(data);
    ++self->refine_evals_;
    const FrenetTrajectory tr = self->FromParams(x);
    double v = self->CostOf(tr, self->lon_[self->winner_lon_], self->lat_[self->winner_lat_]);
    if (!self->constraints_ok_) {
      // Algorithms without constraint support get the limits as a steep penalty.
      self->FillTicks(tr);
      v += 1e3 * std::max(0.0, self->Violation(nullptr));
    }
    return v;
  }

  static double RefineConstraint(unsigned n, const double* x, double* grad, void* data) {
    (void)n;
    (void)grad;
    auto* self = static_cast<SearchPlanner*>(data);
    self->FillTicks(self->FromParams(x));
    return self->Violation(nullptr);
  }

  void Refine() {
    PlanSummary& sum = result_.summary;
    const LonTraj& lb = lon_[winner_lon_];
    const LatTraj& db = lat_[winner_lat_];
    // Braking is the emergency family: it is sent as sampled, at once.
    if (lb.kind == cost::LonKind::kBraking) return;
    double x[4] = {lb.param, lb.traj.duration, db.traj.duration, db.offset};
    double lo[4], hi[4];
    switch (lb.kind) {
      case cost::LonKind::kVelocityKeeping:
        lo[0] = 0;
        hi[0] = ctx_.lane_speed_limit[db.lane];
        break;
      case cost::LonKind::kFollowing:
        lo[0] = -5;
        hi[0] = 30;
        break;
      case cost::LonKind::kStopping:
        lo[0] = 0;
        hi[0] = std::max(1.0, start_.s_d * cfg_.max_duration);
        break;
      case cost::LonKind::kBraking:
        return;
    }
    lo[1] = cfg_.min_duration;
    hi[1] = cfg_.max_duration;
    lo[2] = std::min(cfg_.lat_min_duration, db.traj.duration);
    hi[2] = std::max(cfg_.lat_max_duration, db.traj.duration);
    lo[3] = -0.5;
    hi[3] = 0.5;
    for (int i = 0; i < 4; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
    const double before = CostOf(winner_, lb, db);
    sum.refine_cost_before = before;
    sum.refine_cost_after = before;
    nlopt_set_lower_bounds(opt_, lo);
    nlopt_set_upper_bounds(opt_, hi);
    // The first steps: a tenth of each range. Explicit, or NLopt would keep the step it derived
    // from the first refinement ever run (state carried across cycles and episodes).
    double step[4];
    for (int i = 0; i < 4; ++i) step[i] = std::max(1e-3, 0.1 * (hi[i] - lo[i]));
    nlopt_set_initial_step(opt_, step);
    const double remaining = 0.8 * cfg_.budget_ms - Elapsed();
    const double maxtime_ms = std::min(cfg_.refine_budget_ms, remaining);
    // 0 switches NLopt's clock off: pinned deadlines leave refine.max_iterations as the bound.
    nlopt_set_maxtime(opt_, std::isfinite(maxtime_ms) ? std::max(1e-3, maxtime_ms) * 1e-3 : 0.0);
    refine_evals_ = 0;
    double best = 0;
    const nlopt_result r = nlopt_optimize(opt_, x, &best);
    sum.refine_iterations = refine_evals_;
    if (r < 0 || !Finite(best) || best >= before) return;
    // Safety re-check of the refined trajectory; keep the unrefined winner if it fails.
    const FrenetTrajectory refined = FromParams(x);
    FillTicks(refined);
    if (Violation(nullptr) > 0 || Collides()) return;
    winner_ = refined;
    sum.refine_cost_after = CostOf(refined, lb, db);
  }

  // ---- Decision memory, costs, fallback, output ---------------------------------------------

  void RecordDecision(int lane) {
    const int committed = prev_target_lane_ >= 0 ? prev_target_lane_ : LaneOf(start_.d);
    if (lane != committed) {
      lane_before_change_ = committed;
      time_since_change_ = 0;
    }
    prev_target_lane_ = lane;
    prev_lat_lane_ = lat_[winner_lat_].lane;
    prev_lat_offset_ = winner_.lat.At(winner_.lat.end_time()).p - lane_center_[prev_lat_lane_];
    prev_traj_ = winner_;
    prev_base_ = 0;
    have_prev_traj_ = true;
  }

  void EvaluateWinnerCosts() {
    const LonTraj& lbase = lon_[winner_lon_];
    const LatTraj& dbase = lat_[winner_lat_];
    const double total =
        costs_->Evaluate(ctx_, SampleForCost(winner_, lbase, dbase), per_term_.data());
    for (int i = 0; i < costs_->size(); ++i) result_.summary.winner_costs[i].value = per_term_[i];
    result_.summary.winner_total_cost = Finite(total) ? total : 1e300;
  }

  // Samples last cycle's winner from the current start on into the tick buffers; false when
  // there is none or it now collides. The XY limits were checked on it when it won.
  bool ContinuePrevious() {
    if (!have_prev_traj_) return false;
    for (int i = 1; i <= n_ticks_; ++i) {
      const FrenetState st = prev_traj_.At(prev_elapsed_ + i * kTickSeconds);
      tk_s_[i] = st.s;
      tk_sd_[i] = st.s_d;
      tk_sdd_[i] = st.s_dd;
      tk_d_[i] = st.d;
      tk_dd_[i] = st.d_d;
      tk_ddd_[i] = st.d_dd;
    }
    if (Collides()) return false;
    prev_base_ = prev_elapsed_;  // the next cycle's elapsed time counts from this start
    return true;
  }

  // Keep-lane braking at a jerk-limited constant deceleration, integrated tick by tick; it
  // never exceeds the limits. The first braking level that clears the traffic wins, else the
  // hardest.
  void BuildFallback() {
    const double levels[3] = {cfg_.fallback_decel,
                              std::min(2 * cfg_.fallback_decel, 0.75 * cfg_.max_accel),
                              0.9 * cfg_.max_accel};
    const int lane = LaneOf(start_.d);
    Trajectory1d lat{traj::SolveQuintic(start_.d, start_.d_d, start_.d_dd, lane_center_[lane], 0, 0,
                                        cfg_.fallback_lat_duration),
                     cfg_.fallback_lat_duration};
    for (int level = 0; level < 3; ++level) {
      const double decel = levels[level];
      const double jerk = std::min(cfg_.fallback_jerk, 0.8 * cfg_.max_jerk);
      double s = start_.s, v = std::max(start_.s_d, 0.0), a = start_.s_dd;
      for (int i = 1; i <= n_ticks_; ++i) {
        // Aim at -decel, but ease off near standstill so a reaches 0 when v does.
        const double target = v > 0 ? -std::min(decel, std::sqrt(2.0 * jerk * v)) : 0.0;
        const double da = std::clamp(target - a, -jerk * kTickSeconds, jerk * kTickSeconds);
        a += da;
        v += a * kTickSeconds;
        if (v <= 0) {
          v = 0;
          a = 0;
        }
        s += v * kTickSeconds;
        const traj::State1d d = lat.At(i * kTickSeconds);
        tk_s_[i] = s;
        tk_sd_[i] = v;
        tk_sdd_[i] = a;
        tk_d_[i] = d.p;
        tk_dd_[i] = d.v;
        tk_ddd_[i] = d.a;
      }
      if (!Collides()) break;
    }
  }

  void Output() {
    const int new_points = cfg_.output_points - kept_;
    for (int i = 1; i <= new_points; ++i) {
      const int k = kept_ + i - 1;
      plan_s_[k] = tk_s_[i];
      plan_sd_[k] = tk_sd_[i];
      plan_sdd_[k] = tk_sdd_[i];
      plan_d_[k] = tk_d_[i];
      plan_dd_[k] = tk_dd_[i];
      plan_ddd_[k] = tk_ddd_[i];
      const map::CartesianPose p = line_->ToCartesian(tk_s_[i], tk_d_[i]);
      plan_x_[k] = p.x;
      plan_y_[k] = p.y;
    }
    plan_n_ = cfg_.output_points;
    plan_start_index_ = kept_ > 0 ? kept_ - 1 : -1;
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
      result_.x.push_back(plan_x_[k]);
      result_.y.push_back(plan_y_[k]);
    }
    have_plan_ = true;
  }

  PlannerClock clock_ms_;
  Settings cfg_;
  std::shared_ptr<const map::ReferenceLine> line_;
  std::shared_ptr<const cost::CostSet> costs_;
  std::unique_ptr<Predictor> predictor_;
  XyChecker checker_;
  nlopt_opt opt_ = nullptr;
  bool constraints_ok_ = false;
  int refine_evals_ = 0;

  double lane_nominal_[cost::kMaxLanes] = {};  // configured lane centres, m
  double lane_center_[cost::kMaxLanes] = {};   // this cycle's (LaneCentres), m
  int n_samples_ = 0, n_ticks_ = 0;
  double t0_ = 0;  // ms, clock_ms_ at the start of the cycle
  CycleTrace* trace_ = nullptr;
  int trace_max_ = 0;

  // Per cycle.
  FrenetState start_;
  int kept_ = 0;
  double t_keep_ = 0;
  cost::CostContext ctx_;
  std::vector<LonTraj> lon_;
  std::vector<LatTraj> lat_;
  std::vector<double> lon_s_, lon_sd_, lon_sdd_, lat_d_, lat_dd_, lat_ddd_;
  std::vector<int> cand_lon_, cand_lat_, order_;
  int sorted_ = 0;  // order_[0, sorted_) is in cost order (SortUpTo)
  // Per candidate (LeastHarm): first collision step and clearance on bare boxes.
  std::vector<int> first_hit_;
  std::vector<double> clearance_;
  std::vector<double> cand_cost_;
  // Traffic of the cycle (context index c): predicted s, d, speed at the scoring samples
  // ([c * n_samples_ + k]), where it is at the start instant, its predictor index, and its
  // predicted s, d, speed and lateral speed at the collision-check steps ([c * (n_steps_ + 1) +
  // j], t_keep_ + j * collision_step_ ticks).
  std::vector<double> car_s_, car_d_, car_v_, car_s0_, car_d0_;
  std::vector<int> car_index_;
  int collision_step_ = 5, n_steps_ = 0;
  std::vector<double> step_s_, step_d_, step_v_, step_vd_;
  // Broad-phase masks (cost::CostInput::near_lat, near_lon).
  std::vector<std::uint64_t> lat_near_, lon_near_, ref_near_lat_, ref_near_lon_;
  std::vector<double> prev_s_, prev_d_;
  std::vector<double> ref_s_, ref_sd_, ref_sdd_, ref_d_, ref_dd_, ref_ddd_;
  std::vector<double> tk_s_, tk_sd_, tk_sdd_, tk_d_, tk_dd_, tk_ddd_;
  std::vector<double> chk_x_, chk_y_;
  std::vector<double> per_term_;
  int first_new_ = 0;
  int winner_index_ = -1, winner_lon_ = -1, winner_lat_ = -1;
  double winner_cost_ = 0;
  FrenetTrajectory winner_;

  // Across cycles.
  bool have_plan_ = false;
  int plan_n_ = 0;
  int plan_start_index_ = 0;  // index of the start state of the stored plan's new part
  std::vector<double> plan_s_, plan_sd_, plan_sdd_, plan_d_, plan_dd_, plan_ddd_, plan_x_, plan_y_;
  std::vector<double> hist_x_, hist_y_;
  int hist_n_ = 0;
  // Consecutive ticks the simulator may have read the ego astride a lane line: up to the last
  // driven point, and up to this cycle's start state (kept points included).
  int straddle_ticks_ = 0, straddle_at_start_ = 0;
  bool have_prev_traj_ = false;
  FrenetTrajectory prev_traj_;
  double prev_elapsed_ = 0;  // s: the current start's time on prev_traj_
  double prev_base_ = 0;     // s: the stored plan start's time on prev_traj_ (see ContinuePrevious)
  int prev_target_lane_ = -1, lane_before_change_ = -1;
  int prev_lat_lane_ = -1;  // lane and end offset (m) of the previous winner's lateral move
  double prev_lat_offset_ = 0;
  double time_since_change_ = 1e9;
  // Plan reuse between full searches (see CanReuse).
  struct SnapCar {
    int id;
    double x, y, vx, vy;
  };
  static constexpr int kMaxSnap = 64;
  SnapCar snap_[kMaxSnap] = {};
  int snap_n_ = 0;
  double snap_ego_x_ = 0, snap_ego_y_ = 0;
  int ticks_since_search_ = 0;
  bool can_reuse_ = false;
  double clock_ = NAN;  // s, simulated time of the current message (NaN: unknown)
  int reuse_lane_ = -1;
  double reuse_end_speed_ = 0, reuse_duration_ = 0;

  PlanResult result_;
};

}  // namespace

std::unique_ptr<Planner> MakeSearchPlanner(const PlannerConfig& config,
                                           std::shared_ptr<const map::ReferenceLine> line,
                                           std::shared_ptr<const cost::CostSet> costs,
                                           PlannerClock clock) {
  return std::make_unique<SearchPlanner>(config, std::move(line), std::move(costs),
                                         std::move(clock));
}

}  // namespace frenetic::plan

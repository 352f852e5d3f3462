// The `search` planner. Werling, Ziegler, Kammel, Thrun, "Optimal Trajectory Generation for
// Dynamic Street Scenarios in a Frenet Frame", ICRA 2010: 1-D longitudinal and lateral bundles,
// every pair scored, lazy hard checks in cost order, a backup that always exists. This file is
// the cycle's orchestration; the stages live in search/*.h (context, lattice, scoring, checks,
// least_harm, refiner, fallback, continuity) and share one Workspace.
#include "plan/search/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "frenetic/plan/predictor.h"
#include "frenetic/traj/frenet.h"
#include "plan/predictor_options.h"
#include "plan/search/checks.h"
#include "plan/search/context.h"
#include "plan/search/continuity.h"
#include "plan/search/fallback.h"
#include "plan/search/lattice.h"
#include "plan/search/least_harm.h"
#include "plan/search/refiner.h"
#include "plan/search/scoring.h"
#include "plan/search/selection.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan {
namespace {

using search::Finite;
using traj::FrenetState;
using traj::FrenetTrajectory;

// Traced, CheckLazily walks this many ranks in cost order (more when more are traced), then
// tests the rest by their cost bound (Selection); untraced, it tests them all by bound.
constexpr int kCheckRestMin = 4;
// Lane ends (WithLaneEnds): the id of lane l's car is kLaneEndId - l; it is kLaneEndLength m
// long; ends within kLaneEndRange m ahead are shown (ends within kLaneEndSlack m of the road's
// own end are the road's end, not a lane's).
constexpr int kLaneEndId = -1000;
constexpr double kLaneEndLength = 1.0;
constexpr double kLaneEndRange = 250.0;
constexpr double kLaneEndSlack = 1.0;

double SteadyMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::unique_ptr<Predictor> MakePredictor(const PlannerConfig& config,
                                         std::shared_ptr<const map::Road> road,
                                         const search::Settings& cfg) {
  PredictorOptions po = BasicPredictorOptions(config);
  po.brake_threshold = config.value("prediction.brake_threshold");
  po.brake_horizon = config.value("prediction.brake_horizon");
  po.lateral_threshold = config.value("prediction.lateral_threshold");
  po.lane_change_ghosts = config.int_value("prediction.lane_change_ghosts") != 0;
  po.lane_width = cfg.lane_width;
  po.num_lanes = cfg.num_lanes;
  po.car_length = cfg.car_length;
  po.car_width = cfg.car_width;
  // The horizons the context samples predictions over, from the kept points' end.
  po.future_horizon = std::max(cfg.score_horizon, cfg.check_horizon) + 1.0;
  return config.int_value("prediction.manoeuvres") != 0
             ? MakeManoeuvrePredictor(std::move(road), po)
             : MakeConstantVelocityPredictor(std::move(road), po);
}

class SearchPlanner : public Planner {
 public:
  SearchPlanner(const PlannerConfig& config, std::shared_ptr<const map::Road> road,
                std::shared_ptr<const cost::CostSet> costs, PlannerClock clock)
      : timer_(clock ? std::move(clock) : PlannerClock(SteadyMs)),
        cfg_(config, *road),
        road_(std::move(road)),
        line_(road_->line_ptr()),
        costs_(std::move(costs)),
        predictor_(MakePredictor(config, road_, cfg_)),
        ws_(cfg_),
        lattice_(cfg_, *predictor_, ws_),
        scorer_(cfg_, *costs_, ws_, timer_),
        checker_(cfg_, *line_, ws_),
        least_harm_(cfg_, ws_, scorer_, checker_, timer_),
        selection_(cfg_, ws_, scorer_, checker_, timer_),
        refiner_(cfg_, config.refine_algorithm(), ws_, lattice_, scorer_, checker_, timer_),
        continuity_(cfg_, *line_, ws_, timer_) {
    per_term_.assign(costs_->size(), 0.0);
    rows_.reserve(search::kMaxCars + cost::kMaxLanes);
    for (int l = 0; l < road_->num_lanes(); ++l) road_end_ = std::max(road_end_, road_->LaneEnd(l));
    result_.x.reserve(cfg_.output_points + 1);
    result_.y.reserve(cfg_.output_points + 1);
    result_.summary.winner_costs.resize(costs_->size());
    for (int i = 0; i < costs_->size(); ++i) {
      result_.summary.winner_costs[i].name = costs_->name(i);
      result_.summary.winner_costs[i].weight = costs_->weight(i);
    }
    Reset();
  }

  std::string_view name() const override { return "search"; }

  void set_trace(CycleTrace* trace, int max_candidates) override {
    trace_ = trace;
    trace_max_ = max_candidates;
  }

  void Reset() override {
    continuity_.Reset();
    ws_.have_prev_traj = false;
    ws_.prev_target_lane = -1;
    ws_.lane_before_change = -1;
    ws_.time_since_change = 1e9;
    sim_time_ = NAN;
    none_passed_last_ = false;
    predictor_->Reset();
  }

  const PlanResult& Plan(const Telemetry& t) override {
    timer_.Start();
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
    const search::Continuity::Sync sync = continuity_.Synchronise(t, prev_ok, ego_ok);
    const int consumed = sync.consumed;
    const bool synced = sync.synced;
    // Simulated time of this message: it dates the traffic readings for the predictor's
    // acceleration estimates. Unknown after a resynchronisation.
    sim_time_ = synced ? (std::isnan(sim_time_) ? 0.0 : sim_time_) + consumed * kTickSeconds : NAN;
    if (synced && ego_ok && continuity_.CanReuse(t, consumed)) {
      continuity_.ReusePlan(consumed, result_);
      return result_;
    }
    FrenetState start;
    int kept = 0;
    double elapsed = 0;  // s between the previous start state and this one
    if (synced) {
      kept = std::min(cfg_.keep_points, continuity_.plan_n() - consumed);
      start = continuity_.KeepPoints(consumed, kept, &elapsed);
    } else {
      continuity_.Desync();
      ws_.have_prev_traj = false;
      if (ego_ok) {
        const double hint = continuity_.have_plan() ? continuity_.plan_s(0) : t.s;
        const map::FrenetPoint f = line_->ToFrenet(t.x, t.y, hint);
        const map::RefSample c = line_->At(f.s);
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
        start = {0.0, 0.0, 0.0, ws_.lane_center[std::min(1, cfg_.num_lanes - 1)], 0.0, 0.0};
      }
      if (!start.IsFinite()) start = {0.0, 0.0, 0.0, ws_.lane_center[0], 0.0, 0.0};
      // s' and d' from the measured heading can be off on the very first tick; the lattice
      // starts from rest in d' to avoid sweeping across the road.
      start.d_d = std::clamp(start.d_d, -2.0, 2.0);
      start.s_d = std::clamp(start.s_d, 0.0, cfg_.max_speed);
      invalid = invalid || !ego_ok;
    }
    if (line_->closed() && (start.s >= line_->length() || start.s < 0)) {
      continuity_.Rebase(start, kept);
    }
    sum.points_kept = kept;
    ws_.kept = kept;
    ws_.start = start;
    ws_.t_keep = kept * kTickSeconds;
    ws_.time_since_change += elapsed;
    ws_.num_goals = static_cast<int>(std::min<std::size_t>(t.goals.size(), cost::kMaxGoalRegions));
    for (int g = 0; g < ws_.num_goals; ++g) {
      ws_.goals[g] = t.goals[g];
      ws_.goals[g].t_lo -= ws_.t_keep;
      ws_.goals[g].t_hi -= ws_.t_keep;
    }
    if (ws_.have_prev_traj) ws_.prev_elapsed = ws_.prev_base + elapsed;

    // Prediction (relative to the start state's s; the observation is "now"), with the ends of
    // lanes that end ahead as cars at rest.
    predictor_->Observe(WithLaneEnds(t.sensor_fusion, start.s), start.s, sim_time_, t.futures,
                        start.d);
    search::BuildContext(cfg_, *road_, *predictor_, ws_);
    continuity_.SetXyPrefix(checker_);
    sum.ms_prepare = Elapsed();

    bool found = false;       // a candidate passed every check
    bool least_harm = false;  // none did: the least harmful feasible one was taken instead
    bool over_budget = false;
    if (!invalid || synced) {
      lattice_.Generate();
      sum.candidates_generated = static_cast<int>(ws_.cand_lon.size());
      sum.ms_generate = Elapsed() - sum.ms_prepare;
      const double t_score = Elapsed();
      if (!scorer_.Score()) {
        over_budget = true;
        sum.deadline_stage = PlanSummary::Stage::kScore;
      }
      sum.candidates_scored = static_cast<int>(ws_.order.size());
      sum.ms_score = Elapsed() - t_score;
      const double t_check = Elapsed();
      bool check_cut = false;
      const bool none_passed_before = none_passed_last_;
      found = CheckLazily(&check_cut);
      none_passed_last_ = !found && !check_cut;
      if (!found && !check_cut) least_harm = least_harm_.Choose(&check_cut, none_passed_before);
      if (check_cut) {
        over_budget = true;
        sum.deadline_stage = PlanSummary::Stage::kCheck;
      }
      sum.ms_check = Elapsed() - t_check;
      // A swerve into a goal region is taken as it is: its checks end at the region
      // (Workspace::CheckTicks), the refinement's run over the whole horizon; and a pass, which
      // the refinement's single move cannot express.
      if (found && cfg_.refine && refiner_.available() && ws_.lat[ws_.winner_lat].goal < 0 &&
          !ws_.lat[ws_.winner_lat].pass()) {
        // A pinned (infinite) cycle budget always leaves room; a pinned refinement budget
        // asks for none beyond the cycle's.
        const double refine_ms = std::isfinite(cfg_.refine_budget_ms) ? cfg_.refine_budget_ms : 0;
        if (Elapsed() + refine_ms < 0.8 * cfg_.budget_ms) {
          const double t_ref = Elapsed();
          refiner_.Refine(sum);
          sum.ms_refine = Elapsed() - t_ref;
        } else if (sum.deadline_stage == PlanSummary::Stage::kNone) {
          // Not enough time left: the unrefined winner goes out, on time.
          sum.deadline_stage = PlanSummary::Stage::kRefine;
        }
      }
    }
    const double t_out = Elapsed();
    if (found || least_harm) {
      checker_.FillTicks(ws_.winner);
      sum.winner_lane = ws_.lat[ws_.winner_lat].lane;
      sum.winner_end_speed = ws_.winner.lon.At(ws_.winner.lon.duration).v;
      sum.winner_duration = ws_.winner.lon.duration;
      RecordDecision(sum.winner_lane);
      continuity_.RememberWinner(sum.winner_lane, sum.winner_end_speed, sum.winner_duration);
      EvaluateWinnerCosts();
    } else if (over_budget && search::ContinuePrevious(ws_, checker_)) {
      // Cut short (a loaded machine): last cycle's winner, still collision-free, is a better
      // answer than braking, which invites the car behind into the ego's boot.
      sum.winner_lane = ws_.prev_target_lane;
    } else {
      search::BuildFallback(cfg_, ws_, checker_);
      ws_.have_prev_traj = false;
    }
    continuity_.Store(result_);
    // Only a clean search result may be re-sent without searching: a fallback, an invalid
    // input or a cut-short search replans at the next message.
    continuity_.SearchDone(t, found && !invalid && !over_budget);
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
  double Elapsed() const { return timer_.Elapsed(); }

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

  // Finds the cheapest candidate that passes every check: the Frenet-only collision test
  // first, then the hard limits. False when none passed or the deadline (85% of budget_ms) cut
  // it short (then *over_budget is set). Traced, the traced ranks are checked in cost order,
  // sorting lazily (the trace shows why each was rejected); the rest, and untraced every
  // candidate, are tested by their cost bound instead (Selection::CheapestPassing), which
  // needs no exact cost for a candidate that collides: the same winner.
  bool CheckLazily(bool* over_budget) {
    PlanSummary& sum = result_.summary;
    const int n = static_cast<int>(ws_.order.size());
    const int rest_at = trace_ != nullptr ? std::max(kCheckRestMin, trace_max_) : 0;
    for (int r = 0; r < n; ++r) {
      if ((r & 7) == 7 && timer_.ChecksOver(cfg_.budget_ms)) {
        *over_budget = true;
        return false;
      }
      if (r == rest_at) {
        bool cut = false;
        const int best = selection_.CheapestPassing(r, none_passed_last_, &sum, &cut);
        if (cut) *over_budget = true;
        if (best < 0) return false;
        ws_.TakeWinner(best);
        return true;
      }
      if (!scorer_.SortUpTo(r)) {  // costing the next candidates ran into the deadline
        *over_budget = true;
        return false;
      }
      const int c = ws_.order[r];
      ++sum.candidates_checked;
      // Cheapest first: the Frenet-only collision test skips the tick sampling and the XY
      // conversion for the many candidates that run into traffic.
      // Past the traced ranks, whether it collides is all the walk needs.
      int hit_car = -1, hit = ws_.n_steps + 1;
      if (trace_ != nullptr && r < trace_max_) {
        hit = checker_.FirstCollision(checker_.StepsOf(c), 1.0, 1.0, &hit_car, true, 1,
                                      ws_.CheckSteps(c));
      } else {
        hit = checker_.CandidateCollides(c) ? 1 : hit;
      }
      if (hit <= ws_.n_steps) {
        ++sum.rejections[static_cast<int>(Reject::kCollision)];
        Trace(r, false, static_cast<int>(Reject::kCollision), hit_car,
              hit * ws_.collision_step * kTickSeconds);
        continue;
      }
      Reject why = Reject::kCount;
      if (checker_.CandidateViolation(c, &why) > 0) {
        ++sum.rejections[static_cast<int>(why)];
        Trace(r, false, static_cast<int>(why));
        continue;
      }
      ++sum.candidates_feasible;
      ws_.TakeWinner(c);
      Trace(r, true, -1);
      for (int rr = r + 1;
           rr < n && trace_ != nullptr && static_cast<int>(trace_->candidates.size()) < trace_max_;
           ++rr) {
        if (!scorer_.SortUpTo(rr)) break;
        Trace(rr, false, -1);
      }
      return true;
    }
    return false;
  }

  // The sensor rows plus, for every lane that ends ahead before the road does (a lane drop, an
  // on-ramp's end) or at a wall (the map's closed end), a car at rest in its last metre: the
  // lattice follows and stops for it, the costs and checks see the lane as blocked there, as a
  // driver sees a lane drop. Rows are returned as they are on a road whose lanes never end.
  std::span<const SensorCar> WithLaneEnds(const std::vector<SensorCar>& rows, double start_s) {
    if (road_->uniform()) return rows;
    rows_.assign(rows.begin(), rows.begin() + std::min<std::size_t>(rows.size(), search::kMaxCars));
    for (int l = 0; l < road_->num_lanes(); ++l) {
      // The lane's wall (a closed end of the map), or its own end before the road's.
      double end = road_->Wall(l);
      if (road_->LaneEnd(l) < road_end_ - kLaneEndSlack) end = std::min(end, road_->LaneEnd(l));
      if (!std::isfinite(end) || end < start_s - kLaneEndSlack || end > start_s + kLaneEndRange) {
        continue;
      }
      // The car fills the lane's last kLaneEndLength m (inside the road, where the predictor
      // keeps it).
      const double s_car = end - 0.5 * kLaneEndLength;
      const map::Road::Span at = road_->LaneAt(l, s_car);
      if (!at.exists) continue;
      const map::CartesianPose p = line_->ToCartesian(s_car, at.centre());
      SensorCar c;
      c.id = kLaneEndId - l;
      c.x = p.x;
      c.y = p.y;
      c.s = s_car;
      c.d = at.centre();
      c.length = kLaneEndLength;
      c.width = std::max(at.width() - 0.2, 0.5);
      rows_.push_back(c);
    }
    return rows_;
  }

  // car: context index of the car a collision rejection is against (-1: none), at time t.
  void Trace(int rank, bool winner, int reject, int car = -1, double t = 0) {
    if (trace_ == nullptr || static_cast<int>(trace_->candidates.size()) >= trace_max_) return;
    const int c = ws_.order[rank];
    CandidateTrace ct;
    ct.lane = ws_.lat[ws_.cand_lat[c]].lane;
    const search::LonTraj& lt = ws_.lon[ws_.cand_lon[c]];
    ct.end_speed = lt.traj.poly.V(lt.traj.duration);
    ct.duration = lt.traj.duration;
    ct.total_cost = ws_.cand_cost[c];
    ct.checked = winner || reject >= 0;
    ct.winner = winner;
    ct.reject = reject;
    if (car >= 0) {
      ct.reject_car = predictor_->cars()[ws_.car_index[car]].id;
      ct.reject_time = t;
    }
    const FrenetTrajectory tr = ws_.Candidate(c);
    for (double tt = 0; tt <= cfg_.score_horizon + 1e-9; tt += 0.25) {
      const FrenetState st = tr.At(tt);
      const map::CartesianPose p = line_->ToCartesian(st.s, st.d);
      ct.x.push_back(p.x);
      ct.y.push_back(p.y);
    }
    costs_->Evaluate(ws_.ctx, scorer_.InputFor(ws_.cand_lon[c], ws_.cand_lat[c]), per_term_.data());
    for (int i = 0; i < costs_->size(); ++i) {
      ct.costs.push_back({costs_->name(i), costs_->weight(i), per_term_[i]});
    }
    trace_->candidates.push_back(std::move(ct));
  }

  // Remembers the winner's lane decision (the lane-change timer starts when the target lane
  // changes) and trajectory for the next cycles.
  void RecordDecision(int lane) {
    const int committed =
        ws_.prev_target_lane >= 0 ? ws_.prev_target_lane : search::LaneOf(cfg_, ws_, ws_.start.d);
    if (lane != committed) {
      ws_.lane_before_change = committed;
      ws_.time_since_change = 0;
    }
    ws_.prev_target_lane = lane;
    ws_.prev_lat_lane = ws_.lat[ws_.winner_lat].lane;
    ws_.prev_swerve_goal = ws_.lat[ws_.winner_lat].goal;
    ws_.prev_lat_offset =
        ws_.winner.lat.At(ws_.winner.lat.end_time()).p - ws_.lane_center[ws_.prev_lat_lane];
    ws_.prev_traj = ws_.winner;
    ws_.prev_base = 0;
    ws_.have_prev_traj = true;
  }

  void EvaluateWinnerCosts() {
    const search::LonTraj& lbase = ws_.lon[ws_.winner_lon];
    const search::LatTraj& dbase = ws_.lat[ws_.winner_lat];
    const double total = costs_->Evaluate(ws_.ctx, scorer_.SampleForCost(ws_.winner, lbase, dbase),
                                          per_term_.data());
    for (int i = 0; i < costs_->size(); ++i) result_.summary.winner_costs[i].value = per_term_[i];
    result_.summary.winner_total_cost = Finite(total) ? total : 1e300;
  }

  search::CycleClock timer_;
  search::Settings cfg_;
  std::shared_ptr<const map::Road> road_;
  std::shared_ptr<const map::ReferenceLine> line_;  // road_'s
  std::shared_ptr<const cost::CostSet> costs_;
  std::unique_ptr<Predictor> predictor_;
  // The stages, in cycle order after the context (search::BuildContext), all on ws_.
  search::Workspace ws_;
  search::Lattice lattice_;
  search::Scorer scorer_;
  search::Checker checker_;
  search::LeastHarm least_harm_;
  search::Selection selection_;
  search::Refiner refiner_;
  search::Continuity continuity_;

  std::vector<double> per_term_;  // unweighted term values (Trace, EvaluateWinnerCosts)
  std::vector<SensorCar> rows_;   // WithLaneEnds' rows
  // The road's end: the farthest lane end (a lane ending before it, by more than kLaneEndSlack,
  // ends within the road).
  double road_end_ = -std::numeric_limits<double>::infinity();
  bool none_passed_last_ = false;              // the last search's checks found no candidate passing
  CycleTrace* trace_ = nullptr;
  int trace_max_ = 0;
  double sim_time_ = NAN;  // s, simulated time of the current message (NaN: unknown)
  PlanResult result_;
};

}  // namespace

std::unique_ptr<Planner> MakeSearchPlanner(const PlannerConfig& config,
                                           std::shared_ptr<const map::Road> road,
                                           std::shared_ptr<const cost::CostSet> costs,
                                           PlannerClock clock) {
  return std::make_unique<SearchPlanner>(config, std::move(road), std::move(costs),
                                         std::move(clock));
}

std::unique_ptr<Planner> MakeSearchPlanner(const PlannerConfig& config,
                                           std::shared_ptr<const map::ReferenceLine> line,
                                           std::shared_ptr<const cost::CostSet> costs,
                                           PlannerClock clock) {
  return MakeSearchPlanner(config, ConfiguredRoad(config, std::move(line)), std::move(costs),
                           std::move(clock));
}

}  // namespace frenetic::plan

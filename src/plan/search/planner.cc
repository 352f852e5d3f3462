// The `search` planner. Werling, Ziegler, Kammel, Thrun, "Optimal Trajectory Generation for
// Dynamic Street Scenarios in a Frenet Frame", ICRA 2010: 1-D longitudinal and lateral bundles,
// every pair scored, lazy hard checks in cost order, a backup that always exists. This file is
// the cycle's orchestration; the stages live in search/*.h (context, lattice, scoring,
// limits, collisions, selection, least_harm, refiner, fallback, continuity) and share one
// Workspace.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "frenetic/plan/search_planner.h"
#include "frenetic/traj/frenet.h"
#include "plan/predictor.h"
#include "plan/predictor_options.h"
#include "plan/search/collisions.h"
#include "plan/search/context.h"
#include "plan/search/continuity.h"
#include "plan/search/fallback.h"
#include "plan/search/lattice.h"
#include "plan/search/least_harm.h"
#include "plan/search/limits.h"
#include "plan/search/refiner.h"
#include "plan/search/scoring.h"
#include "plan/search/selection.h"
#include "plan/search/settings.h"
#include "plan/search/tracer.h"
#include "plan/search/workspace.h"

namespace frenetic::plan {
namespace {

using search::Finite;
using traj::FrenetState;
using traj::FrenetTrajectory;

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
  po.follow_gap = config.value("prediction.follow_gap");
  po.merge_time = config.value("prediction.merge_time");
  po.lane_width = cfg.road.lane_width;
  po.num_lanes = cfg.road.num_lanes;
  po.car_length = cfg.check.car_length;
  po.car_width = cfg.check.car_width;
  // The horizons the context samples predictions over, from the kept points' end.
  po.future_horizon = std::max(cfg.score.horizon, cfg.check.horizon) + 1.0;
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
        limits_(cfg_, *line_, ws_),
        collisions_(cfg_, ws_),
        tracer_(cfg_, ws_, scorer_, *costs_, *line_, *predictor_),
        selection_(cfg_, ws_, scorer_, limits_, collisions_, tracer_, timer_),
        least_harm_(cfg_, ws_, scorer_, limits_, collisions_, timer_),
        refiner_(cfg_, config.refine_algorithm(), ws_, lattice_, scorer_, limits_, collisions_,
                 timer_),
        continuity_(cfg_, *line_, ws_, timer_),
        lane_ends_(*road_) {
    per_term_.assign(costs_->size(), 0.0);
    result_.x.reserve(cfg_.continuity.output_points + 1);
    result_.y.reserve(cfg_.continuity.output_points + 1);
    result_.summary.winner_costs.resize(costs_->size());
    for (int i = 0; i < costs_->size(); ++i) {
      result_.summary.winner_costs[i].name = costs_->name(i);
      result_.summary.winner_costs[i].weight = costs_->weight(i);
    }
    Reset();
  }

  std::string_view name() const override { return "search"; }

  void set_trace(CycleTrace* trace, int max_candidates) override {
    tracer_.Attach(trace, max_candidates);
  }
  void set_least_harm(bool on) override { least_harm_on_ = on; }

  void Reset() override {
    continuity_.Reset();
    ws_.have_prev_traj = false;
    ws_.prev_target_lane = -1;
    ws_.lane_before_change = -1;
    ws_.time_since_change = 1e9;
    sim_time_ = NAN;
    ws_.none_passed_last = false;
    predictor_->Reset();
  }

  const PlanResult& Plan(const Telemetry& t) override {
    timer_.Start();
    PlanSummary& sum = result_.summary;
    ResetSummary(sum);
    result_.status = PlanStatus::kOk;
    result_.x.clear();
    result_.y.clear();
    tracer_.Clear();

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
      kept = std::min(cfg_.continuity.keep_points, continuity_.plan_n() - consumed);
      start = continuity_.KeepPoints(consumed, kept, &elapsed);
    } else {
      continuity_.Desync();
      ws_.have_prev_traj = false;
      start = continuity_.MeasuredStart(t, ego_ok);
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
    predictor_->Observe(lane_ends_.With(t.sensor_fusion, start.s), start.s, sim_time_, t.futures,
                        start.d);
    search::BuildContext(cfg_, *road_, *predictor_, ws_);
    continuity_.SetXyPrefix(limits_);
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
      const bool none_passed_before = ws_.none_passed_last;
      found = selection_.Select(none_passed_before, &sum, &check_cut);
      ws_.none_passed_last = !found && !check_cut;
      if (!found && !check_cut && least_harm_on_) {
        least_harm = least_harm_.Choose(&check_cut, none_passed_before);
      }
      if (check_cut) {
        over_budget = true;
        sum.deadline_stage = PlanSummary::Stage::kCheck;
      }
      sum.ms_check = Elapsed() - t_check;
      // A swerve into a goal region is taken as it is: its checks end at the region
      // (Workspace::CheckTicks), the refinement's run over the whole horizon; and a pass, which
      // the refinement's single move cannot express.
      if (found && cfg_.refine.enabled && refiner_.available() &&
          !ws_.lat[ws_.winner_lat].swerve() && !ws_.lat[ws_.winner_lat].pass()) {
        // A pinned (infinite) cycle budget always leaves room; a pinned refinement budget
        // asks for none beyond the cycle's.
        const double refine_ms = std::isfinite(cfg_.refine.budget_ms) ? cfg_.refine.budget_ms : 0;
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
      ws_.FillTicks(ws_.winner);
      sum.winner_lane = ws_.lat[ws_.winner_lat].lane;
      sum.winner_end_speed = ws_.winner.lon.At(ws_.winner.lon.duration).v;
      sum.winner_duration = ws_.winner.lon.duration;
      RecordDecision(sum.winner_lane);
      continuity_.RememberWinner(sum.winner_lane, sum.winner_end_speed, sum.winner_duration);
      EvaluateWinnerCosts();
    } else if (over_budget && search::ContinuePrevious(ws_, collisions_)) {
      // Cut short (a loaded machine): last cycle's winner, still collision-free, is a better
      // answer than braking, which invites the car behind into the ego's boot.
      sum.winner_lane = ws_.prev_target_lane;
    } else {
      search::BuildFallback(cfg_, ws_, collisions_);
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
  search::LimitChecker limits_;
  search::CollisionChecker collisions_;
  search::Tracer tracer_;
  search::Selection selection_;
  search::LeastHarm least_harm_;
  search::Refiner refiner_;
  search::Continuity continuity_;
  search::LaneEnds lane_ends_;

  std::vector<double> per_term_;   // unweighted term values (EvaluateWinnerCosts)
  double sim_time_ = NAN;          // s, simulated time of the current message (NaN: unknown)
  bool least_harm_on_ = true;      // set_least_harm
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

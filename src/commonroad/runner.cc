#include "frenetic/commonroad/runner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/goal_frenet.h"
#include "frenetic/commonroad/observation.h"
#include "frenetic/commonroad/path_time.h"
#include "frenetic/commonroad/road_builder.h"
#include "frenetic/cost/goal_region.h"
#include "frenetic/plan/telemetry.h"
#include "frenetic/units.h"

namespace frenetic::commonroad {
namespace {

// The planner's limits sit this far inside the verdict's: it measures them on its own path,
// which the KS ego follows to within centimetres, not exactly.
constexpr double kLimitMargin = 0.85;
// The planner's top speed: this share of the vehicle's v_max (the path's speed is checked on its
// 0.02 s points, which the KS ego tracks to within centimetres per second).
constexpr double kTopSpeedShare = 0.97;

// The step after which the run ends: the last goal window's end, else the last step an
// obstacle is recorded at (at least 10 s), capped.
int EndStep(const Scenario& sc, const PlanningProblem& p) {
  int end = -1;
  bool untimed = false;
  for (const GoalState& g : p.goals) {
    if (g.time) {
      end = std::max(end, g.time->end);
    } else {
      untimed = true;
    }
  }
  if (untimed || end < 0) {
    int last = p.initial.time_step + static_cast<int>(std::lround(10.0 / sc.dt));
    for (const Obstacle& o : sc.obstacles) {
      if (o.role == ObstacleRole::kDynamic) last = std::max(last, o.LastStep());
    }
    end = std::max(end, last);
  }
  const int most = static_cast<int>(std::lround(std::clamp(kMaxSeconds / sc.dt, 1.0, 1e6)));
  return std::min(end, p.initial.time_step + most);
}

// Signed Menger curvature of three points (left positive).
double Curvature(double x1, double y1, double x2, double y2, double x3, double y3) {
  const double ax = x2 - x1, ay = y2 - y1, bx = x3 - x2, by = y3 - y2, cx = x3 - x1, cy = y3 - y1;
  const double den = std::sqrt((ax * ax + ay * ay) * (bx * bx + by * by) * (cx * cx + cy * cy));
  return den > 1e-12 ? 2.0 * (ax * by - ay * bx) / den : 0.0;
}

}  // namespace

bool PlanMissesGoal(const plan::PlanResult& res) {
  for (const plan::CostTermValue& v : res.summary.winner_costs) {
    if (v.name == "goal") return v.weight > 0 && v.value > 0;
  }
  return false;
}

KsState FollowPath(const KsState& ego, const std::vector<double>& x, const std::vector<double>& y,
                   double dt, const VehicleParams& vp, double phase) {
  constexpr double kHeadingGain = 0.5;  // of the heading error
  constexpr double kCrossGain = 1.0;    // 1/s: Stanley's k
  constexpr double kAlongGain = 1.0;    // 1/s: speed per m of along-track error
  constexpr double kMinSpan = 0.5;      // m: the shortest chord the path's direction is taken on
  // The point dt in: point j, or between it and the next (a step that is not a whole number
  // of ticks, or a path whose points lie a phase off the ticks).
  const PathIndex in = PathIndexAt(dt - phase);
  const int j = in.lo, between = in.frac > 0 ? 1 : 0;
  const int n = static_cast<int>(std::min(x.size(), y.size()));
  if (n < j + 3 + between) return SimulateKs(ego, {0, 0}, dt, vp);
  const double xj = PathValueAt(x, in), yj = PathValueAt(y, in);
  // The neighbours the heading and curvature are measured over: the next points, or farther
  // ones at a crawl (points millimetres apart give no direction).
  int a = std::max(0, j - 1), b = j + 1 + between;
  while (std::hypot(x[b] - x[a], y[b] - y[a]) < kMinSpan && (a > 0 || b + 1 < n)) {
    if (a > 0) --a;
    if (b + 1 < n) ++b;
  }
  const double theta = std::atan2(y[b] - y[a], x[b] - x[a]);
  const double speed = std::hypot(x[b] - x[a], y[b] - y[a]) / ((b - a) * plan::kTickSeconds);
  const double kappa = Curvature(x[a], y[a], xj, yj, x[b], y[b]);
  const double l_wb = vp.Wheelbase();
  const double delta_ff = std::atan(l_wb * kappa);
  // The centre moves at the slip angle beta off the vehicle's axis.
  const double beta = std::atan(vp.b * std::tan(delta_ff) / l_wb);
  const double psi_ff = theta - beta;
  const double v_ff = speed * std::cos(beta);
  // Within the steering rate and acceleration limits, and the friction circle a^2 + (v psi')^2
  // <= a_max^2 at the step's start (with kLimitMargin to spare).
  const double yaw_acc = ego.velocity * ego.velocity / l_wb * std::tan(ego.steering_angle);
  const double a_room = std::sqrt(std::max(0.0, std::pow(kLimitMargin * vp.a_max, 2) - yaw_acc * yaw_acc));
  auto clip = [&](KsInput w) {
    w.steering_rate = std::clamp(w.steering_rate, vp.steering_rate_min, vp.steering_rate_max);
    w.acceleration = std::clamp(w.acceleration, -a_room,
                                std::min(a_room, kLimitMargin * vp.MaxAcceleration(ego.velocity)));
    return w;
  };
  const KsInput ff = clip({(delta_ff - ego.steering_angle) / dt, (v_ff - ego.velocity) / dt});
  const KsState pred = SimulateKs(ego, ff, dt, vp);
  // Errors of the predicted state against the path's point: cross-track (left positive) and
  // along-track (ahead positive) in the path's direction, and the heading's.
  const double ex = xj - pred.x, ey = yj - pred.y;
  const double c = std::cos(theta), sn = std::sin(theta);
  const double along = ex * c + ey * sn, cross = -(-ex * sn + ey * c);
  const double heading_err = WrapAngle(psi_ff - pred.orientation);
  // Within the steering limits, and the friction circle's lateral part: v^2 tan(delta) / l_wb
  // <= a_max at the step's end speed.
  const double v_end = std::max(ego.velocity, v_ff);
  const double max_steer =
      std::min(kLimitMargin * std::min(vp.steering_max, -vp.steering_min),
               std::atan(kLimitMargin * vp.a_max * l_wb / std::max(v_end * v_end, 1e-6)));
  const double delta_cmd = std::clamp(delta_ff + kHeadingGain * heading_err -
                                          std::atan(kCrossGain * cross / std::max(ego.velocity, 1.0)),
                                      -max_steer, max_steer);
  // Never backwards: the planner's paths do not reverse, and a vehicle that rolls back at a
  // stop (ahead of a path point that barely moves) turns the other way as it steers.
  const double v_cmd = std::max(0.0, v_ff + kAlongGain * along);
  const KsInput u = clip({(delta_cmd - ego.steering_angle) / dt, (v_cmd - ego.velocity) / dt});
  return SimulateKs(ego, u, dt, vp);
}

const char* ToString(PredictionMode mode) {
  return mode == PredictionMode::kRecorded ? "recorded" : "constant-velocity";
}

StatusOr<PredictionMode> ParsePredictionMode(std::string_view text) {
  if (text == "recorded") return PredictionMode::kRecorded;
  if (text == "constant-velocity") return PredictionMode::kConstantVelocity;
  return Status::Error("unknown prediction '" + std::string(text) +
                       "' (known: recorded, constant-velocity)");
}

Status RunOptions::Validate() const {
  if (vehicle_type < 1 || vehicle_type > 3) {
    return Status::Error("vehicle type must be 1, 2 or 3, got " + std::to_string(vehicle_type));
  }
  return Status::Ok();
}

StatusOr<plan::PlannerConfig> CommonRoadConfig(plan::PlannerConfig c, const VehicleParams& vp,
                                               PredictionMode /*prediction*/) {
  c.PinDeadlines();
  const std::pair<const char*, double> values[] = {
      {"limits.max_speed_mph", kTopSpeedShare * vp.v_max / units::kMphToMps},
      {"check.ego_length", vp.length},
      {"check.ego_width", vp.width},
      {"vehicle.wheelbase", vp.Wheelbase()},
      {"vehicle.max_steer", kLimitMargin * vp.steering_max},
      {"vehicle.max_steer_rate", kLimitMargin * vp.steering_rate_max},
      {"vehicle.max_accel", kLimitMargin * vp.a_max},
      {"vehicle.switch_speed", vp.v_switch},
  };
  for (const auto& [key, value] : values) {
    if (Status st = c.Set(key, value); !st.ok()) return st;
  }
  return c;
}

ScenarioRun RunScenario(const Scenario& sc, const plan::PlannerConfig& config,
                        const RunOptions& options) {
  ScenarioRun out;
  out.source = sc.source;
  out.benchmark_id = sc.benchmark_id;
  const VehicleParams vp = VehicleParamsForType(options.vehicle_type).ok()
                               ? *VehicleParamsForType(options.vehicle_type)
                               : VehicleParams();
  const VerdictChecker checker(sc, vp);
  const double dt = sc.dt;
  for (const PlanningProblem& problem : sc.problems) {
    ProblemRun run;
    run.problem_id = problem.id;
    if (checker.StartFailure(problem)) {
      // Infeasible at start: the initial state already collides or lies off the road. Nothing
      // is planned; the verdict reports it apart.
      KsState ego;
      ego.time_step = problem.initial.time_step;
      ego.x = problem.initial.position.x;
      ego.y = problem.initial.position.y;
      ego.velocity = problem.initial.velocity.value_or(0.0);
      ego.orientation = problem.initial.orientation.value_or(0.0);
      ego.steering_angle = problem.initial.steering_angle.value_or(0.0);
      run.trajectory.push_back(ego);
      run.stop_reason = "infeasible_at_start";
      run.verdict = checker.Check(problem, run.trajectory);
      if (options.on_problem_end) options.on_problem_end(problem, run);
      out.problems.push_back(std::move(run));
      continue;
    }
    auto built = BuildRoad(sc, problem);
    if (!built.ok()) {
      run.road = built.status();
      run.verdict = checker.Check(problem, run.trajectory);
      if (options.on_problem_end) options.on_problem_end(problem, run);
      out.problems.push_back(std::move(run));
      continue;
    }
    const map::Road& road = *built->road;
    const map::ReferenceLine& line = road.line();
    run.lanes = road.num_lanes();
    run.road_length = line.length();
    run.route = built->route;
    const std::vector<FrenetGoal> regions = FrenetGoals(sc, problem, line);
    // The planner's regions: one reaching the map's end (closed: the verdict holds the whole box
    // to the lanelets, while the planner's lanes run on) ends half the ego's length before it,
    // so that the ego's centre in it keeps its front on the map when it must wait there for the
    // window to open. (The run ends past the regions themselves.)
    std::vector<FrenetGoal> goals = regions;
    const double last = built->map_end - 0.5 * vp.length;
    const double start_s = line.ToFrenet(problem.initial.position.x, problem.initial.position.y).s;
    for (FrenetGoal& g : goals) {
      if (std::isfinite(g.region.s_hi) && g.region.s_hi > last) {
        g.region.s_hi = std::max(g.region.s_lo, last);
      }
      g.region.across_open = AcrossOpen(road, start_s, g.region);
    }
    // The top speed is the vehicle's (CommonRoadConfig); the lanes' signs limit it further.
    const plan::PlannerConfig& problem_config = config;
    auto planner = plan::MakePlanner("search", problem_config, built->road);
    if (!planner.ok()) {
      run.road = planner.status();
      if (options.on_problem_end) options.on_problem_end(problem, run);
      out.problems.push_back(std::move(run));
      continue;
    }
    for (const FrenetGoal& g : goals) {
      const cost::GoalRegion& r = g.region;
      spdlog::debug("{} #{}: goal s [{:.2f}, {:.2f}] d [{:.2f}, {:.2f}] slope {:.4f} steps [{}, {}] v [{}, {}] h [{}, {}]",
                    sc.benchmark_id, problem.id, r.s_lo, r.s_hi, r.d_lo, r.d_hi, r.d_slope, r.t_lo, r.t_hi,
                    r.v_lo, r.v_hi, r.h_lo, r.h_hi);
    }
    for (int l = 0; l < road.num_lanes(); ++l) {
      const map::Road::Span a = road.LaneAt(l, start_s);
      spdlog::debug("{} #{}: lane {} [{:.2f}, {:.2f}] at the start, s [{:.1f}, {:.1f}]",
                    sc.benchmark_id, problem.id, l, a.left, a.right, road.LaneBegin(l),
                    road.LaneEnd(l));
    }
    const int start = problem.initial.time_step, end = EndStep(sc, problem);
    KsState ego;
    ego.time_step = start;
    ego.x = problem.initial.position.x;
    ego.y = problem.initial.position.y;
    ego.velocity = problem.initial.velocity.value_or(0.0);
    if (problem.initial.orientation) {
      ego.orientation = *problem.initial.orientation;
    } else {
      ego.orientation = line.At(line.ToFrenet(ego.x, ego.y).s).heading;
    }
    ego.steering_angle = problem.initial.steering_angle.value_or(0.0);
    run.trajectory.push_back(ego);
    plan::Telemetry t;
    std::vector<double> path_x, path_y;
    double phase = 0;  // s: path_x[0] lies this much later than a tick on (path_time.h)
    std::optional<Rescue> rescue;
    if (options.rescue) {
      RescueOptions rescue_options;
      rescue_options.retry_states = options.rescue_retry_states;
      // The lane changes the planner's predictor reads from lateral motion (none without its
      // manoeuvres).
      rescue_options.lateral_threshold = config.int_value("prediction.manoeuvres") != 0
                                             ? config.value("prediction.lateral_threshold")
                                             : 0.0;
      rescue.emplace(road, vp, dt, rescue_options);
      rescue->SetRoadArea(&checker.road());
    }
    run.stop_reason = "time";
    const GoalTest goal(sc, problem.goals);
    // A state that meets a goal ends the run after it. The initial state ends it one step on:
    // CommonRoad's feasibility check fails on a trajectory of a single state.
    const bool met_at_start = goal.MeetsAny(ego);
    for (int k = start; k < end; ++k) {
      if (k > start && (met_at_start || goal.MeetsAny(ego))) {
        run.stop_reason = "goal";
        break;
      }
      // The telemetry of step k.
      t.x = ego.x;
      t.y = ego.y;
      t.yaw = ego.orientation;
      t.speed = ego.velocity;
      const map::FrenetPoint fe = line.ToFrenet(ego.x, ego.y);
      if (PassedEveryGoal(regions, fe.s)) {
        run.stop_reason = "goal_passed";
        break;
      }
      t.s = fe.s;
      t.d = fe.d;
      t.previous_path_x = path_x;
      t.previous_path_y = path_y;
      Observe(sc, k, line, fe.s, options.prediction, &t);
      t.goals.clear();
      for (const FrenetGoal& g : goals) {
        cost::GoalRegion r = Inset(g.region);
        // Time steps to seconds from now, a little inside the window (the verdict looks at
        // whole steps; a window of one step stays one instant).
        const double in = g.timed_lo && g.timed_hi
                              ? InsetBy(r.t_lo * dt, r.t_hi * dt, kTimeInset * dt) : 0.0;
        if (g.timed_lo) r.t_lo = (r.t_lo - k) * dt + in;
        if (g.timed_hi) r.t_hi = (r.t_hi - k) * dt - in;
        t.goals.push_back(r);
      }
      const bool tracing = spdlog::should_log(spdlog::level::trace);
      plan::CycleTrace trace;
      if (tracing) (*planner)->set_trace(&trace, 200);
      // A way the rescue holds stands in for the planner's least harm (Rescue::Holds): the
      // planner then skips that choice when no candidate passes. Its time counts.
      bool way_holds = false;
      double holds_ms = 0;
      if (rescue) {
        const auto p0 = std::chrono::steady_clock::now();
        rescue->Predict(t);
        way_holds = rescue->Holds(ego, t.goals);
        holds_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - p0)
                .count();
      }
      const CycleInput input{problem, k, built->road, problem_config, t, ego, !way_holds};
      if (options.on_cycle) options.on_cycle(input);
      const auto t0 = std::chrono::steady_clock::now();
      (*planner)->set_least_harm(!way_holds);
      const plan::PlanResult& res = (*planner)->Plan(t);
      // A path planned afresh from the ego's state (none of the previous points kept: it did
      // not match the planner's own) starts a tick on, on the ticks.
      if (res.summary.points_kept == 0) phase = 0;
      if (options.on_plan) options.on_plan(input, res);
      if (tracing) {
        // The best candidate of each lane: its cost by term and what became of it.
        std::vector<bool> seen(16, false);
        for (const plan::CandidateTrace& c : trace.candidates) {
          if (c.lane < 0 || c.lane >= 16 || (seen[c.lane] && !c.checked)) continue;
          seen[c.lane] = true;
          std::string terms;
          for (const plan::CostTermValue& v : c.costs) {
            if (v.weight * v.value > 0.01) terms += fmt::format(" {} {:.2f}", v.name, v.weight * v.value);
          }
          spdlog::trace("  lane {} v_end {:.1f} T {:.1f} cost {:.2f} reject {} car {} at {:.1f} s:{}",
                        c.lane, c.end_speed, c.duration, c.total_cost,
                        c.reject >= 0 ? plan::ToString(static_cast<plan::Reject>(c.reject)) : "-",
                        c.reject_car, c.reject_time, terms);
        }
        (*planner)->set_trace(nullptr, 0);
      }
      // The planner's path against the predictions: when it hits a car, the rescue's way if
      // one lasts longer; when it misses the goal for good, the rescue's way to it if there is
      // one.
      std::optional<KsInput> rescue_input;
      double rescue_ms = holds_ms;
      if (rescue) {
        const auto r0 = std::chrono::steady_clock::now();
        rescue->SetPathPhase(phase);
        const RescueStep step = rescue->Answer(
            t, res.x, res.y, ego, res.status == plan::PlanStatus::kFallbackUsed, PlanMissesGoal(res));
        rescue_ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - r0)
                .count();
        rescue_input = step.input;
        if (step.why == RescueStep::Why::kNoPath) {
          spdlog::debug("{} #{} step {}: no candidate passes; the rescue's way stands in "
                        "({:.3f} ms)",
                        sc.benchmark_id, problem.id, k, rescue_ms);
        } else if (step.why == RescueStep::Why::kHit) {
          spdlog::debug("{} #{} step {}: the planner's path hits a car at step {}; rescue "
                        "({:.3f} ms) {}",
                        sc.benchmark_id, problem.id, k, step.hit, rescue_ms,
                        rescue_input ? "drives its way" : "found no way");
        } else if (step.why == RescueStep::Why::kGoal) {
          spdlog::debug("{} #{} step {}: the planner's path misses a closing goal; rescue "
                        "({:.3f} ms) {}",
                        sc.benchmark_id, problem.id, k, rescue_ms,
                        rescue_input ? "drives a way to it" : "found no way to it");
        }
      }
      const double ms =
          holds_ms +
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      RunCycle cyc;
      cyc.step = k;
      cyc.plan_ms = options.timing ? ms : 0.0;
      cyc.rescue_ms = options.timing ? rescue_ms : 0.0;
      cyc.candidates = res.summary.candidates_generated;
      cyc.checked = res.summary.candidates_checked;
      cyc.status = res.status;
      // The ego drives dt along the plan; the planner gets the whole points left over (their
      // phase off the ticks carried to the next step: path_time.h).
      if (rescue_input) {
        // The way's input, exactly (the search simulated it); the planner gets the rest of the
        // way as its previous path.
        cyc.rescued = true;
        rescue->Points(ego, &path_x, &path_y);
        phase = 0;  // the way's points start at the ego
        const size_t used = static_cast<size_t>(TicksConsumed(dt, &phase));
        path_x.erase(path_x.begin(), path_x.begin() + std::min(used, path_x.size()));
        path_y.erase(path_y.begin(), path_y.begin() + std::min(used, path_y.size()));
        ego = SimulateKs(ego, *rescue_input, dt, vp);
        ego.time_step = k + 1;
      } else {
        ego = FollowPath(ego, res.x, res.y, dt, vp, phase);
        ego.time_step = k + 1;
        const size_t used = static_cast<size_t>(TicksConsumed(dt, &phase));
        const size_t j =
            std::min<size_t>(std::max<size_t>(used, 1) - 1, res.x.empty() ? 0 : res.x.size() - 1);
        if (!res.x.empty()) cyc.tracking_error = std::hypot(ego.x - res.x[j], ego.y - res.y[j]);
        path_x.assign(res.x.begin() + std::min(used, res.x.size()), res.x.end());
        path_y.assign(res.y.begin() + std::min(used, res.y.size()), res.y.end());
      }
      run.trajectory.push_back(ego);
      // A collision or a box off the road fails the problem whatever follows: the run ends.
      if (checker.CollisionAt(ego)) {
        run.stop_reason = "collision";
      } else if (checker.OffRoadAt(ego)) {
        run.stop_reason = "off_road";
      }
      std::string why;
      for (int q = 0; q < static_cast<int>(plan::Reject::kCount); ++q) {
        if (res.summary.rejections[q] > 0) {
          why += std::string(" ") + plan::ToString(static_cast<plan::Reject>(q)) + " " +
                 std::to_string(res.summary.rejections[q]);
        }
      }
      spdlog::debug("{} #{} step {}: {} {:.3f} ms cands {} checked {} ({}) lane {} v_end {:.2f} | ego s {:.2f} d {:.2f} v {:.2f} delta {:.3f} track {:.3f}",
                    sc.benchmark_id, problem.id, k, plan::ToString(res.status), ms,
                    res.summary.candidates_generated, res.summary.candidates_checked, why,
                    res.summary.winner_lane, res.summary.winner_end_speed, fe.s, fe.d,
                    ego.velocity, ego.steering_angle, cyc.tracking_error);
      run.cycles.push_back(cyc);
      run.computation_s += cyc.plan_ms / 1000.0;
      if (run.stop_reason != "time") break;
    }
    if (run.stop_reason == "time" && goal.MeetsAny(ego)) run.stop_reason = "goal";
    run.verdict = checker.Check(problem, run.trajectory);
    if (options.on_problem_end) options.on_problem_end(problem, run);
    out.problems.push_back(std::move(run));
  }
  return out;
}

}  // namespace frenetic::commonroad

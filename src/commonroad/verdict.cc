#include "frenetic/commonroad/verdict.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "frenetic/check.h"

namespace frenetic::commonroad {

const char* ToString(FailureKind kind) {
  switch (kind) {
    case FailureKind::kTrajectory: return "trajectory";
    case FailureKind::kStart: return "start";
    case FailureKind::kGoal: return "goal";
    case FailureKind::kCollision: return "collision";
    case FailureKind::kOffRoad: return "off_road";
    case FailureKind::kSteeringAngle: return "steering_angle";
    case FailureKind::kSteeringRate: return "steering_rate";
    case FailureKind::kVelocity: return "velocity";
    case FailureKind::kAcceleration: return "acceleration";
    case FailureKind::kFrictionCircle: return "friction_circle";
    case FailureKind::kDynamics: return "dynamics";
  }
  return "unknown";
}

const Failure* Verdict::Find(FailureKind kind) const {
  for (const Failure& f : failures) {
    if (f.kind == kind) return &f;
  }
  return nullptr;
}

std::string Verdict::Summary() const {
  std::string out;
  if (infeasible_at_start) {
    const Failure& f = *infeasible_at_start;
    return "infeasible at start: " + std::string(ToString(f.kind)) + " at step " +
           std::to_string(f.step) + " (" + f.detail + ")";
  }
  if (solved) {
    out = "solved: goal at step " + std::to_string(*goal_step);
    return out;
  }
  out = "failed:";
  for (size_t i = 0; i < failures.size(); ++i) {
    const Failure& f = failures[i];
    out += (i ? "; " : " ") + std::string(ToString(f.kind)) + " at step " +
           std::to_string(f.step) + " (" + f.detail + ")";
  }
  return out;
}

Status VerdictOptions::Validate() const {
  const struct {
    const char* name;
    double value;
  } values[] = {{"road_tolerance", road_tolerance},
                {"open_end_margin", open_end_margin},
                {"position_tolerance", position_tolerance},
                {"orientation_tolerance", orientation_tolerance},
                {"limit_tolerance", limit_tolerance},
                {"start_position_tolerance", start_position_tolerance},
                {"start_orientation_tolerance", start_orientation_tolerance},
                {"start_velocity_tolerance", start_velocity_tolerance}};
  for (const auto& v : values) {
    if (!std::isfinite(v.value) || v.value < 0) {
      return Status::Error(std::string("verdict option ") + v.name +
                           " must be finite and >= 0");
    }
  }
  if (integration_substeps < 1 || integration_substeps > 10000) {
    return Status::Error("verdict option integration_substeps must be in [1, 10000]");
  }
  return Status::Ok();
}

namespace {

std::string Fmt(const char* format, double a, double b = 0, double c = 0, double d = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c, d);
  return buffer;
}

// Where obstacle o was when it first came into the scene during the trajectory, up to and
// including step `until` (its collision), seen from the ego then (centre to centre along the
// ego's heading): "; in the scene from step 8, 9.8 m behind the ego then". *entered_s: the
// seconds from then to `until`, when that was after the trajectory's first state. A car that
// enters the scene (a recording's view) close behind the ego gives it little time to react. An
// obstacle there at the start, gone and back (a set-based one with gaps), counts from the start.
std::string FirstSeen(const Obstacle& o, std::span<const KsState> traj, int until, double dt,
                      std::optional<double>* entered_s) {
  for (const KsState& e : traj) {
    if (e.time_step > until) break;
    const std::optional<ShapeGroup> occupancy = o.OccupancyAt(e.time_step);
    if (!occupancy) continue;
    const std::optional<State> state = o.StateAt(e.time_step);
    const Vec2 at = state ? state->position : occupancy->Centroid();
    const double dx = at.x - e.x, dy = at.y - e.y;
    const double c = std::cos(e.orientation), sn = std::sin(e.orientation);
    const double ahead = dx * c + dy * sn;  // along the ego's heading, centre to centre
    const bool from_start = e.time_step == traj.front().time_step;
    // Rounded to a nanosecond: 0.3, not 0.30000000000000004, in the JSON.
    if (!from_start) *entered_s = std::round((until - e.time_step) * dt * 1e9) / 1e9;
    std::string out = from_start ? std::string("; in the scene from the start, ")
                                 : "; in the scene from step " + std::to_string(e.time_step) + ", ";
    if (std::abs(ahead) < 0.05) return out + "beside the ego then";
    return out + Fmt(ahead < 0 ? "%.1f m behind the ego then" : "%.1f m ahead of the ego then",
                     std::abs(ahead));
  }
  return "";
}

bool Finite(const KsState& s) {
  return std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.steering_angle) &&
         std::isfinite(s.velocity) && std::isfinite(s.orientation);
}

// Which parts of a goal state a state meets.
struct GoalParts {
  bool time = true, position = true, velocity = true, orientation = true;
  int Count() const { return time + position + velocity + orientation; }
  bool All() const { return Count() == 4; }
};

GoalParts EvaluateGoal(const GoalState& goal, const KsState& s,
                       const std::map<int, std::vector<Vec2>>& lanelet_polygons) {
  GoalParts parts;
  if (goal.time) parts.time = goal.time->Contains(s.time_step);
  if (goal.HasPosition()) {
    const Vec2 p{s.x, s.y};
    parts.position = std::any_of(goal.shapes.begin(), goal.shapes.end(),
                                 [&](const Shape& shape) { return shape.Contains(p); });
    for (int id : goal.lanelets) {
      if (parts.position) break;
      const auto it = lanelet_polygons.find(id);
      parts.position = it != lanelet_polygons.end() && PolygonContains(it->second, p);
    }
  }
  if (goal.velocity) parts.velocity = goal.velocity->Contains(s.velocity);
  if (goal.orientation) {
    parts.orientation =
        AngleInInterval(s.orientation, goal.orientation->start, goal.orientation->end);
  }
  return parts;
}

std::map<int, std::vector<Vec2>> GoalLaneletPolygons(const Scenario& scenario,
                                                     std::span<const GoalState> goals) {
  std::map<int, std::vector<Vec2>> polygons;
  for (const GoalState& g : goals) {
    for (int id : g.lanelets) {
      if (polygons.count(id)) continue;
      if (const Lanelet* l = scenario.FindLanelet(id)) polygons[id] = l->Polygon();
    }
  }
  return polygons;
}

// Why no state met a goal: per goal state, the parts missing at the step that met the most.
std::string GoalMissDetail(std::span<const GoalState> goals, std::span<const KsState> traj,
                           const std::map<int, std::vector<Vec2>>& polygons) {
  std::string out = "no state meets a goal state";
  for (size_t g = 0; g < goals.size() && g < 3; ++g) {
    const GoalState& goal = goals[g];
    size_t best = 0;
    GoalParts best_parts = EvaluateGoal(goal, traj[0], polygons);
    for (size_t i = 1; i < traj.size(); ++i) {
      const GoalParts parts = EvaluateGoal(goal, traj[i], polygons);
      if (parts.Count() > best_parts.Count()) {
        best = i;
        best_parts = parts;
      }
    }
    const KsState& s = traj[best];
    out += "; goal " + std::to_string(g) + " closest at step " + std::to_string(s.time_step) +
           ":";
    if (!best_parts.time) {
      out += " time not in [" + std::to_string(goal.time->start) + ", " +
             std::to_string(goal.time->end) + "]";
    }
    if (!best_parts.position) out += Fmt(" position (%.2f, %.2f) outside the region", s.x, s.y);
    if (!best_parts.velocity) {
      out += Fmt(" velocity %.2f m/s not in [%.2f, %.2f]", s.velocity, goal.velocity->start,
                 goal.velocity->end);
    }
    if (!best_parts.orientation) {
      out += Fmt(" orientation %.3f rad not in [%.3f, %.3f]", s.orientation,
                 goal.orientation->start, goal.orientation->end);
    }
  }
  if (goals.size() > 3) out += "; ...";
  return out;
}

}  // namespace

bool MeetsGoal(const Scenario& scenario, const GoalState& goal, const KsState& state) {
  return GoalTest(scenario, {&goal, 1}).MeetsAny(state);
}

GoalTest::GoalTest(const Scenario& scenario, std::span<const GoalState> goals)
    : goals_(goals.begin(), goals.end()), polygons_(GoalLaneletPolygons(scenario, goals)) {}

bool GoalTest::MeetsAny(const KsState& state) const {
  return std::any_of(goals_.begin(), goals_.end(),
                     [&](const GoalState& g) { return EvaluateGoal(g, state, polygons_).All(); });
}

VerdictChecker::VerdictChecker(const Scenario& scenario, const VehicleParams& vehicle,
                               const VerdictOptions& options)
    : scenario_(&scenario),
      vehicle_(vehicle),
      options_(options),
      road_(RoadArea::Build(scenario.lanelets, options.road_tolerance, options.open_end_margin)) {
  FRENETIC_CHECK(options.Validate().ok());
}

Verdict VerdictChecker::Check(const PlanningProblem& problem,
                              std::span<const KsState> trajectory) const {
  Verdict verdict;
  verdict.problem_id = problem.id;
  std::vector<Failure> found;
  std::vector<bool> have(static_cast<int>(FailureKind::kDynamics) + 1, false);
  const auto fail = [&](FailureKind kind, int step, std::string detail,
                        std::optional<int> obstacle = std::nullopt,
                        std::optional<double> entered_s = std::nullopt) {
    if (have[static_cast<int>(kind)]) return;
    have[static_cast<int>(kind)] = true;
    found.push_back({kind, step, std::move(detail), obstacle, entered_s});
  };
  const auto finish = [&]() {
    std::stable_sort(found.begin(), found.end(), [](const Failure& a, const Failure& b) {
      return static_cast<int>(a.kind) < static_cast<int>(b.kind);
    });
    verdict.failures = std::move(found);
    verdict.solved = verdict.goal_step.has_value() && verdict.failures.empty();
    return verdict;
  };

  // The trajectory itself; the other checks see its valid prefix.
  if (trajectory.empty()) {
    fail(FailureKind::kTrajectory, problem.initial.time_step, "the trajectory has no state");
    fail(FailureKind::kGoal, problem.initial.time_step, "the trajectory has no state");
    return finish();
  }
  size_t valid = trajectory.size();
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const KsState& s = trajectory[i];
    if (!Finite(s)) {
      fail(FailureKind::kTrajectory, s.time_step, "a value is not finite");
      valid = i;
      break;
    }
    if (i > 0 && s.time_step != trajectory[i - 1].time_step + 1) {
      fail(FailureKind::kTrajectory, s.time_step,
           "time step " + std::to_string(s.time_step) + " follows step " +
               std::to_string(trajectory[i - 1].time_step));
      valid = i;
      break;
    }
  }
  const std::span<const KsState> traj = trajectory.first(valid);
  if (traj.empty()) {
    fail(FailureKind::kGoal, problem.initial.time_step, "no valid state");
    return finish();
  }

  // Start.
  const KsState& s0 = traj.front();
  const State& init = problem.initial;
  if (s0.time_step != init.time_step) {
    fail(FailureKind::kStart, s0.time_step,
         "starts at step " + std::to_string(s0.time_step) + ", the problem at step " +
             std::to_string(init.time_step));
  } else if (std::abs(s0.x - init.position.x) > options_.start_position_tolerance ||
             std::abs(s0.y - init.position.y) > options_.start_position_tolerance) {
    fail(FailureKind::kStart, s0.time_step,
         Fmt("starts at (%.3f, %.3f), the problem at (%.3f, %.3f)", s0.x, s0.y,
             init.position.x, init.position.y));
  } else if (init.orientation &&
             // Unwrapped, as the solution checker's np.allclose compares them: a first state
             // turned by a whole turn does not start where the problem does.
             !(std::abs(s0.orientation - *init.orientation) <=
               options_.start_orientation_tolerance)) {
    fail(FailureKind::kStart, s0.time_step,
         Fmt("starts with orientation %.4f rad, the problem with %.4f rad", s0.orientation,
             *init.orientation));
  } else if (init.velocity &&
             std::abs(s0.velocity - *init.velocity) > options_.start_velocity_tolerance) {
    fail(FailureKind::kStart, s0.time_step,
         Fmt("starts at %.3f m/s, the problem at %.3f m/s", s0.velocity, *init.velocity));
  }

  // Goal.
  const GoalTest goal(*scenario_, problem.goals);
  for (const KsState& s : traj) {
    if (goal.MeetsAny(s)) {
      verdict.goal_step = s.time_step;
      break;
    }
  }
  if (!verdict.goal_step) {
    fail(FailureKind::kGoal, traj.back().time_step,
         GoalMissDetail(problem.goals, traj, goal.polygons()));
  }

  // Collision and road, every state from the first to the last.
  for (const KsState& s : traj) {
    if (!have[static_cast<int>(FailureKind::kCollision)]) {
      if (std::optional<Failure> f = CollisionAt(s)) {
        if (const Obstacle* o = scenario_->FindObstacle(*f->obstacle_id); o != nullptr) {
          f->detail += FirstSeen(*o, traj, f->step, scenario_->dt, &f->entered_s);
        }
        fail(f->kind, f->step, std::move(f->detail), f->obstacle_id, f->entered_s);
      }
    }
    if (!have[static_cast<int>(FailureKind::kOffRoad)]) {
      if (std::optional<Failure> f = OffRoadAt(s)) fail(f->kind, f->step, std::move(f->detail));
    }
  }
  verdict.infeasible_at_start = StartFailure(problem);

  // Kinematic limits and the KS model.
  const VehicleParams& p = vehicle_;
  const double tol = options_.limit_tolerance;
  const double dt = scenario_->dt;
  for (size_t i = 0; i < traj.size(); ++i) {
    const KsState& s = traj[i];
    if (s.steering_angle < p.steering_min - tol || s.steering_angle > p.steering_max + tol) {
      fail(FailureKind::kSteeringAngle, s.time_step,
           Fmt("steering angle %.4f rad outside [%.3f, %.3f]", s.steering_angle,
               p.steering_min, p.steering_max));
    }
    if (s.velocity < p.v_min - tol || s.velocity > p.v_max + tol) {
      fail(FailureKind::kVelocity, s.time_step,
           Fmt("velocity %.3f m/s outside [%.2f, %.2f]", s.velocity, p.v_min, p.v_max));
    }
    if (i + 1 == traj.size()) break;
    const KsState& n = traj[i + 1];
    const KsInput u{(n.steering_angle - s.steering_angle) / dt, (n.velocity - s.velocity) / dt};
    if (u.steering_rate < p.steering_rate_min - tol ||
        u.steering_rate > p.steering_rate_max + tol) {
      fail(FailureKind::kSteeringRate, s.time_step,
           Fmt("steering rate %.4f rad/s to step %.0f outside [%.2f, %.2f]", u.steering_rate,
               n.time_step, p.steering_rate_min, p.steering_rate_max));
    }
    const double a_limit = p.MaxAcceleration(s.velocity);
    if (u.acceleration < -p.a_max - tol || u.acceleration > a_limit + tol) {
      fail(FailureKind::kAcceleration, s.time_step,
           Fmt("acceleration %.3f m/s^2 at %.2f m/s outside [%.2f, %.3f]", u.acceleration,
               s.velocity, -p.a_max, a_limit));
    }
    const double lateral = s.velocity * s.velocity / p.Wheelbase() * std::tan(s.steering_angle);
    if (std::hypot(u.acceleration, lateral) > p.a_max + tol) {
      fail(FailureKind::kFrictionCircle, s.time_step,
           Fmt("longitudinal %.3f and lateral %.3f m/s^2 exceed a_max %.2f m/s^2",
               u.acceleration, lateral, p.a_max));
    }
    if (!have[static_cast<int>(FailureKind::kDynamics)]) {
      const KsState sim = SimulateKs(s, u, dt, p, options_.integration_substeps);
      const Vec2 rear_sim = RearAxle(sim, p), rear_next = RearAxle(n, p);
      const double ex = std::abs(rear_sim.x - rear_next.x);
      const double ey = std::abs(rear_sim.y - rear_next.y);
      const double epsi = std::abs(WrapAngle(sim.orientation - n.orientation));
      if (ex > options_.position_tolerance || ey > options_.position_tolerance ||
          epsi > options_.orientation_tolerance) {
        fail(FailureKind::kDynamics, s.time_step,
             Fmt("one KS step from here misses step %.0f by %.3f m (x), %.3f m (y), %.4f rad",
                 n.time_step, ex, ey, epsi));
      }
    }
  }
  return finish();
}

std::optional<Failure> VerdictChecker::CollisionAt(const KsState& s) const {
  const VehicleParams& p = vehicle_;
  const double ego_radius = std::hypot(p.length, p.width) / 2;
  const Vec2 center{s.x, s.y};
  const auto box = BoxCorners(center, s.orientation, p.length, p.width);
  for (const Obstacle& o : scenario_->obstacles) {
    const std::optional<ShapeGroup> occupancy = o.OccupancyAt(s.time_step);
    if (!occupancy) continue;
    const bool near =
        std::any_of(occupancy->shapes.begin(), occupancy->shapes.end(), [&](const Shape& shape) {
          return Distance(shape.Centroid(), center) <= ego_radius + shape.BoundingRadius();
        });
    if (near && occupancy->Overlaps(box)) {
      const std::optional<State> state = o.StateAt(s.time_step);
      const Vec2 at = state ? state->position : occupancy->Centroid();
      return Failure{FailureKind::kCollision, s.time_step,
                     "the ego overlaps obstacle " + std::to_string(o.id) + " (" + o.type +
                         Fmt(") at (%.2f, %.2f)", at.x, at.y),
                     o.id, std::nullopt};
    }
  }
  return std::nullopt;
}

std::optional<Failure> VerdictChecker::OffRoadAt(const KsState& s) const {
  const auto box = BoxCorners({s.x, s.y}, s.orientation, vehicle_.length, vehicle_.width);
  if (road_.ContainsConvex(box)) return std::nullopt;
  return Failure{FailureKind::kOffRoad, s.time_step,
                 Fmt("the ego's box at (%.2f, %.2f), orientation %.3f rad, leaves the lanelets",
                     s.x, s.y, s.orientation),
                 std::nullopt, std::nullopt};
}

std::optional<Failure> VerdictChecker::StartFailure(const PlanningProblem& problem) const {
  KsState s;
  s.time_step = problem.initial.time_step;
  s.x = problem.initial.position.x;
  s.y = problem.initial.position.y;
  s.orientation = problem.initial.orientation.value_or(0.0);
  if (std::optional<Failure> f = CollisionAt(s)) return f;
  if (std::optional<Failure> f = OffRoadAt(s)) return f;
  return UnavoidableCollision(problem);
}

std::optional<Failure> VerdictChecker::UnavoidableCollision(const PlanningProblem& problem) const {
  const VehicleParams& p = vehicle_;
  const double dt = scenario_->dt;
  const double v0 = problem.initial.velocity.value_or(0.0);
  const double psi0 = problem.initial.orientation.value_or(0.0);
  const double delta0 = std::abs(problem.initial.steering_angle.value_or(0.0));
  const double steer_rate = std::max(std::abs(p.steering_rate_min), std::abs(p.steering_rate_max));
  const double steer_max = std::max(std::abs(p.steering_min), std::abs(p.steering_max));
  const double half_l = 0.5 * p.length, half_w = 0.5 * p.width;
  const Vec2 along{std::cos(psi0), std::sin(psi0)};
  for (int k = 1; k <= kUnavoidableSteps; ++k) {
    const double t = k * dt;
    // The rear axle's path length (signed) within [x_lo, x_hi], its heading within +-dpsi of
    // the initial one (the yaw rate v tan(delta) / l, delta growing at most at the steering
    // rate); the centre, b ahead of the rear axle, turns with it.
    const double x_lo = v0 * t - 0.5 * p.a_max * t * t;
    const double x_hi = v0 * t + 0.5 * p.a_max * t * t;
    const double v_abs = std::max(std::abs(v0) + p.a_max * t, 0.0);
    const double dpsi =
        v_abs * std::tan(std::min(delta0 + steer_rate * t, steer_max)) / p.Wheelbase() * t;
    if (!(dpsi < 0.5)) break;
    const double reach = std::max(std::abs(x_lo), std::abs(x_hi));
    const double lateral = (reach + p.b) * std::sin(dpsi) + kReachSlack;
    const double lo = (x_lo >= 0 ? x_lo * std::cos(dpsi) : x_lo) - p.b * (1 - std::cos(dpsi)) -
                      kReachSlack;
    const double hi = x_hi + kReachSlack;
    // Every box of a centre in [lo, hi] x [-lateral, lateral] (initial frame) turned by up to
    // dpsi covers this rectangle (the inscribed one of a turned box, a' = a cos - w sin).
    const double a = half_l * std::cos(dpsi) - half_w * std::sin(dpsi);
    const double w = half_w * std::cos(dpsi) - half_l * std::sin(dpsi);
    const double core_lo = hi - a, core_hi = lo + a, core_w = w - lateral;
    if (!(core_hi > core_lo) || !(core_w > 0)) break;
    const double mid = 0.5 * (core_lo + core_hi);
    const Vec2 centre{problem.initial.position.x + mid * along.x,
                      problem.initial.position.y + mid * along.y};
    const auto core = BoxCorners(centre, psi0, core_hi - core_lo, 2 * core_w);
    const int step = problem.initial.time_step + k;
    for (const Obstacle& o : scenario_->obstacles) {
      const std::optional<ShapeGroup> occupancy = o.OccupancyAt(step);
      if (!occupancy || !occupancy->Overlaps(core)) continue;
      return Failure{FailureKind::kCollision, step,
                     "every state the vehicle can reach at step " + std::to_string(step) +
                         " overlaps obstacle " + std::to_string(o.id) + " (" + o.type + ")",
                     o.id, std::nullopt};
    }
  }
  return std::nullopt;
}

Verdict CheckTrajectory(const Scenario& scenario, const PlanningProblem& problem,
                        const VehicleParams& vehicle, std::span<const KsState> trajectory,
                        const VerdictOptions& options) {
  return VerdictChecker(scenario, vehicle, options).Check(problem, trajectory);
}

}  // namespace frenetic::commonroad

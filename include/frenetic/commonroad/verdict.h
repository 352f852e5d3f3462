// Whether a KS trajectory solves a CommonRoad planning problem, checked the way CommonRoad's
// solution checker (commonroad_dc.feasibility.solution_checker.valid_solution) checks it, and
// independent of any planner. Each check reports the first step at which it fails.
//
//  - trajectory: states at consecutive time steps, finite values (checked first; the remaining
//    checks run on the valid prefix).
//  - start: the first state is the problem's initial state: same time step; position within
//    0.1 m per coordinate, orientation within 0.1 rad, velocity within 2 m/s (the tolerances of
//    solution_checker.starts_at_correct_state).
//  - goal: the first step at which the state meets any of the problem's goal states (time step in
//    its interval; position inside one of its shapes, or inside one of its lanelets' polygons;
//    velocity in its interval; orientation in its interval modulo 2 pi; absent parts always met).
//    The state's (x, y) is the tested point (GoalRegion.is_reached uses the state's position).
//  - collision: the ego's l x w box centred on (x, y) along psi overlaps what an obstacle
//    occupies at the same step (Obstacle::OccupancyAt): a trajectory-based dynamic obstacle's shape
//    at its recorded state there (none before its initial step or after its trajectory's end), a
//    set-based one's occupancies covering the step (its shape at its initial state at the initial
//    step), a static one's shape at every step. Touching counts.
//  - road: the ego's box lies inside the union of all lanelets, both directions, the network's
//    ends closed (RoadArea, with options.road_tolerance and options.open_end_margin).
//  - infeasible at start: the problem's initial state itself collides (its box overlaps an
//    obstacle at the initial step) or lies off the road, or a collision within the first
//    kUnavoidableSteps steps cannot be avoided (an obstacle overlaps every box the vehicle can
//    reach then: UnavoidableCollision); no trajectory can solve it (it starts there), so the
//    problem is reported apart, not as a planner's failure.
//  - kinematic limits, per state: steering angle in [steering_min, steering_max], velocity in
//    [v_min, v_max]; per step k -> k+1 with the input reconstructed from the two states
//    (steering rate = (delta_{k+1} - delta_k) / dt, acceleration = (v_{k+1} - v_k) / dt, both
//    exact for a constant KS input): steering rate in [steering_rate_min, max], acceleration in
//    [-a_max, MaxAcceleration(v_k)] (the v_switch rule), friction circle
//    a^2 + (v_k * psi'_k)^2 <= a_max^2 (VehicleDynamics.violates_friction_circle). Limits get
//    options.limit_tolerance of slack (CommonRoad rounds inputs to 4 decimals before its bounds
//    check).
//  - dynamics: the state at k simulated one step with that input (SimulateKs, CommonRoad's input
//    constraints applied) must land on the state at k+1: rear-axle position within
//    options.position_tolerance per coordinate and orientation within
//    options.orientation_tolerance (position_orientation_feasibility_criteria, e = [0.02, 0.02,
//    0.03]). CommonRoad instead searches for the input that best fits position and orientation
//    (SLSQP) and never compares the next state's steering angle; reconstructing the input from
//    the recorded steering angles is stricter there: a trajectory whose steering angles do not
//    follow from its path fails here and may pass CommonRoad.
//
// Not checked: collisions between the egos of several planning problems.
#pragma once

#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/road_area.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

enum class FailureKind {
  kTrajectory,     // empty, steps not consecutive, or a value not finite
  kStart,          // the first state is not the initial state
  kGoal,           // no state meets a goal state
  kCollision,      // the ego's box overlaps an obstacle
  kOffRoad,        // the ego's box leaves the lanelets
  kSteeringAngle,  // steering angle out of its range
  kSteeringRate,   // steering rate out of its range
  kVelocity,       // velocity out of its range
  kAcceleration,   // acceleration out of its range (v_switch rule)
  kFrictionCircle, // longitudinal and lateral acceleration together above a_max
  kDynamics,       // the next state does not follow from the KS model
};
// "trajectory", "start", "goal", "collision", "off_road", "steering_angle", "steering_rate",
// "velocity", "acceleration", "friction_circle", "dynamics".
const char* ToString(FailureKind kind);

struct Failure {
  FailureKind kind = FailureKind::kTrajectory;
  int step = 0;                    // time step; for per-step limits, that of the step's start
  std::string detail;              // one line, values and units
  std::optional<int> obstacle_id;  // kCollision
  // kCollision: s before the collision that the obstacle came into the scene, when that was
  // after the trajectory's first state (a car entering a recording's view); none when it was
  // there from the start.
  std::optional<double> entered_s;
};

struct Verdict {
  int problem_id = 0;
  bool solved = false;           // goal reached and no failure
  std::optional<int> goal_step;  // first time step meeting a goal state
  // The first failure of each kind, in the order of FailureKind.
  std::vector<Failure> failures;
  // Set when the initial state already fails a collision or road check (then the same failure
  // is among `failures` at the initial step), or a collision soon after it cannot be avoided
  // (VerdictChecker::UnavoidableCollision): the problem has no solution.
  std::optional<Failure> infeasible_at_start;

  const Failure* Find(FailureKind kind) const;
  // "solved: goal at step 42", "failed: collision at step 12 (...); goal at step 49 (...)" or
  // "infeasible at start: collision at step 0 (...)".
  std::string Summary() const;
};

// Steps after the initial one that VerdictChecker::UnavoidableCollision looks at.
inline constexpr int kUnavoidableSteps = 10;
// m of slack on the reach's bounds (rounding in the recorded states).
inline constexpr double kReachSlack = 0.01;

struct VerdictOptions {
  double road_tolerance = RoadArea::kDefaultTolerance;  // m, see RoadArea
  double open_end_margin = RoadArea::kDefaultOpenEndMargin;  // m, see RoadArea
  double position_tolerance = 0.02;                     // m per coordinate, dynamics check
  double orientation_tolerance = 0.03;                  // rad, dynamics check
  double limit_tolerance = 1e-4;  // slack on every limit, in the limit's own unit
  double start_position_tolerance = 0.1;     // m per coordinate
  double start_orientation_tolerance = 0.1;  // rad
  double start_velocity_tolerance = 2.0;     // m/s
  int integration_substeps = 10;             // Runge-Kutta steps per time step (SimulateKs)

  // An error naming the first option that is negative, not finite, or (substeps) below 1.
  Status Validate() const;
};

// True when the state meets the goal state (see above); `scenario` resolves lanelet goals (an id
// it does not know is never met).
bool MeetsGoal(const Scenario& scenario, const GoalState& goal, const KsState& state);

// MeetsGoal for many states: the goals copied and their lanelets' polygons built once (it keeps
// no reference to `scenario`).
class GoalTest {
 public:
  GoalTest(const Scenario& scenario, std::span<const GoalState> goals);
  // True when the state meets one of the goal states.
  bool MeetsAny(const KsState& state) const;
  // The goal lanelets' polygons, by lanelet id.
  const std::map<int, std::vector<Vec2>>& polygons() const { return polygons_; }

 private:
  std::vector<GoalState> goals_;
  std::map<int, std::vector<Vec2>> polygons_;
};

// Checks trajectories against one scenario; builds the road area once.
class VerdictChecker {
 public:
  // `scenario` must outlive the checker. CHECKs options.Validate().
  VerdictChecker(const Scenario& scenario, const VehicleParams& vehicle,
                 const VerdictOptions& options = {});

  // `trajectory`: the ego's states from the problem's initial time step, one per step. Never
  // fails: bad trajectories give kTrajectory failures.
  Verdict Check(const PlanningProblem& problem, std::span<const KsState> trajectory) const;
  // The problem's initial state (at its time step, with its orientation, else 0) checked for
  // collision and road as a trajectory's state is, then UnavoidableCollision: the failure when
  // one is found (the problem is infeasible at start), else nothing.
  std::optional<Failure> StartFailure(const PlanningProblem& problem) const;
  // A collision no trajectory from the initial state avoids, at one of the kUnavoidableSteps
  // steps after it: an obstacle that overlaps, at that step, the rectangle every box the
  // vehicle can reach then covers. The reach is over-approximated (acceleration within
  // +-a_max, the heading's change within what the steering rate and angle allow, the centre
  // within the path those bound), so a collision found here is certain; the rectangle vanishes
  // within a few steps at road speeds, and later collisions are never found. nullopt: none.
  std::optional<Failure> UnavoidableCollision(const PlanningProblem& problem) const;

  const RoadArea& road() const { return road_; }

  // The collision and road failures of one state as Check finds them, each when it fails.
  std::optional<Failure> CollisionAt(const KsState& s) const;
  std::optional<Failure> OffRoadAt(const KsState& s) const;

 private:
  const Scenario* scenario_;
  VehicleParams vehicle_;
  VerdictOptions options_;
  RoadArea road_;
};

// One trajectory, without keeping the checker.
Verdict CheckTrajectory(const Scenario& scenario, const PlanningProblem& problem,
                        const VehicleParams& vehicle, std::span<const KsState> trajectory,
                        const VerdictOptions& options = {});

}  // namespace frenetic::commonroad

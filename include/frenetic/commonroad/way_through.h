// Whether any way through a problem's traffic exists: a diagnostic for unsolved problems, to
// tell a planner's miss from a problem that has no solution.
//
// A breadth-first search of the states the vehicle can reach, step by step from the problem's
// initial state, each state kept only while the verdict's own collision and road checks
// (VerdictChecker::CollisionAt, OffRoadAt) pass. The vehicle moves along its heading with the
// KS model's limits: at each step one of five forward accelerations (from -a_max to the limit
// at its speed, VehicleParams::MaxAcceleration) and one of five changes of its path's curvature
// (up to what the steering rate allows in a step, tan(delta) / wheelbase within the steering
// angle's limit), the forward and lateral (v^2 curvature) accelerations within the friction
// circle a_max. States are merged on a grid (position, speed, heading and curvature cells), and
// when more than max_states are valid at a step a spread of them over coarse strata of position
// and speed is kept (deterministic).
//
// The search also tells whether a kept state meets one of the problem's goal states
// (MeetsGoal): it goes on past the last moving car's step (static obstacles and the road still
// checked) until one does or every goal's window has closed (at most max_seconds). A way to the
// goal is the stronger evidence: a trajectory that ends in a goal state is a solution (the
// checker reads it up to its last state). None found is weaker than none through the traffic:
// past the traffic no step's cap is told (`exhaustive` speaks of the traffic's steps only).
//
// So the model is coarser than KS (five choices of each input a step, the grid, the cap): a way
// found is strong evidence that the problem has a solution; none found, with `exhaustive` (no
// step capped), that it has none. Neither is a proof.
#pragma once

#include <cstdint>

#include "frenetic/commonroad/planning_problem.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/commonroad/verdict.h"

namespace frenetic::commonroad {

struct WayThroughOptions {
  int max_states = 10000;         // valid states kept per step (a spread when more)
  // s searched at most after the initial state, in the scenario's steps (200 at 0.1 s, 500 at
  // 0.04 s); with no moving car, the traffic's part lasts a twentieth of it (1 s).
  double max_seconds = 20.0;
  double cell_xy = 0.25;          // m, grid cell of the position
  double cell_v = 0.25;           // m/s, of the speed
  double cell_heading = 0.01;     // rad, of the heading
  double cell_curvature = 0.002;  // 1/m, of the path's curvature
};

struct WayThrough {
  bool found = false;        // some state lasts from the initial step to last_step
  int last_step = 0;         // the traffic's last step (capped by max_seconds)
  int survived_to = 0;       // the last step some state reached (last_step when found)
  bool exhaustive = true;    // no step was capped at max_states
  std::int64_t checked = 0;  // states checked for collision and road
  int goal_step = -1;        // the first step a kept state met a goal state; -1: none did
  int goal_searched_to = 0;  // the last step searched for one: goal_step when found
};

// The search from problem.initial to the last step any dynamic obstacle exists (at most
// options.max_seconds later), then on until a state meets a goal (above); `checker` is the
// scenario's, for `vehicle`. An initial state that already fails gives found false and
// survived_to the initial step.
WayThrough SearchWayThrough(const Scenario& scenario, const PlanningProblem& problem,
                            const VerdictChecker& checker, const VehicleParams& vehicle,
                            const WayThroughOptions& options = {});

}  // namespace frenetic::commonroad

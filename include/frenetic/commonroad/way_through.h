// Whether any way through a problem's traffic exists: a diagnostic for unsolved problems, to
// tell a planner's miss from a problem that has no solution.
//
// A breadth-first search of the states the vehicle can reach, step by step from the problem's
// initial state, each state kept only while the verdict's own collision and road checks
// (VerdictChecker::CollisionAt, OffRoadAt) pass. The vehicle is a point moving along its
// heading: at each step one of five forward accelerations (from -a_max to the KS limit at its
// speed, VehicleParams::MaxAcceleration) and one of five lateral accelerations (the path's
// curvature, within the steering angle's limit and the friction circle a_max); the steering
// rate is not bounded. States are merged on a grid (position, speed, heading cells), and when
// more than max_states are left at a step a random-like spread of them is kept (the first
// valid ones in the order of a hash of their cells: deterministic).
//
// So the model is looser than KS in one way (the steering rate) and coarser in another (the
// grid and the cap): a way found is a strong hint that the problem has a solution, none found
// with `exhaustive` (no step capped) a strong hint that it has none. Neither is a proof.
#pragma once

#include <cstdint>

#include "frenetic/commonroad/planning_problem.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/commonroad/verdict.h"

namespace frenetic::commonroad {

struct WayThroughOptions {
  int max_states = 10000;      // states kept per step (an even spread when more)
  int max_steps = 200;         // steps searched at most after the initial one
  double lateral_accel = 4;    // m/s^2, the largest lateral acceleration tried (also half of it)
  double cell_xy = 0.25;       // m, grid cell of the position
  double cell_v = 0.25;        // m/s, of the speed
  double cell_heading = 0.01;  // rad, of the heading
};

struct WayThrough {
  bool found = false;        // some state lasts from the initial step to last_step
  int last_step = 0;         // the step searched to: the traffic's last (capped by max_steps)
  int survived_to = 0;       // the last step some state reached (last_step when found)
  bool exhaustive = true;    // no step was capped at max_states
  std::int64_t checked = 0;  // states checked for collision and road
};

// The search from problem.initial to the last step any dynamic obstacle exists (at most
// options.max_steps later); `checker` is the scenario's, for `vehicle`. An initial state that
// already fails gives found false and survived_to the initial step.
WayThrough SearchWayThrough(const Scenario& scenario, const PlanningProblem& problem,
                            const VerdictChecker& checker, const VehicleParams& vehicle,
                            const WayThroughOptions& options = {});

}  // namespace frenetic::commonroad

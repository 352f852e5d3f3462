// A CommonRoad planning problem (format 2020a, §planningProblem): the ego's initial state and one
// or more goal states, any one of which solves the problem.
#pragma once

#include <optional>
#include <vector>

#include "frenetic/commonroad/shape.h"
#include "frenetic/commonroad/state.h"

namespace frenetic::commonroad {

// What a state must meet to reach the goal. Absent parts are always met; a position given by
// shapes is met inside any of them, one given by lanelets inside any of those lanelets' polygons.
struct GoalState {
  std::optional<IntervalI> time;  // time steps, inclusive
  std::vector<Shape> shapes;      // scenario frame
  std::vector<int> lanelets;      // lanelet ids
  std::optional<Interval> velocity;     // m/s
  std::optional<Interval> orientation;  // rad, compared modulo 2 pi
  int line = 0;                   // source line, 0 when built in code

  bool HasPosition() const { return !shapes.empty() || !lanelets.empty(); }
};

struct PlanningProblem {
  int id = 0;
  State initial;  // position: the ego's centre (the KS reference point; see ks_model.h)
  std::vector<GoalState> goals;
  int line = 0;   // source line, 0 when built in code
};

}  // namespace frenetic::commonroad

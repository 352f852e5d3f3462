// A CommonRoad obstacle (format 2020a, §staticObstacle and §dynamicObstacle): a shape in its own
// frame, placed at each time step by the obstacle's state there (position = the shape's origin,
// orientation = its rotation).
//
// A static obstacle stands at its initial state at every time step. A dynamic obstacle's future
// is given one of two ways:
//  - trajectory-based (<trajectory>): a state at each step after the initial one; the obstacle
//    exists from its initial state's time step to its trajectory's last one;
//  - set-based (<occupancySet>, a set-based prediction such as SPOT's): regions of the scenario
//    that may be occupied, each over a time step or an interval of steps; the obstacle exists at
//    its initial step (occupying its shape at its initial state) and at every later step that an
//    occupancy covers.
// Before and after, and at steps no occupancy covers, it is gone (no state, no occupancy), as in
// CommonRoad's collision checker.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frenetic/commonroad/shape.h"
#include "frenetic/commonroad/state.h"

namespace frenetic::commonroad {

enum class ObstacleRole { kStatic, kDynamic };
// How a dynamic obstacle's future is given (see above); static obstacles: kTrajectory, empty.
enum class ObstaclePrediction { kTrajectory, kSetBased };

// One element of a set-based prediction: the region occupied over `time` (steps, both ends
// included; an exact time has start == end), in the scenario's frame.
struct Occupancy {
  IntervalI time;
  ShapeGroup shape;
};

struct Obstacle {
  int id = 0;
  ObstacleRole role = ObstacleRole::kDynamic;
  ObstaclePrediction prediction = ObstaclePrediction::kTrajectory;
  std::string type;  // <type>: "car", "truck", "unknown", "parkedVehicle", ...
  ShapeGroup shape;  // in the obstacle's frame
  State initial;     // its time step is the first step the obstacle exists
  // Trajectory-based: the states after the initial one, at consecutive time steps.
  std::vector<State> trajectory;
  // Set-based: the occupancies, all after the initial step, in file order (they may overlap in
  // time or leave steps uncovered).
  std::vector<Occupancy> occupancies;
  double dt = 0.1;  // s per time step (the scenario's): set-based states' velocities
  int line = 0;     // source line, 0 when built in code

  // The state at `step`; absent when the obstacle does not exist then (see above). Set-based
  // obstacles after their initial step have no recorded state; the one returned is derived from
  // the occupancy at `step` (OccupancyAt): position = the centre of its bounding box (the
  // smallest-area rectangle holding it, ShapeGroup::BoundingBox), orientation = the box's side
  // direction nearest the direction from the initial position to that centre (the initial
  // orientation when it lies within 1 m), velocity = the distance from the centre at the
  // previous step the obstacle exists (its initial position at the initial step) divided by the
  // time between; no acceleration or other fields.
  std::optional<State> StateAt(int step) const;
  // What the obstacle occupies at `step`, in the scenario's frame: its shape placed at its state
  // there (static, trajectory-based, and set-based at the initial step); for set-based ones after
  // it, the shapes of every occupancy whose time covers `step`, together. Absent when the
  // obstacle does not exist then.
  std::optional<ShapeGroup> OccupancyAt(int step) const;
  // Last time step the obstacle exists (a static obstacle: INT_MAX).
  int LastStep() const;
};

}  // namespace frenetic::commonroad

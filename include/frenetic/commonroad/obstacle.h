// A CommonRoad obstacle (format 2020a, §staticObstacle and §dynamicObstacle): a shape in its own
// frame, placed at each time step by the obstacle's state there (position = the shape's origin,
// orientation = its rotation).
//
// A static obstacle stands at its initial state at every time step. A dynamic obstacle exists from
// its initial state's time step to its trajectory's last one: before and after it is gone (no
// state, no occupancy), as in CommonRoad's collision checker.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frenetic/commonroad/shape.h"
#include "frenetic/commonroad/state.h"

namespace frenetic::commonroad {

enum class ObstacleRole { kStatic, kDynamic };

struct Obstacle {
  int id = 0;
  ObstacleRole role = ObstacleRole::kDynamic;
  std::string type;  // <type>: "car", "truck", "unknown", "parkedVehicle", ...
  ShapeGroup shape;  // in the obstacle's frame
  State initial;     // its time step is the first step the obstacle exists
  // Dynamic obstacles: the states after the initial one, at consecutive time steps.
  std::vector<State> trajectory;
  int line = 0;  // source line, 0 when built in code

  // The state at `step`; absent when the obstacle does not exist then (see above).
  std::optional<State> StateAt(int step) const;
  // The shape placed at the state at `step`; absent when the obstacle does not exist then.
  std::optional<ShapeGroup> OccupancyAt(int step) const;
  // Last time step the obstacle exists (a static obstacle: INT_MAX).
  int LastStep() const;
};

}  // namespace frenetic::commonroad

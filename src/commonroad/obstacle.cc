#include "frenetic/commonroad/obstacle.h"

#include <climits>

namespace frenetic::commonroad {

std::optional<State> Obstacle::StateAt(int step) const {
  if (role == ObstacleRole::kStatic) return initial;
  if (step == initial.time_step) return initial;
  if (trajectory.empty() || step < trajectory.front().time_step) return std::nullopt;
  const long index = static_cast<long>(step) - trajectory.front().time_step;
  if (index >= static_cast<long>(trajectory.size())) return std::nullopt;
  return trajectory[index];
}

std::optional<ShapeGroup> Obstacle::OccupancyAt(int step) const {
  const std::optional<State> state = StateAt(step);
  if (!state) return std::nullopt;
  return shape.Transformed(state->position, state->orientation.value_or(0.0));
}

int Obstacle::LastStep() const {
  if (role == ObstacleRole::kStatic) return INT_MAX;
  return trajectory.empty() ? initial.time_step : trajectory.back().time_step;
}

}  // namespace frenetic::commonroad

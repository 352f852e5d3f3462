#include "frenetic/commonroad/obstacle.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <numbers>
#include <utility>

namespace frenetic::commonroad {

namespace {

// m: a set-based obstacle's centre this far from its initial position gives the direction its
// bounding box is turned to; nearer, the initial orientation does (a centre that has barely
// moved gives no direction).
constexpr double kMinChord = 1.0;

// The same rectangle, its heading turned by a multiple of pi/2 to lie nearest `reference`.
OrientedBox TurnedToward(OrientedBox box, double reference) {
  const double quarters = std::round(WrapAngle(reference - box.heading) / (0.5 * std::numbers::pi));
  if (!std::isfinite(quarters)) return box;
  box.heading = WrapAngle(box.heading + quarters * 0.5 * std::numbers::pi);
  if (static_cast<int>(quarters) % 2 != 0) std::swap(box.length, box.width);
  return box;
}

}  // namespace

std::optional<State> Obstacle::StateAt(int step) const {
  if (role == ObstacleRole::kStatic) return initial;
  if (step == initial.time_step) return initial;
  if (prediction == ObstaclePrediction::kSetBased) {
    const std::optional<ShapeGroup> occupied = OccupancyAt(step);
    if (!occupied) return std::nullopt;
    // The latest earlier step the obstacle exists: one an occupancy covers, else the initial.
    int previous = initial.time_step;
    for (const Occupancy& o : occupancies) {
      if (o.time.start < step) previous = std::max(previous, std::min(o.time.end, step - 1));
    }
    const double initial_heading = initial.orientation.value_or(0.0);
    OrientedBox box = occupied->BoundingBox(initial_heading);
    const Vec2 chord = box.center - initial.position;
    if (Norm(chord) >= kMinChord) box = TurnedToward(box, std::atan2(chord.y, chord.x));
    // (The box's centre does not depend on the heading asked for.)
    const Vec2 before = previous == initial.time_step
                            ? initial.position
                            : OccupancyAt(previous)->BoundingBox(initial_heading).center;
    State st;
    st.time_step = step;
    st.position = box.center;
    st.orientation = box.heading;
    st.velocity = Distance(box.center, before) / ((static_cast<double>(step) - previous) * dt);
    return st;
  }
  if (trajectory.empty() || step < trajectory.front().time_step) return std::nullopt;
  const long index = static_cast<long>(step) - trajectory.front().time_step;
  if (index >= static_cast<long>(trajectory.size())) return std::nullopt;
  return trajectory[index];
}

std::optional<ShapeGroup> Obstacle::OccupancyAt(int step) const {
  if (role == ObstacleRole::kDynamic && prediction == ObstaclePrediction::kSetBased &&
      step != initial.time_step) {
    if (step < initial.time_step) return std::nullopt;
    ShapeGroup out;
    bool covered = false;
    for (const Occupancy& o : occupancies) {
      if (!o.time.Contains(step)) continue;
      covered = true;
      out.shapes.insert(out.shapes.end(), o.shape.shapes.begin(), o.shape.shapes.end());
    }
    if (!covered) return std::nullopt;
    return out;
  }
  const std::optional<State> state = StateAt(step);
  if (!state) return std::nullopt;
  return shape.Transformed(state->position, state->orientation.value_or(0.0));
}

int Obstacle::LastStep() const {
  if (role == ObstacleRole::kStatic) return INT_MAX;
  if (prediction == ObstaclePrediction::kSetBased) {
    int last = initial.time_step;
    for (const Occupancy& o : occupancies) last = std::max(last, o.time.end);
    return last;
  }
  return trajectory.empty() ? initial.time_step : trajectory.back().time_step;
}

}  // namespace frenetic::commonroad

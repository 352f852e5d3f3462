// A CommonRoad state (an obstacle's or a planning problem's) and the intervals goal states use.
//
// CommonRoad lets a state field be exact (<exact>) or an interval (<intervalStart>, <intervalEnd>);
// states here keep one exact value per field: an interval is read as its midpoint, and a position
// given as a shape (an uncertain position) as the shape's centroid. Goal states keep their
// intervals (GoalState). Units SI: m, rad, m/s, m/s^2, rad/s; time as an integer step of the
// scenario's dt.
#pragma once

#include <optional>

#include "frenetic/commonroad/geometry.h"

namespace frenetic::commonroad {

struct Interval {
  double start = 0, end = 0;
  bool Contains(double v) const { return v >= start && v <= end; }
  double Mid() const { return 0.5 * (start + end); }
};

struct IntervalI {
  int start = 0, end = 0;
  bool Contains(int v) const { return v >= start && v <= end; }
};

struct State {
  int time_step = 0;
  Vec2 position;  // obstacles: the shape's reference point (centre); planning problems: ego centre
  // Present when the file gives the field.
  std::optional<double> orientation, velocity, acceleration, yaw_rate, slip_angle, steering_angle;
};

}  // namespace frenetic::commonroad

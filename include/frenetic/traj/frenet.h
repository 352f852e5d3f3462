// Frenet states and trajectories on the reference line: s along the line (m, not wrapped inside
// the planner: callers wrap with ReferenceLine::WrapS), d positive to the right of the driving
// direction (m), and their first two time derivatives.
#pragma once

#include <cmath>

#include "frenetic/traj/polynomial.h"

namespace frenetic::traj {

struct FrenetState {
  double s = 0, s_d = 0, s_dd = 0;  // m, m/s, m/s^2
  double d = 0, d_d = 0, d_dd = 0;  // m, m/s, m/s^2
  bool IsFinite() const {
    return std::isfinite(s) && std::isfinite(s_d) && std::isfinite(s_dd) && std::isfinite(d) &&
           std::isfinite(d_d) && std::isfinite(d_dd);
  }
};

// A longitudinal and a lateral 1-D trajectory from the same start instant.
struct FrenetTrajectory {
  Trajectory1d lon, lat;
  FrenetState At(double t) const {
    const State1d a = lon.At(t), b = lat.At(t);
    return {a.p, a.v, a.a, b.p, b.v, b.a};
  }
};

}  // namespace frenetic::traj

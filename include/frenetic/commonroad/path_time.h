// A planner's path read at a scenario's step size. The planner's paths are points every
// plan::kTickSeconds (the Udacity simulator's 0.02 s), the first one tick on; a CommonRoad file
// steps by its own timeStepSize, which need not be a whole number of ticks (0.05 s is 2.5).
// Between points the path is read linearly, and the points a step consumes are whole: the
// path left over starts off a tick by a phase of at most half a tick, carried to the next step.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "frenetic/plan/planner.h"

namespace frenetic::commonroad {

// Where on a path (points every tick, the first one tick after the path's start) a time t s
// after its start lies: between point lo and lo + 1, frac of the way (0 within 1e-9 of a
// point: a whole number of ticks reads the point itself). Before the first point: the first
// (a step shorter than 0.03 s, with its phase, may read a little late).
struct PathIndex {
  int lo = 0;
  double frac = 0;
};
inline PathIndex PathIndexAt(double t) {
  // Past a million points: there (no path is that long; the int stays defined).
  const double f = std::min(t / plan::kTickSeconds - 1.0, 1e6);
  if (!(f > 0)) return {};
  const double whole = std::round(f);
  if (std::abs(f - whole) < 1e-9) return {static_cast<int>(whole), 0.0};
  const double lo = std::floor(f);
  return {static_cast<int>(lo), f - lo};
}

// One coordinate of a path (its x or its y) at `in`: the point, or linear between it and the
// next (which must exist when in.frac > 0).
inline double PathValueAt(const std::vector<double>& v, const PathIndex& in) {
  return in.frac > 0 ? v[in.lo] + in.frac * (v[in.lo + 1] - v[in.lo]) : v[in.lo];
}

// The whole points of a path that a step of dt s consumes, when the path's first point lies
// `*phase` s later than one tick after the step's start; *phase becomes the offset of the path
// left over (at most half a tick either way; 0 when dt is a whole number of ticks).
inline int TicksConsumed(double dt, double* phase) {
  const double tick = plan::kTickSeconds;
  const int consumed = static_cast<int>(std::lround(std::clamp((dt - *phase) / tick, 0.0, 1e6)));
  double next = consumed * tick + *phase - dt;
  if (std::abs(next) < 1e-9) next = 0;
  *phase = next;
  return consumed;
}

}  // namespace frenetic::commonroad

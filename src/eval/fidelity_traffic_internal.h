// Internals of the traffic statistics (fidelity_traffic.cc) shared with the traffic runs
// (drive/traffic_runs.cc): the road's lanes as the statistics count them, and profile lookup.
#pragma once

#include <algorithm>
#include <vector>

namespace frenetic::sim::fidelity {

inline bool OnRoad(double d) { return d >= 0 && d <= 12; }
inline int LaneOf(double d) { return d < 4 ? 0 : (d < 8 ? 1 : 2); }

// Linear interpolation of v over increasing t at `time`, clamped to the ends; `empty` when
// there is nothing to interpolate.
inline double Interpolate(const std::vector<double>& t, const std::vector<double>& v, double time,
                   double empty) {
  if (t.empty() || v.size() != t.size()) return empty;
  if (time <= t.front()) return v.front();
  if (time >= t.back()) return v.back();
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
  const double span = t[i] - t[i - 1];
  const double w = span > 0 ? (time - t[i - 1]) / span : 1.0;
  return v[i - 1] + (v[i] - v[i - 1]) * w;
}

}  // namespace frenetic::sim::fidelity

#include "frenetic/commonroad/way_through.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <vector>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/reach_grid.h"

namespace frenetic::commonroad {
namespace {

struct Point {
  double x, y, v, heading;
  double curvature;  // 1/m, of the path (tan(steering angle) / wheelbase)
};

struct Cells {
  double xy, v, heading, curvature;
};

std::uint64_t CellOf(const Point& p, const Cells& c) {
  const double cell[5] = {c.xy, c.xy, c.v, c.heading, c.curvature};
  return reach::CellOf(p.x, p.y, p.v, p.heading, p.curvature, cell);
}

}  // namespace

WayThrough SearchWayThrough(const Scenario& scenario, const PlanningProblem& problem,
                            const VerdictChecker& checker, const VehicleParams& vehicle,
                            const WayThroughOptions& options) {
  WayThrough r;
  const int first = problem.initial.time_step;
  int traffic_end = INT_MIN;
  for (const Obstacle& o : scenario.obstacles) {
    if (o.LastStep() != INT_MAX) traffic_end = std::max(traffic_end, o.LastStep());
  }
  const int horizon = traffic_end == INT_MIN
                          ? std::min(options.max_steps, 10)
                          : std::clamp(traffic_end - first, 0, options.max_steps);
  r.last_step = first + horizon;
  r.survived_to = first;
  const double dt = scenario.dt;
  const auto valid = [&](const Point& p, int step) {
    ++r.checked;
    KsState s;
    s.time_step = step;
    s.x = p.x;
    s.y = p.y;
    s.velocity = p.v;
    s.orientation = p.heading;
    return !checker.CollisionAt(s) && !checker.OffRoadAt(s);
  };
  const double wheelbase = vehicle.Wheelbase();
  std::vector<Point> now{{problem.initial.position.x, problem.initial.position.y,
                          std::clamp(problem.initial.velocity.value_or(0.0), 0.0, vehicle.v_max),
                          problem.initial.orientation.value_or(0.0),
                          std::tan(problem.initial.steering_angle.value_or(0.0)) / wheelbase}};
  if (!valid(now[0], first)) return r;
  // The path's curvature within the steering angle's limit, and its change in a step within
  // what the steering rate allows (d tan(delta) / dt = delta' / cos^2 delta >= delta').
  const double max_curvature =
      std::tan(std::min(std::abs(vehicle.steering_min), std::abs(vehicle.steering_max))) /
      wheelbase;
  const double turn =
      std::min(std::abs(vehicle.steering_rate_min), std::abs(vehicle.steering_rate_max)) * dt /
      wheelbase;
  const double turns[5] = {-turn, -0.5 * turn, 0.0, 0.5 * turn, turn};
  const Cells cells{options.cell_xy, options.cell_v, options.cell_heading, options.cell_curvature};
  // Strata of position and speed; the 1e3 cells leave of heading and curvature only their sign.
  const Cells strata_cells{2.0, 1.0, 1e3, 1e3};
  std::vector<std::pair<std::uint64_t, Point>> next;
  KeyTable seen;
  reach::SpreadScratch spread;
  std::vector<std::pair<std::size_t, std::size_t>> rank;  // (rank in its stratum, index)
  for (int k = 1; k <= horizon; ++k) {
    const int step = first + k;
    next.clear();
    seen.Clear();
    for (const Point& p : now) {
      const double up = vehicle.MaxAcceleration(p.v);
      const double forward[5] = {-vehicle.a_max, -0.5 * vehicle.a_max, 0.0, 0.5 * up, up};
      for (const double a : forward) {
        const double v1 = std::clamp(p.v + a * dt, 0.0, vehicle.v_max);
        const double v_mid = 0.5 * (p.v + v1);
        for (const double dk : turns) {
          const double k1 = std::clamp(p.curvature + dk, -max_curvature, max_curvature);
          // The friction circle: forward and lateral (v^2 curvature) acceleration together.
          const double lateral = v1 * v1 * k1;
          if (a * a + lateral * lateral > vehicle.a_max * vehicle.a_max) continue;
          const double h1 = p.heading + 0.5 * (p.curvature + k1) * v_mid * dt;
          const double h_mid = 0.5 * (p.heading + h1);
          const Point q{p.x + v_mid * dt * std::cos(h_mid), p.y + v_mid * dt * std::sin(h_mid), v1,
                        h1, k1};
          const std::uint64_t cell = CellOf(q, cells);
          if (seen.Insert(cell)) next.push_back({cell, q});
        }
      }
    }
    // Checked round-robin over coarse strata (2 m of position, 1 m/s of speed) until
    // max_states are valid: a capped step keeps a spread over positions and speeds, the rare
    // slow states (the ones that stop before a wall) with the many fast ones.
    reach::SpreadOrder(next, [&](const Point& q) { return CellOf(q, strata_cells); }, spread, rank);
    const std::size_t n = next.size(), cap = std::max(options.max_states, 1);
    now.clear();
    std::size_t visited = 0;
    for (; visited < n && now.size() < cap; ++visited) {
      const Point& q = next[rank[visited].second].second;
      if (valid(q, step)) now.push_back(q);
    }
    if (now.empty()) return r;
    if (visited < n) r.exhaustive = false;
    r.survived_to = step;
  }
  r.found = true;
  return r;
}

}  // namespace frenetic::commonroad

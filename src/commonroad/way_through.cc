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
  const double seconds = std::isfinite(options.max_seconds) ? options.max_seconds : 0.0;
  const int max_steps =
      static_cast<int>(std::lround(std::clamp(seconds / scenario.dt, 1.0, 100000.0)));
  const int horizon = traffic_end == INT_MIN ? std::max(1, max_steps / 20)
                                             : std::clamp(traffic_end - first, 0, max_steps);
  r.last_step = first + horizon;
  r.survived_to = first;
  // Past the traffic, on until a goal's window has closed (a goal without one: max_steps).
  std::int64_t goal_end = INT_MIN;
  for (const GoalState& g : problem.goals) {
    goal_end = std::max<std::int64_t>(goal_end, g.time ? g.time->end : INT_MAX);
  }
  const int goal_horizon =
      goal_end == INT_MIN
          ? 0
          : static_cast<int>(std::clamp<std::int64_t>(goal_end - first, 0, max_steps));
  const GoalTest goal(scenario, problem.goals);
  const double dt = scenario.dt;
  const auto state = [](const Point& p, int step) {
    KsState s;
    s.time_step = step;
    s.x = p.x;
    s.y = p.y;
    s.velocity = p.v;
    s.orientation = p.heading;
    return s;
  };
  const auto valid = [&](const Point& p, int step) {
    ++r.checked;
    const KsState s = state(p, step);
    return !checker.CollisionAt(s) && !checker.OffRoadAt(s);
  };
  // Whether a kept state at `step` meets a goal (recorded once).
  const auto meets_goal = [&](const std::vector<Point>& kept, int step) {
    if (r.goal_step >= 0) return;
    r.goal_searched_to = step;
    for (const Point& p : kept) {
      if (goal.MeetsAny(state(p, step))) {
        r.goal_step = step;
        return;
      }
    }
  };
  const double wheelbase = vehicle.Wheelbase();
  std::vector<Point> now{{problem.initial.position.x, problem.initial.position.y,
                          std::clamp(problem.initial.velocity.value_or(0.0), 0.0, vehicle.v_max),
                          problem.initial.orientation.value_or(0.0),
                          std::tan(problem.initial.steering_angle.value_or(0.0)) / wheelbase}};
  r.goal_searched_to = first;
  if (!valid(now[0], first)) return r;
  meets_goal(now, first);
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
  // No step to get through: found.
  if (horizon == 0) r.found = true;
  const int steps = std::max(horizon, goal_horizon);
  for (int k = 1; k <= steps; ++k) {
    if (k > horizon && r.goal_step >= 0) break;  // through the traffic, and a goal met
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
    if (visited < n && k <= horizon) r.exhaustive = false;
    meets_goal(now, step);
    if (k <= horizon) r.survived_to = step;
    if (k == horizon) r.found = true;
  }
  return r;
}

}  // namespace frenetic::commonroad

#include "frenetic/commonroad/cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

namespace frenetic::commonroad {

namespace {

// scipy.integrate._basic_simpson: Simpson's rule over the sample triples starting at start,
// start + 2, ... below stop.
double BasicSimpson(std::span<const double> y, size_t start, size_t stop, double dx) {
  double sum = 0;
  for (size_t i = start; i < stop && i + 2 < y.size(); i += 2) {
    sum += y[i] + 4 * y[i + 1] + y[i + 2];
  }
  return sum * dx / 3;
}

// The lanelet a state stands on and its centre line.
struct LaneMatch {
  const Lanelet* lanelet = nullptr;
  const std::vector<Vec2>* center = nullptr;
  PolylineProjection projection;
};

class LaneMatcher {
 public:
  LaneMatcher(const Scenario& scenario, double radius) : scenario_(scenario), radius_(radius) {
    for (const Lanelet& l : scenario.lanelets) {
      polygons_.push_back(l.Polygon());
      centers_.push_back(l.CenterLine());
      Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
      for (const Vec2& q : polygons_.back()) {
        lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
        hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
      }
      boxes_.push_back({lo, hi});
    }
  }

  // Among the lanelets within `radius_` of the point (CommonRoad: a circle of radius w / 2.5
  // intersecting the lanelet polygon), the one whose centre line runs closest to the heading,
  // then the nearest centre line; without any, the lanelet with the nearest polygon.
  std::optional<LaneMatch> Match(Vec2 p, double heading) const {
    std::optional<LaneMatch> best;
    double best_key[2] = {0, 0};
    for (size_t i = 0; i < polygons_.size(); ++i) {
      const auto& [lo, hi] = boxes_[i];
      if (p.x < lo.x - radius_ || p.x > hi.x + radius_ || p.y < lo.y - radius_ ||
          p.y > hi.y + radius_) {
        continue;
      }
      const double gap = PolygonDistance(polygons_[i], p);
      if (!(gap <= radius_)) continue;
      const PolylineProjection proj = ProjectOntoPolyline(centers_[i], p);
      const double misalign = std::abs(WrapAngle(heading - proj.heading)) > std::numbers::pi / 2 ? 1 : 0;
      const double key[2] = {misalign, std::abs(proj.d)};
      if (!best || key[0] < best_key[0] || (key[0] == best_key[0] && key[1] < best_key[1])) {
        best = LaneMatch{&scenario_.lanelets[i], &centers_[i], proj};
        best_key[0] = key[0];
        best_key[1] = key[1];
      }
    }
    if (best) return best;
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < polygons_.size(); ++i) {
      const double gap = PolygonDistance(polygons_[i], p);
      if (gap < nearest) {
        nearest = gap;
        best = LaneMatch{&scenario_.lanelets[i], &centers_[i],
                         ProjectOntoPolyline(centers_[i], p)};
      }
    }
    return best;
  }

  // The lanelet's centre line with its first predecessors and first successors in front and
  // behind, up to `reach` m each way (computed once per lanelet).
  const std::vector<Vec2>& ExtendedCenter(const Lanelet& lanelet, double reach) const {
    auto [it, inserted] = extended_.try_emplace(lanelet.id);
    if (inserted) it->second = Extend(lanelet, reach);
    return it->second;
  }

 private:
  std::vector<Vec2> Extend(const Lanelet& lanelet, double reach) const {
    std::vector<Vec2> line = Center(lanelet);
    const Lanelet* cur = &lanelet;
    for (double len = 0; len < reach && !cur->successors.empty();) {
      cur = scenario_.FindLanelet(cur->successors.front());
      if (!cur || cur == &lanelet) break;
      const std::vector<Vec2>& next = Center(*cur);
      line.insert(line.end(), next.begin(), next.end());
      len += PolylineLength(next);
    }
    cur = &lanelet;
    for (double len = 0; len < reach && !cur->predecessors.empty();) {
      cur = scenario_.FindLanelet(cur->predecessors.front());
      if (!cur || cur == &lanelet) break;
      const std::vector<Vec2>& prev = Center(*cur);
      line.insert(line.begin(), prev.begin(), prev.end());
      len += PolylineLength(prev);
    }
    return CleanPolyline(line);
  }

  const std::vector<Vec2>& Center(const Lanelet& l) const {
    return centers_[&l - scenario_.lanelets.data()];
  }

  const Scenario& scenario_;
  double radius_;
  std::vector<std::vector<Vec2>> polygons_, centers_;
  std::vector<std::pair<Vec2, Vec2>> boxes_;  // bounding boxes of the polygons
  mutable std::map<int, std::vector<Vec2>> extended_;
};

std::vector<double> Diff(std::span<const double> v, double dt) {
  std::vector<double> out;
  for (size_t i = 1; i < v.size(); ++i) out.push_back((v[i] - v[i - 1]) / dt);
  return out;
}

std::vector<double> Squared(std::vector<double> v) {
  for (double& x : v) x *= x;
  return v;
}

}  // namespace

double Simpson(std::span<const double> y, double dx) {
  const size_t n = y.size();
  if (n < 2) return 0;
  if (n % 2 == 1) return BasicSimpson(y, 0, n - 2, dx);
  // even='avg': Simpson on the first n - 1 samples plus a trapezoid on the last interval, and a
  // trapezoid on the first interval plus Simpson on the last n - 1 samples, averaged.
  const double val = 0.5 * dx * (y[n - 1] + y[n - 2]) + 0.5 * dx * (y[1] + y[0]);
  const double result = BasicSimpson(y, 0, n - 3, dx) + BasicSimpson(y, 1, n - 2, dx);
  return result / 2 + val / 2;
}

PartialCosts ComputePartialCosts(const Scenario& scenario, const PlanningProblem& problem,
                                 const VehicleParams& vehicle,
                                 std::span<const KsState> trajectory) {
  PartialCosts c;
  if (trajectory.empty()) return c;
  const double dt = scenario.dt;
  const size_t n = trajectory.size();
  std::vector<double> v(n), delta(n), psi(n);
  for (size_t i = 0; i < n; ++i) {
    v[i] = trajectory[i].velocity;
    delta[i] = trajectory[i].steering_angle;
    psi[i] = trajectory[i].orientation;
  }
  c.time = (trajectory.back().time_step - trajectory.front().time_step) * dt;
  const std::vector<double> accel = Diff(v, dt);
  c.acceleration = Simpson(Squared(accel), dt);
  c.jerk = Simpson(Squared(Diff(accel, dt)), dt);
  c.path_length = Simpson(v, dt);
  c.steering_angle = Simpson(Squared(delta), dt);
  c.steering_rate = Simpson(Squared(Diff(delta, dt)), dt);
  c.yaw_rate = Simpson(Squared(Diff(psi, dt)), dt);

  std::optional<double> goal_velocity;
  for (const GoalState& g : problem.goals) {
    if (g.velocity) goal_velocity = std::min(goal_velocity.value_or(g.velocity->start),
                                             g.velocity->start);
  }
  std::vector<double> v_offset(n, 0.0);
  if (goal_velocity && *goal_velocity != 0) {
    for (size_t i = 0; i < n; ++i) v_offset[i] = *goal_velocity - v[i];
  }
  c.velocity_offset = Simpson(Squared(v_offset), dt);

  // Lane-based terms (approximations, see the header).
  const double ego_radius = vehicle.width / 2.5;  // LaneletRouteMatcher.ego_radius
  const LaneMatcher matcher(scenario, ego_radius);
  std::vector<double> lat(n, 0.0), orient(n, 0.0), obstacle(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const KsState& s = trajectory[i];
    const Vec2 p{s.x, s.y};
    const std::optional<LaneMatch> m = matcher.Match(p, s.orientation);
    if (!m) continue;
    lat[i] = m->projection.d;
    orient[i] = WrapAngle(s.orientation - m->projection.heading);
    const std::vector<Vec2>& line = matcher.ExtendedCenter(*m->lanelet, 250);
    const PolylineProjection ego = ProjectOntoPolyline(line, p);
    double nearest = std::numeric_limits<double>::infinity();
    for (const Obstacle& o : scenario.obstacles) {
      const std::optional<State> os = o.StateAt(s.time_step);
      if (!os) continue;
      const Vec2 center =
          o.shape.Transformed(os->position, os->orientation.value_or(0.0)).Centroid();
      if (std::abs(center.x - p.x) > 100 || std::abs(center.y - p.y) > 100) continue;
      const PolylineProjection obs = ProjectOntoPolyline(line, center);
      const double ahead = obs.s - ego.s;
      if (std::abs(ego.d - obs.d) < 2.8 && ahead > 0) {
        nearest = std::min(nearest, ahead - ego_radius);
      }
    }
    obstacle[i] = std::isfinite(nearest) ? std::exp(-0.1 * nearest) : 0.0;
  }
  c.lane_center_offset = Simpson(Squared(lat), dt);
  c.orientation_offset = Simpson(Squared(orient), dt);
  c.distance_to_obstacles = Simpson(obstacle, dt);
  return c;
}

StatusOr<CostReport> EvaluateCost(std::string_view cost_function, const Scenario& scenario,
                                  const PlanningProblem& problem, const VehicleParams& vehicle,
                                  std::span<const KsState> trajectory) {
  if (cost_function != "JB1" && cost_function != "WX1") {
    return Status::Error("cost function '" + std::string(cost_function.substr(0, 20)) +
                         "' is not implemented (JB1, WX1)");
  }
  if (trajectory.empty()) return Status::Error("cost of an empty trajectory");
  CostReport report;
  report.cost_function = std::string(cost_function);
  report.partials = ComputePartialCosts(scenario, problem, vehicle, trajectory);
  const PartialCosts& p = report.partials;
  if (cost_function == "JB1") {
    report.terms = {{"T", 1.0, p.time}};
  } else {
    report.terms = {{"T", 10.0, p.time},
                    {"V", 1.0, p.velocity_offset},
                    {"A", 0.1, p.acceleration},
                    {"J", 0.1, p.jerk},
                    {"D", 0.1, p.distance_to_obstacles},
                    {"L", 10.0, p.lane_center_offset}};
  }
  for (const CostTerm& t : report.terms) report.total += t.weight * t.value;
  return report;
}

}  // namespace frenetic::commonroad

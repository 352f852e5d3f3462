// The CommonRoad benchmark's cost functions JB1 and WX1 for a KS trajectory.
//
// Source: the cost function documentation ("CommonRoad: Cost Functions", costFunctions_commonRoad
// .pdf) as implemented by the drivability checker's evaluator, which scores submissions:
// commonroad_dc/costs/evaluation.py (CostFunctionMapping) and partial_cost_functions.py.
//   JB1 = 1 * T
//   WX1 = 10 * T + 1 * V + 0.1 * A + 0.1 * J + 0.1 * D + 10 * L
// and evaluation.py evaluates the partial cost "L" with lane_center_offset_cost (its enum calls L
// the path length; PartialCostFunctionMapping maps it to the lane-centre offset): WX1 here does
// the same. Each partial cost integrates a per-state signal with Simpson's rule over the time steps
// (scipy.integrate.simps(y, dx=dt); for an even number of samples the average of the two
// Simpson-plus-trapezoid variants, scipy's even='avg', the default before scipy 1.11):
//   T  time: (last step - first step) * dt
//   V  velocity offset: (v_goal - v)^2, v_goal the lowest goal velocity interval start (0 cost
//      when no goal state gives a velocity, or it is 0)
//   A  acceleration: ((v_{k+1} - v_k) / dt)^2
//   J  jerk: second difference of v over dt^2, squared
//   L  lane-centre offset: d^2, d the lateral distance to the matched lane's centre line
//   D  distance to obstacles: exp(-0.1 * (s_obs - s_ego - w / 2.5)) for the nearest obstacle
//      ahead in the ego's lane (lateral offsets within 2.8 m of each other, centre within 100 m
//      in x and y), 0 when there is none
// Also computed (not used by JB1 / WX1): path length (v), steering angle (delta^2), steering rate,
// yaw rate, orientation offset to the lane (all squared and integrated like the others).
//
// Approximations: CommonRoad maps the trajectory onto a lanelet route and converts it into a
// curvilinear frame along the route's smoothed centre line (route_matcher.py,
// LaneletRouteMatcher). Here each state is matched to the lanelet it stands on whose centre line
// runs closest to its heading (then nearest), and L, D and the orientation offset use that
// lanelet's centre line, extended along first successors and predecessors for D (up to 250 m).
// On straight lanes both agree; through lane changes and on curved roads L and D may differ by a
// few per cent from CommonRoad's figures. T, V, A and J are exact.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

// Unweighted partial costs of one trajectory (see above for each definition).
struct PartialCosts {
  double time = 0;                   // T, s
  double velocity_offset = 0;        // V
  double acceleration = 0;           // A
  double jerk = 0;                   // J
  double lane_center_offset = 0;     // L as commonroad_dc evaluates it (LC)
  double distance_to_obstacles = 0;  // D
  double path_length = 0;            // m
  double steering_angle = 0;         // SA
  double steering_rate = 0;          // SR
  double yaw_rate = 0;               // Y
  double orientation_offset = 0;     // O
};

struct CostTerm {
  std::string name;  // "T", "V", "A", "J", "D", "L"
  double weight = 0;
  double value = 0;  // unweighted
};

struct CostReport {
  std::string cost_function;  // "JB1" or "WX1"
  double total = 0;           // sum of weight * value
  std::vector<CostTerm> terms;
  PartialCosts partials;
};

// Composite Simpson's rule over equally spaced samples, scipy's simps(y, dx) with even='avg'.
// Fewer than two samples integrate to 0.
double Simpson(std::span<const double> y, double dx);

// Every partial cost of the trajectory (states at consecutive steps; fewer than two states give
// zeros except the offsets of the one state).
PartialCosts ComputePartialCosts(const Scenario& scenario, const PlanningProblem& problem,
                                 const VehicleParams& vehicle, std::span<const KsState> trajectory);

// "JB1" or "WX1"; any other id (CommonRoad's SA1, SM1, ... are not implemented) or an empty
// trajectory is an error.
StatusOr<CostReport> EvaluateCost(std::string_view cost_function, const Scenario& scenario,
                                  const PlanningProblem& problem, const VehicleParams& vehicle,
                                  std::span<const KsState> trajectory);

}  // namespace frenetic::commonroad

// CommonRoad's kinematic single-track model (KS; "CommonRoad: Vehicle Models", §KS;
// vehiclemodels/vehicle_dynamics_ks.py) and the state a KS solution trajectory carries.
//
// Reference point. A KS state's (x, y) is the vehicle's centre: the point b ahead of the rear
// axle on the vehicle's axis (b from VehicleParams). This is what CommonRoad's own tools do:
// the drivability checker's KinematicSingleTrackDynamics (feasibility/vehicle_dynamics.py)
// converts a state to the model's rear-axle coordinates with x_rear = x - b cos(psi),
// y_rear = y - b sin(psi) and back with + b, and its collision, road-boundary and goal checks
// (solution_checker.py: TrajectoryPrediction(trajectory, shape=Rectangle(l, w))) centre the
// vehicle's l x w rectangle on (x, y), oriented along psi. The planning problem's initial
// position is the same point.
//
// Dynamics, at the rear axle (x_r, y_r), state (x_r, y_r, delta, v, psi), input (steering rate
// u1, acceleration u2):
//   x_r' = v cos psi,  y_r' = v sin psi,  delta' = u1,  v' = u2,  psi' = v / l_wb * tan delta
// with CommonRoad's input constraints applied (steeringConstraints, accelerationConstraints):
// u1 is clipped to [steering_rate_min, max] and set to 0 when delta is at its limit and u1 would
// push beyond; u2 is clipped to [-a_max, MaxAcceleration(v)] and set to 0 when v is at v_min or
// v_max and u2 would push beyond.
#pragma once

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/vehicle_params.h"

namespace frenetic::commonroad {

struct KsState {
  int time_step = 0;
  double x = 0, y = 0;         // m, vehicle centre (see above)
  double steering_angle = 0;   // rad, front wheels
  double velocity = 0;         // m/s, along the vehicle's axis
  double orientation = 0;      // rad, counter-clockwise from +x
};

struct KsInput {
  double steering_rate = 0;  // rad/s
  double acceleration = 0;   // m/s^2
};

// The rear axle's centre of a state, and a centre from a rear-axle position.
Vec2 RearAxle(const KsState& s, const VehicleParams& p);
Vec2 CenterFromRearAxle(Vec2 rear, double orientation, const VehicleParams& p);

// The input after CommonRoad's constraints at (delta, v) (see above).
KsInput ConstrainInput(double steering_angle, double velocity, KsInput u, const VehicleParams& p);

// The state `dt` later under constant input `u` (constrained along the way, as CommonRoad's
// odeint simulation does), integrated with `substeps` classical Runge-Kutta steps. time_step
// advances by one.
KsState SimulateKs(const KsState& start, KsInput u, double dt, const VehicleParams& p,
                   int substeps = 10);

}  // namespace frenetic::commonroad

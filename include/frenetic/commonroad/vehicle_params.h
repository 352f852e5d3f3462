// The CommonRoad benchmark vehicles (types 1, 2, 3) with the parameters the kinematic
// single-track (KS) model uses.
//
// Values from CommonRoad's vehicle models (commonroad-vehicle-models, PYTHON/vehiclemodels/
// parameters_vehicle1.py, parameters_vehicle2.py, parameters_vehicle3.py; "CommonRoad: Vehicle
// Models", vehicleModels_commonRoad.pdf), which commonroad-io (common/solution.py VehicleType) and
// the drivability checker (feasibility/vehicle_dynamics.py VehicleParameterMapping) import. The
// axle distances a and b are given there in feet (unitConversion.ft_IN_m, 0.3048 m/ft):
//   1 Ford Escort  a 2.9 ft,      b 4.95 ft
//   2 BMW 320i     a 3.793293 ft, b 4.667707 ft
//   3 VW Vanagon   a 3.775563 ft, b 4.334437 ft
#pragma once

#include <string>

#include "frenetic/status.h"

namespace frenetic::commonroad {

struct VehicleParams {
  int type = 2;                  // CommonRoad vehicle type: 1, 2 or 3
  std::string name = "BMW 320i";
  double length = 4.508;         // m
  double width = 1.610;          // m
  double a = 3.793293 * 0.3048;  // m, centre of gravity to front axle
  double b = 4.667707 * 0.3048;  // m, centre of gravity to rear axle
  double steering_min = -1.066, steering_max = 1.066;            // rad
  double steering_rate_min = -0.4, steering_rate_max = 0.4;      // rad/s
  double v_min = -13.6, v_max = 50.8;                            // m/s
  double v_switch = 7.319;                                       // m/s
  double a_max = 11.5;                                           // m/s^2, absolute

  double Wheelbase() const { return a + b; }  // m
  // The largest forward acceleration at speed v (CommonRoad accelerationConstraints): a_max up to
  // v_switch, a_max * v_switch / v above it. m/s^2.
  double MaxAcceleration(double v) const;
  // "KS2": the vehicle id of CommonRoad's benchmark ids.
  std::string KsId() const { return "KS" + std::to_string(type); }
};

// Type 1 (Ford Escort), 2 (BMW 320i, the default) or 3 (VW Vanagon); an error otherwise.
StatusOr<VehicleParams> VehicleParamsForType(int type);

}  // namespace frenetic::commonroad

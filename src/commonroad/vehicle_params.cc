#include "frenetic/commonroad/vehicle_params.h"

namespace frenetic::commonroad {

namespace {
constexpr double kFoot = 0.3048;  // m
}  // namespace

double VehicleParams::MaxAcceleration(double v) const {
  return v > v_switch ? a_max * v_switch / v : a_max;
}

StatusOr<VehicleParams> VehicleParamsForType(int type) {
  VehicleParams p;  // type 2
  switch (type) {
    case 1:
      p.type = 1;
      p.name = "Ford Escort";
      p.length = 4.298;
      p.width = 1.674;
      p.a = 2.9 * kFoot;
      p.b = 4.95 * kFoot;
      p.steering_min = -0.910;
      p.steering_max = 0.910;
      p.steering_rate_min = -0.4;
      p.steering_rate_max = 0.4;
      p.v_min = -13.9;
      p.v_max = 45.8;
      p.v_switch = 4.755;
      p.a_max = 11.5;
      return p;
    case 2:
      return p;
    case 3:
      p.type = 3;
      p.name = "VW Vanagon";
      p.length = 4.569;
      p.width = 1.844;
      p.a = 3.775563 * kFoot;
      p.b = 4.334437 * kFoot;
      p.steering_min = -1.023;
      p.steering_max = 1.023;
      p.steering_rate_min = -0.4;
      p.steering_rate_max = 0.4;
      p.v_min = -11.2;
      p.v_max = 41.7;
      p.v_switch = 7.824;
      p.a_max = 11.5;
      return p;
    default:
      return Status::Error("vehicle type " + std::to_string(type) +
                           " is not a CommonRoad vehicle (1 Ford Escort, 2 BMW 320i, "
                           "3 VW Vanagon)");
  }
}

}  // namespace frenetic::commonroad

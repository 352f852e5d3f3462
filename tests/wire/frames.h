// Telemetry frames for the wire tests and the net tests: the simulator's real first message
// and frames of any size (for the limits and the abuse tests).
#pragma once

#include <string>
#include <string_view>

namespace frenetic::wire::testing {

// The simulator's first message after "Select" (udacity-sim.md §3.3, §4.3): field order, number
// text and the just-spawned car 0 as logged; the parked cars 1–11 as in the real recording.
inline constexpr std::string_view kFirstTelemetryJson =
    R"({"x":909.48,"y":1128.67,"yaw":0,"speed":0,"s":124.8336,"d":6.164833,)"
    R"("previous_path_x":[],"previous_path_y":[],"end_path_s":0,"end_path_d":0,)"
    R"("sensor_fusion":[[0,1056.788,1164.296,37.39919,15.43803,275.7777,5.999895],)"
    R"([1,775.8,1425.2,0,0,6719.219,-280.1494],[2,775.8,1429,0,0,6716.599,-282.9019],)"
    R"([3,775.8,1432.9,0,0,6713.911,-285.7268],[4,775.8,1436.3,0,0,6711.566,-288.1896],)"
    R"([5,775.8,1441.7,0,0,6661.772,-291.7797],[6,762.1,1421.6,0,0,6711.778,-268.0965],)"
    R"([7,762.1,1425.2,0,0,6709.296,-270.7039],[8,762.1,1429,0,0,6663.543,-273.1828],)"
    R"([9,762.1,1432.9,0,0,6660.444,-275.5511],[10,762.1,1436.3,0,0,6657.743,-277.6157],)"
    R"([11,762.1,1441.7,0,0,6653.453,-280.8947]]})";

inline std::string FirstTelemetryFrame() {
  return "42[\"telemetry\"," + std::string(kFirstTelemetryJson) + "]";
}

// A telemetry frame with the ego at (x, y) and a short previous path.
inline std::string TelemetryFrameAt(double x, double y) {
  return "42[\"telemetry\",{\"x\":" + std::to_string(x) + ",\"y\":" + std::to_string(y) +
         R"(,"yaw":0,"speed":10,"s":1,"d":6,"previous_path_x":[1,2],"previous_path_y":[3,4],)"
         R"("end_path_s":0,"end_path_d":0,"sensor_fusion":[[0,1,2,3,4,5,6]]})"
         "]";
}

// Frames of any size, for limits and abuse: a row the simulator could send; the first
// telemetry with `rows` such rows, or with a `points`-point previous path; with `junk` as the
// value of an extra field.
inline std::string SensorRow(int id) {
  std::string row = "[";
  row += std::to_string(id);
  row += ",1056.788,1164.296,37.39919,15.43803,275.7777,5.999895]";
  return row;
}

inline std::string FrameWithRows(int rows) {
  std::string f = R"(42["telemetry",{"x":909.48,"y":1128.67,"yaw":0,"speed":0,"s":124.8336,)"
                  R"("d":6.164833,"previous_path_x":[],"previous_path_y":[],"end_path_s":0,)"
                  R"("end_path_d":0,"sensor_fusion":[)";
  for (int i = 0; i < rows; ++i) {
    if (i > 0) f += ',';
    f += SensorRow(i);
  }
  return f + "]}]";
}

inline std::string FrameWithPath(int points) {
  std::string xs, ys;
  for (int i = 0; i < points; ++i) {
    if (i > 0) {
      xs += ',';
      ys += ',';
    }
    xs += std::to_string(900 + i);
    ys += "1128.671";
  }
  return R"(42["telemetry",{"x":909.48,"y":1128.67,"yaw":0,"speed":0,"s":124.8336,"d":6.164833,)"
         R"("previous_path_x":[)" +
         xs + R"(],"previous_path_y":[)" + ys +
         R"(],"end_path_s":0,"end_path_d":0,"sensor_fusion":[]}])";
}

inline std::string FrameWithJunk(const std::string& junk) {
  return R"(42["telemetry",{"x":909.48,"y":1128.67,"yaw":0,"speed":0,"s":124.8336,"d":6.164833,)"
         R"("junk":)" +
         junk +
         R"(,"previous_path_x":[],"previous_path_y":[],"end_path_s":0,)"
         R"("end_path_d":0,"sensor_fusion":[]}])";
}

}  // namespace frenetic::wire::testing

// The record format: what `frenetic drive --record` and `frenetic commonroad --record` write and
// `frenetic report` reads, in one place. JSON lines: one header line, one exchange line per
// planning cycle, one footer line at the end (a run cut short has none). A file whose name ends
// in ".gz" is one gzip stream of those lines (the reader tells gzip from text by the first
// byte). Writers: record::Writer (writer.h) with the lines formatted by the drive's record
// (drive/) and by commonroad::RunRecorder; reader: record::ReadRecord (reader.h).
//
// Header ("type": "header"):
//   "version"      kVersion
//   "map"          the track file (a drive) or the scenario file (CommonRoad)
//   "scenario"     the scenario's name (a drive) or the benchmark id (CommonRoad)
//   "seed"         the traffic's seed (0 for CommonRoad)
//   "planner"      the planner's name ("remote" for a drive over the network)
//   "config"       the planner configuration as JSON (YamlToJson: plan_json.h), or null
//   "timing"       a drive: the latency mode; CommonRoad: "wall" or "off"
//   "lanes", "lane_width", "max_s"         the road: lanes, m, the reference line's length, m
//   "car_length", "car_width"              m, every car's box (CommonRoad: the ego's)
//   a drive only: "cars" (the traffic's count), "centerline" ([[x, y], ...] every ~2 m, d = 0,
//     lanes to its right), "connect" (the planner server's URL, over the network only);
//   CommonRoad only: "world": "commonroad", "problem" (the planning problem's id), "dt" (s per
//     time step), "prediction", "vehicle" ("KS2"), "road": {"lanes": [{"left": {"x", "y"},
//     "right": {"x", "y"}}]} (each lane's borders, left to right, polylines, m, every ~2 m) and
//     "goals": [{"x", "y", "steps"}] (each goal region's outline, closed implicitly, and its time
//     window in steps, or null).
//
// Exchange ("type": "exchange"), one per planning cycle:
//   "i"            the cycle, from 0;  "t": simulated s when the telemetry was sent
//   "step"         CommonRoad: the time step
//   "telemetry"    a drive: the simulator's own JSON text of the telemetry sent (wire/protocol.h:
//                  mph, degrees, float32 numbers); CommonRoad: x, y, yaw (deg), speed (mph), s,
//                  d and "sensor_fusion" rows [id, x, y, vx, vy, s, d, length, width, heading
//                  in degrees]
//   "path"         {"x": [...], "y": [...]}: the path sent, m, map frame, a point per 0.02 s
//   "plan"         PlanJson (plan_json.h): "status", "ms_total" and, from an in-process planner,
//                  the counts, "rejections" by reason, "winner_costs" [{name, weight, value}],
//                  the winner's lane, end speed and duration, the refinement and "candidates" (best
//                  first: lane, end_speed, duration, total_cost, checked, winner, reject,
//                  reject_car, reject_t, x, y at 0.1 m, costs). Times are 0 with timing off, so the
//                  same seed gives byte-identical records.
//   "metrics"      the simulator's measures after the exchange: speed_mph, lane and, from a
//                  drive, acc, acc_t, acc_n, jerk, gap, headway, leader, distance_m,
//                  curr_miles, best_miles, l_old, l_new
//   "incidents"    the incidents that began in the exchange: [{t, s, d, lane, kind, value}]
//
// Footer ("type": "footer"): "report", the run's report: a drive's DriveReport::ToJson()
// (drive/drive_report.h: miles, incidents and incidents_by_kind, plan_ms {p50, p99, max},
// incident_log...), a CommonRoad run's verdict ("solved", "goal_step", "stop_reason",
// "failures" [{kind, step, detail, obstacle, obstacle_entered_s (when a collision's car came
// into the scene after the start: s before the contact)}], "incidents" by kind, "steps",
// "distance_m", "sim_seconds", "avg_speed_mph", "max_speed_mph", "plan_ms" {p50, p99, max},
// "plan_fallbacks").
#pragma once

namespace frenetic::record {

inline constexpr int kVersion = 1;

// The keys every writer and the reader share: the line types, the header's fields and the
// sections of an exchange line. (A section's own fields are written in one place each:
// PlanJson, the drive's metrics, and read in reader.cc.)
namespace key {

inline constexpr char kType[] = "type";
inline constexpr char kHeader[] = "header";
inline constexpr char kExchange[] = "exchange";
inline constexpr char kFooter[] = "footer";

// Header.
inline constexpr char kVersion[] = "version";
inline constexpr char kMap[] = "map";
inline constexpr char kScenario[] = "scenario";
inline constexpr char kSeed[] = "seed";
inline constexpr char kPlanner[] = "planner";
inline constexpr char kConfig[] = "config";
inline constexpr char kTiming[] = "timing";
inline constexpr char kLanes[] = "lanes";
inline constexpr char kLaneWidth[] = "lane_width";
inline constexpr char kMaxS[] = "max_s";
inline constexpr char kCarLength[] = "car_length";
inline constexpr char kCarWidth[] = "car_width";
inline constexpr char kCars[] = "cars";
inline constexpr char kCenterline[] = "centerline";
inline constexpr char kConnect[] = "connect";
inline constexpr char kWorld[] = "world";
inline constexpr char kCommonRoad[] = "commonroad";  // the value of "world"
inline constexpr char kProblem[] = "problem";
inline constexpr char kDt[] = "dt";
inline constexpr char kPrediction[] = "prediction";
inline constexpr char kVehicle[] = "vehicle";
inline constexpr char kRoad[] = "road";  // {"lanes": [{"left": {"x", "y"}, "right": ...}]}
inline constexpr char kLeft[] = "left";
inline constexpr char kRight[] = "right";
inline constexpr char kGoals[] = "goals";  // [{"x", "y", "steps"}]
inline constexpr char kSteps[] = "steps";

// Exchange.
inline constexpr char kCycle[] = "i";
inline constexpr char kTime[] = "t";
inline constexpr char kStep[] = "step";
inline constexpr char kTelemetry[] = "telemetry";
inline constexpr char kSensorFusion[] = "sensor_fusion";
inline constexpr char kPath[] = "path";
inline constexpr char kPlan[] = "plan";
inline constexpr char kMetrics[] = "metrics";
inline constexpr char kIncidents[] = "incidents";

// Footer.
inline constexpr char kReport[] = "report";

}  // namespace key
}  // namespace frenetic::record

// Fidelity of the headless simulator against recordings of the real Unity simulator
// (udacity-sim.md §14, shared/realdata/telemetry): `frenetic fidelity` runs every check below.
//  - Protocol: every recorded telemetry object, framed as the simulator frames it, goes through
//    wire::ParseFrame and a planner; the reply goes through wire::FormatControl / wire::ParseReply.
//  - Frenet: the chord-based s, d of the ego, of every sensor_fusion row and of end_path,
//    recomputed from x, y, match the recorded values (documented quirks counted apart).
//  - Ego motion: the recorded reply k, through the simulator's trimming and one-point-per-tick
//    consumption (sim/ego.h), reproduces message k+1 (previous_path, position, speed, yaw).
//  - Traffic: statistics of the simulated traffic (drive/traffic_runs.h) next to the same
//    statistics of the recordings.
// Units: metres, seconds, m/s inside; the recorded wire values (mph, degrees) are kept as
// recorded in RecordedMessage and compared in their own units. Nothing here throws or prints.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/plan/planner.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"
#include "frenetic/status.h"

namespace frenetic::sim {

// One telemetry object as recorded (wire units: speed mph, yaw degrees).
struct RecordedMessage {
  std::string json;  // the object exactly as recorded (one line, no frame)
  double x = 0, y = 0, yaw_deg = 0, speed_mph = 0, s = 0, d = 0;
  double end_path_s = 0, end_path_d = 0;
  std::vector<double> path_x, path_y;                // previous_path_x / _y
  std::vector<std::array<double, 7>> sensor_fusion;  // id, x, y, vx, vy, s, d
};

// A consecutive run from the start: message k and the planner's reply k to it.
struct Recording {
  std::string name;                      // e.g. "Moecker__sdc_path_planning__advanced"
  std::vector<RecordedMessage> messages;
  std::vector<std::string> replies;      // full `42["control",{...}]` frames, same count
};

// Parses one run: `input_text` holds one telemetry object per line, `response_text` one reply
// frame per line (blank lines ignored). Errors name `name`, the file kind and the 1-based line
// (bad JSON, a missing or non-numeric field, unequal line counts).
StatusOr<Recording> ParseRecording(std::string name, std::string_view input_text,
                                   std::string_view response_text);
// Loads every pair `<prefix>input-NAME.json` + `<prefix>response-NAME.json` in `dir` (sorted by
// file name). Fails if `dir` cannot be read or holds no pair.
StatusOr<std::vector<Recording>> LoadRecordings(const std::string& dir);

// One line of the fidelity table. `worst` is the largest deviation seen (in `unit`) over all
// compared values, failing or not; `tolerance` is the allowed deviation in the same unit.
struct CheckRow {
  std::string check;   // e.g. "frenet: sensor_fusion s,d"
  long cases = 0;      // messages, rows or message pairs compared
  long passed = 0;
  double worst = 0;
  double tolerance = 0;
  std::string unit;    // of worst and tolerance ("m", "mph", "deg", "digits", "")
  std::vector<std::string> failures;  // the first few failing cases, one line each
  bool ok() const { return cases > 0 && passed == cases; }
};

// A documented quirk of the real simulator found in the data, counted apart from the checks.
struct QuirkCount {
  std::string check;  // the check it belongs to
  std::string name;
  long count = 0;
  std::string note;
};

struct CheckReport {
  std::vector<CheckRow> rows;
  std::vector<QuirkCount> quirks;
  bool ok() const;
  void Append(const CheckReport& other);
};

// Values printed by the simulator (.NET float.ToString(): float32, 7 significant digits):
// true when `recorded` is `value` rounded to float32 and then to 7 significant digits (either
// rounding of a tie). DigitsOff gives the difference in units of that 7th digit.
bool EqualAsPrinted(double value, double recorded);
double DigitsOff(double value, double recorded);

// --- Protocol -----------------------------------------------------------------------------
// Frames every message as `42["telemetry",<json>]`, parses it with wire::ParseFrame (must be
// kTelemetry with no repair, fields equal to the recorded ones), plans with `planner` (Reset at
// the start of each recording, messages in order), formats the result with wire::FormatControl
// and parses that with wire::ParseReply: equal arrays equal to the plan, finite, >= 50 points.
CheckReport CheckProtocol(std::span<const Recording> recordings, plan::Planner& planner);

// --- Frenet -------------------------------------------------------------------------------
// Frenet of point (px, py) with the waypoint segment chosen from owner (ox, oy), as
// map::ChordFrenet::Convert. A replaceable function so that a wrong conversion can be shown to
// fail the check.
using FrenetFn = std::function<map::FrenetPoint(double px, double py, double ox, double oy)>;
FrenetFn ChordFrenetFn(std::shared_ptr<const World> world);  // the simulator's conversion

// Tolerance of the Frenet comparisons, m (float32 printed with 7 digits is ~5e-4 m at 6000 m).
inline constexpr double kFrenetTolerance = 0.01;

// Ego s, d; every sensor_fusion row's s, d; end_path s, d as the last previous_path point with
// the ego as owner (0, 0 for an empty path). Rows reported as s = d = 0 whose conversion is not
// 0 are the NaN -> 0 quirk; end_path values that the ego-owner quirk moves by more than the
// tolerance are counted too.
CheckReport CheckFrenet(std::span<const Recording> recordings, const FrenetFn& frenet);

// --- Ego motion ---------------------------------------------------------------------------
// The ego's path following, as a replaceable model. The default wraps sim::EgoCar.
class EgoModel {
 public:
  virtual ~EgoModel() = default;
  // A control message's path (m, map frame), trimmed by the model's rule.
  virtual void ApplyPath(std::span<const double> x, std::span<const double> y) = 0;
  virtual void Tick() = 0;  // one 0.02 s tick
  virtual float x() const = 0;
  virtual float y() const = 0;
  virtual double yaw() const = 0;   // rad, counter-clockwise from +x
  virtual float speed() const = 0;  // m/s
  virtual std::span<const float> path_x() const = 0;  // unvisited points
  virtual std::span<const float> path_y() const = 0;
};
// Builds a model at position (x, y) (m) with heading yaw (rad) and no path.
using EgoModelFactory = std::function<std::unique_ptr<EgoModel>(float x, float y, double yaw)>;
EgoModelFactory SimulatorEgoModel();  // sim::EgoCar: the headless simulator's own code

// Yaw is compared with this tolerance: Unity turns the car with a quaternion in float32, which
// is not reproduced bit for bit.
inline constexpr double kYawToleranceDeg = 0.05;
// Speed is compared to 2 units of the 7th digit (~5 float32 ulps at 49 mph): Unity's rigidbody
// velocity is not rounded exactly like displacement / 0.02 s in float (97% are bit-exact).
inline constexpr double kSpeedToleranceDigits = 2;

// For every pair (message k, message k+1): the consumed count c = |reply k| - |previous_path
// k+1| is inferred from the data; the latency split (l_old ticks before the reply, c - l_old
// after) is not observable, so EVERY split 0 <= l_old < c must reproduce message k+1: the model
// starts at message k's pose with message k's previous_path, ticks l_old times, applies reply k
// (parsed with wire::ParseReply), ticks c - l_old times; then previous_path, x, y and speed
// (float32, as printed; speed to kSpeedToleranceDigits) and yaw (kYawToleranceDeg) must equal
// message k+1's. The first move
// from the start pose (message k with an empty previous_path) reports a speed that includes the
// car settling vertically: counted as a quirk, not compared.
CheckReport CheckEgoMotion(std::span<const Recording> recordings, const EgoModelFactory& model);

// --- Traffic statistics ---------------------------------------------------------------------
// One message as the traffic statistics see it.
struct TrafficSample {
  double ego_s = 0;          // m, reported ego s
  double ego_speed = 0;      // m/s, reported ego speed
  double dt = 0;             // s since the previous message of the same run (0 for the first)
  int consumed = 0;          // path points consumed since the previous message (0 for the first)
  std::vector<std::array<double, 7>> cars;  // sensor_fusion rows: id, x, y, vx, vy, s, d
};

// Statistics computed as STATS.md does: samples per message; on-road cars 0 <= d <= 12; a
// re-spawn is a jump of more than 15 m from the constant-velocity prediction (or leaving and
// re-entering the road), and pairs across it are excluded from rates.
struct TrafficFigures {
  long messages = 0, car_samples = 0;
  double car_minutes = 0;
  std::vector<double> speeds;         // m/s, |(vx, vy)| of on-road cars
  std::vector<double> dvdt;           // m/s^2, consecutive on-road samples of one car
  int lane_crossings = 0;             // d crossing 4 or 8 between consecutive samples
  std::vector<double> spawn_ahead;    // m, s offset from the ego of spawns ahead (first
  std::vector<double> spawn_behind;   //   on-road sample of an id, and re-spawns), and behind
  std::vector<double> rel_s;          // m, car s minus ego s (wrapped), on-road samples
  std::vector<double> consumed;       // points per message
  std::vector<double> ego_speeds;     // m/s, the ego's reported speed, every message
};

class TrafficStatsBuilder {
 public:
  explicit TrafficStatsBuilder(double max_s) : max_s_(max_s) {}
  // Adds one run, messages in order.
  void AddRun(std::span<const TrafficSample> run);
  const TrafficFigures& figures() const { return f_; }

 private:
  double max_s_;
  TrafficFigures f_;
};

// The recordings as traffic samples (dt from the consumed counts of the replies).
std::vector<TrafficSample> RecordingTrafficSamples(const Recording& recording);

// One compared statistic: real (recordings) vs simulated, ratio sim / real, allowed band.
struct StatRow {
  std::string name, unit;
  double real = 0, sim = 0, ratio = 0;
  double lo = 0.8, hi = 1.25;  // allowed ratio band
  long real_n = 0, sim_n = 0;  // samples behind each figure
  bool ok() const { return ratio >= lo - 1e-12 && ratio <= hi + 1e-12; }
};
std::vector<StatRow> CompareTraffic(const TrafficFigures& real, const TrafficFigures& sim);

// How a recorded ego drove: its reported speed and d against simulated time (points consumed
// x 0.02 s), for replaying it in the traffic runs. The traffic statistics depend on the ego
// (cars queue behind a slow one), so a like-for-like comparison drives the simulated ego the
// way the recorded one drove.
struct EgoProfile {
  std::string name;
  std::vector<double> t;      // s since the first message, increasing
  std::vector<double> speed;  // m/s
  std::vector<double> d;      // m, reported (chord) d
  double duration() const { return t.empty() ? 0.0 : t.back(); }
  // Linear interpolation at `time` s (clamped to the ends); 0 / 6 m when empty.
  double SpeedAt(double time) const;
  double DAt(double time) const;
};
// The ego's speed and d of one recording (time from the consumed counts of the replies).
EgoProfile RecordingEgoProfile(const Recording& recording);

// Rows of the fidelity table from the statistic comparison (one per StatRow, "traffic: ...").
CheckReport TrafficReport(std::span<const StatRow> rows);

}  // namespace frenetic::sim

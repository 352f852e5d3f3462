// A scenario of the headless simulator: traffic parameters, timing (latency) mode, car box,
// start pose, incident thresholds and quirks. Loaded from config/scenarios/NAME.yaml; every key
// is optional (the defaults are the faithful Udacity simulator, udacity-sim.md §2, §7, §8) and
// unknown keys are errors naming the file and the key.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/status.h"

namespace frenetic::sim {

inline constexpr double kTick = 0.02;  // s, the physics step

// How replies meet the simulator's ticks (§2). Per exchange the simulator sends telemetry,
// advances `l_old` ticks on the old path while the reply is "in flight", applies the new path
// (closest-point trimming) and advances `l_new` >= 1 ticks before the next telemetry.
struct TimingOptions {
  enum class Mode { kLockstep, kFixed, kRandom };
  Mode mode = Mode::kLockstep;  // lockstep: l_old 0, l_new 1
  int l_old = 1, l_new = 2;     // kFixed
  int l_old_min = 0, l_old_max = 2;  // kRandom: uniform integers, inclusive
  int l_new_min = 1, l_new_max = 2;
  Status Validate() const;
};
const char* ToString(TimingOptions::Mode mode);
// "lockstep", "fixed", "random"; an error naming the value otherwise.
StatusOr<TimingOptions::Mode> ParseTimingMode(std::string_view text);

// Where the ego starts. Exactly one form applies:
//  - kAuto: on the Udacity map the real start pose (x 909.48, y 1128.67, yaw 0); on any other
//    map the middle lane at s = 124.8336 of the smooth line, facing the road.
//  - kXY: explicit map position (m) and yaw (degrees, counter-clockwise from +x).
//  - kFrenet: (s, d) on the smooth line, facing the road; s < 0 counts back from the loop end.
struct StartPose {
  enum class Kind { kAuto, kXY, kFrenet };
  Kind kind = Kind::kAuto;
  double x = 0, y = 0, yaw_deg = 0;
  double s = 0, d = 6;
};

// The proportional throttle law (§8.3) with a quadratic drag term, which gives the steady-state
// error that keeps cars several mph below their top speed:
//   a = A_max * clamp(gain * (top_mph - v_mph), -1, 1) * wander - drag * v^2
//       - linear_drag * v   (throttle)
// Unity's Rigidbody.drag damps velocity linearly; with it alone the free cruise speed is a fixed
// fraction of the top speed, as recorded.
struct TrafficOptions {
  int cars = 12;                       // forward cars reported in sensor_fusion, ids 0..cars-1
  double respawn_distance = 200;       // m, Euclidean distance to the ego that queues a respawn
  int batch_min = 1, batch_max = 3;    // cars respawned per scheduler run
  int period_min_frames = 20, period_max_frames = 59;  // frames between scheduler runs
  // Rendered frames per simulated second: the respawn scheduler runs on frames (§2, §8.2).
  // 50 is one frame per physics tick; the recordings' spawn batches came every 1.06 s on
  // average, i.e. about 38 frames per second with the 21-60 frame period.
  double frame_rate = 50;              // Hz
  int spawn_retries = 500;             // placement attempts per car
  double spawn_clearance = 6;          // m, no other car may be closer to a spawn point
  int behind_offset_min = -3, behind_offset_max = -2;  // waypoint index offsets from the ego
  int ahead_offset_min = 4, ahead_offset_max = 5;
  double behind_speed_min_mph = 50, behind_speed_max_mph = 60;  // top speed of behind spawns
  double ahead_speed_min_mph = 40, ahead_speed_max_mph = 50;
  double max_accel = 4.0;              // m/s^2 at full throttle
  double throttle_gain = 0.04;         // 1/mph
  double drag = 0.0037;                // 1/m (a_drag = drag * v^2)
  double linear_drag = 0;              // 1/s (a_drag = linear_drag * v), Unity Rigidbody.drag
  double brake_decel = 9.0;            // m/s^2, full brake when following too close
  double brake_gap_min = 10, brake_gap_max = 20;  // m, clamp of the source's trigger gap
  // s the "too close" test must hold (or fail) before a car starts (or stops) braking: Unity's
  // reaction lag, which keeps the brake/throttle cycle of a queued car from dying out.
  double brake_delay = 0;
  // s the test must fail before a braking car lets go; negative: brake_delay (symmetric lag).
  double brake_release_delay = -1;
  // The source's units mix while too close (§8.3, scene BrakeCondition NeverBrake): the desired
  // speed becomes the leader's speed in m/s taken as mph, so the car brakes (proportionally
  // within 1 mph) only down to leader_mps / 2.237 m/s and, once slower, throttles gently back up
  // to it until the gap opens. Off: it brakes at brake_decel for as long as it is too close.
  bool brake_to_leader_mph = true;
  double follow_lateral = 2.0;         // m, |Δd| under which a car is "in front" (ray-cast)
  double wander_min = 0.3, wander_max = 0.5;  // m, lateral wander amplitude per car
  double wander_period_min = 8, wander_period_max = 20;  // s
  // m/s: below this speed the wander runs slower, in proportion, and stands with the car. Unity's
  // cars steer toward a point tens of metres ahead, so their lateral motion comes with their
  // speed (at most a few degrees off the lane); a wander in time alone would slide a car in a
  // queue sideways and turn its box up to tens of degrees at a crawl. 0: in time alone.
  double wander_full_speed = 5;
  double throttle_wander = 0.1;        // throttle factor in [1 - throttle_wander, 1]
  bool lane_changes = true;            // the §8.5 rule
  double lane_change_gap = 20;         // m, |Δs| every car in the target lane must exceed
  double lane_change_ego_band = 3;     // m, the ego counts when its d is this close to the lane
  double lane_change_min_mph = 15;
  int lane_change_spacing_ticks = 100;
  int lane_change_evaluations = 50;    // the test must pass more often than this in a row
  double lane_change_duration = 2.0;   // s, lateral manoeuvre
  double waypoint_window = 15;         // m, a change starts only this close to the next waypoint
  bool spawn_speed_quirk = true;       // §8.6: speed in the wrong unit for one message
  bool seam_glitch = true;             // §8.6: s = d = 0 just after the seam
  double seam_glitch_window = 10;      // m of line s after the seam where it happens
  // Harder traffic (not in the real simulator; all off by default).
  double cut_in_rate = 0;              // 1/s, chance rate that an adjacent car cuts in
  double cut_in_min_gap = 6, cut_in_max_gap = 20;  // m, bumper gap ahead of the ego
  double cut_in_duration = 1.5;        // s, its lateral manoeuvre
  // m/s: a car slower than the ego by more than this does not cut in (nor does one below the
  // §8.5 lane-change speed): a slow car pulling in a few metres ahead of a fast one makes a
  // crash no driver could avoid, which measures nothing.
  double cut_in_max_closing = 5;
  double hard_brake_rate = 0;          // 1/s, chance rate that the ego's leader brakes hard
  double hard_brake_decel = 8;         // m/s^2
  double hard_brake_duration = 1.5;    // s
  double hard_brake_max_distance = 50;  // m ahead of the ego
  double event_cooldown = 8;           // s between two cut-ins / hard brakes
  // Blockade: at start, one slow car per lane this far ahead of the ego, for `blockade_seconds`.
  bool blockade = false;
  double blockade_distance = 70;       // m
  double blockade_speed = 8;           // m/s top speed while it lasts
  double blockade_seconds = 40;
  Status Validate() const;
};

struct IncidentOptions {
  double speed_limit_mph = 50;    // > this per tick
  double acc_limit = 10;          // m/s^2, >= on 10-tick blocks
  double jerk_limit = 10;         // m/s^3, >= on 1 s blocks
  int lane_line_ticks = 150;      // > this many ticks straddling a lane line
  int display_hold_frames = 51;   // UI hold of collision/speed/lane flags (distance reset)
  // Two onsets of the same kind closer than this (ticks since the last active tick) are one
  // incident in the log and the counts.
  int merge_ticks = 50;
  Status Validate() const;
};

struct Scenario {
  std::string name = "udacity";
  std::string description;
  std::string source;               // file it was read from ("" for built-in defaults)
  std::uint64_t seed = 1;           // default seed (the command line may override it)
  StartPose start;
  double car_length = 4.6, car_width = 2.4;  // m, oriented collision box of every car
  TimingOptions timing;
  TrafficOptions traffic;
  IncidentOptions incidents;
  Status Validate() const;
};

// Parses scenario YAML. Errors name `source` and the key (e.g. "traffic.brake_decel").
StatusOr<Scenario> ParseScenario(std::string_view yaml_text, std::string_view source);
// A name (letters, digits, '-', '_') reads FRENETIC_SOURCE_DIR/config/scenarios/NAME.yaml;
// anything else is a file path.
StatusOr<Scenario> LoadScenario(const std::string& name_or_path);
// Names of the bundled scenarios (sorted).
std::vector<std::string> ScenarioNames();
std::string ScenarioDir();

}  // namespace frenetic::sim

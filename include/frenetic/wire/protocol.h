// The simulator's wire protocol (udacity-sim.md §3): socket.io-flavoured text frames
// `42["telemetry",{...}]`, `42["control",{"next_x":[...],"next_y":[...]}]`, `42["manual",{}]`.
// Units on the wire: speed mph, yaw degrees; converted here to and from plan::Telemetry (SI).
// The codec alone, text in and text out: net/ carries the frames over a WebSocket, the
// in-process drive (drive/) and the fidelity checks (eval/) use it without one.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/plan/telemetry.h"
#include "frenetic/status.h"
#include "frenetic/wire/precision.h"

namespace frenetic::wire {

enum class FrameKind {
  kTelemetry,      // 42["telemetry",{...}] with a usable payload
  kNullTelemetry,  // 42["telemetry",null]: answer manual
  kOtherEvent,     // any other 42 event: answer manual
  kPing,           // engine.io "2": ignore (or answer "3")
  kIgnored,        // anything that is not a 42 frame and needs no answer
  kMalformed,      // a 42 frame that could not be understood: answer manual, log `error`
  kRefused,        // a 42 frame over FrameLimits, not converted: answer manual, log `error`
};
const char* ToString(FrameKind kind);

// What one frame may hold, far above what the simulator sends (12 cars, at most ~100 path
// points), so that converting any frame costs at most ~1 ms however it is made: a frame over
// them is refused (kRefused) before any JSON value is built, by a size check and then a single
// scan of its text that stops at the first excess. Besides the two counts, the scan bounds
// separators (so values: 2 * max_path_points + 8 * max_sensor_rows + 64), strings
// (kMaxFrameStringBytes), other tokens such as numbers (kMaxFrameTokenBytes) and the text
// itself ((separators + 1) * (kMaxFrameTokenBytes + 16) bytes, which leaves room for
// indentation but not for megabytes of padding), whatever field they are in.
struct FrameLimits {
  int max_sensor_rows = 64;    // sensor_fusion rows
  int max_path_points = 1000;  // previous_path_x / previous_path_y elements, each

  Status Validate() const;  // a message naming the bad limit
};
inline constexpr std::size_t kMaxFrameStringBytes = 256;
inline constexpr std::size_t kMaxFrameTokenBytes = 32;

struct ParsedFrame {
  FrameKind kind = FrameKind::kIgnored;
  plan::Telemetry telemetry;  // valid for kTelemetry
  std::string error;          // one line naming what was wrong (kMalformed, or repaired fields)
};

// Parses one text frame. Never throws; hostile input yields kMalformed (or kRefused, over
// `limits`) with a message. The whole frame is parsed as JSON. The ego fields (x, y, yaw, speed,
// s, d, end_path_s, end_path_d) must be finite numbers and previous_path_x/y and sensor_fusion
// must be arrays, else kMalformed naming the field; more sensor_fusion rows or path points than
// the limits allow make it kRefused, naming the field. Within arrays everything good is kept: rows
// of sensor_fusion that are malformed (not 7 finite numbers, id not an integer) are dropped,
// previous_path points are cut at the first non-finite or non-number element, and unequal
// previous_path arrays are cut to the shorter one; `error` then names the first repair (and
// counts the others) while kind stays kTelemetry. Wire mph/degrees become m/s and radians.
ParsedFrame ParseFrame(std::string_view frame, const FrameLimits& limits = {});

// Appends `42["control",{"next_x":[...],"next_y":[...]}]` to *out (cleared first). Only finite
// numbers are written; both arrays always have the same length: min(x.size(), y.size()) points,
// cut before the first point with a non-finite coordinate or one beyond float32 range (which
// the simulator cannot parse): ControlPoints. Numbers are written with kControlDigits
// significant digits (far below the float32 resolution the simulator parses to):
// FormatControlNumber. ControlAsReceived gives the parsed result without the text.
// Returns the number of points written.
std::size_t FormatControl(std::span<const double> x, std::span<const double> y, std::string* out);
inline constexpr std::string_view kManualFrame = R"(42["manual",{}])";

// The telemetry as the simulator writes it (field names and order of §3.3, mph, degrees in
// [0, 360), numbers as float32 with 7 significant digits like .NET float.ToString(), sensor ids
// as integers), as the JSON object alone and as a whole frame. Non-finite numbers (which the
// simulator never sends) are written as 0. Numbers go through FormatTelemetryNumber;
// TelemetryAsReceived gives what ParseFrame makes of the frame, without the text.
std::string TelemetryToJson(const plan::Telemetry& telemetry);
std::string FormatTelemetryFrame(const plan::Telemetry& telemetry);
inline constexpr std::string_view kNullTelemetryFrame = R"(42["telemetry",null])";
inline constexpr std::string_view kPingFrame = "2";
inline constexpr std::string_view kPongFrame = "3";

// What the simulator (the client side) makes of a frame the planner sent.
enum class ReplyKind {
  kControl,    // 42["control",{...}] with usable next_x / next_y
  kManual,     // 42["manual",...]
  kPong,       // engine.io "3"
  kIgnored,    // anything else that is not a 42 frame
  kMalformed,  // a 42 frame the real simulator would choke on (it would stall): see `error`
};
const char* ToString(ReplyKind kind);

struct ParsedReply {
  ReplyKind kind = ReplyKind::kIgnored;
  std::vector<double> x, y;  // m, map frame (kControl); capacity is kept between calls
  std::string error;         // one line naming what was wrong (kMalformed)
};

// Parses a planner's reply into *out (reused to avoid allocation). Stricter than the simulator
// so planner bugs surface: next_x and next_y must be arrays of equal length whose elements are
// numbers finite as float32 (the real simulator throws on null or a shorter next_y and then
// silently stalls; a longer next_y it would tolerate is also reported here). Other fields are
// ignored, as the simulator reads the two arrays by name. Never throws.
void ParseReply(std::string_view frame, ParsedReply* out);

}  // namespace frenetic::wire

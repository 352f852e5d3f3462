// The simulator's wire protocol (udacity-sim.md §3): socket.io-flavoured text frames
// `42["telemetry",{...}]`, `42["control",{"next_x":[...],"next_y":[...]}]`, `42["manual",{}]`.
// Units on the wire: speed mph, yaw degrees; converted here to and from plan::Telemetry (SI).
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "frenetic/plan/telemetry.h"
#include "frenetic/status.h"

namespace frenetic::net {

enum class FrameKind {
  kTelemetry,      // 42["telemetry",{...}] with a usable payload
  kNullTelemetry,  // 42["telemetry",null]: answer manual
  kOtherEvent,     // any other 42 event: answer manual
  kPing,           // engine.io "2": ignore (or answer "3")
  kIgnored,        // anything that is not a 42 frame and needs no answer
  kMalformed,      // a 42 frame that could not be understood: answer manual, log `error`
};

struct ParsedFrame {
  FrameKind kind = FrameKind::kIgnored;
  plan::Telemetry telemetry;  // valid for kTelemetry
  std::string error;          // one line naming what was wrong (kMalformed, or repaired fields)
};

// Parses one text frame. Never throws; hostile input yields kMalformed with a message.
// Non-finite numbers are rejected, rows of sensor_fusion that are malformed are dropped with a
// message (the rest is kept), unequal previous_path arrays are cut to the shorter one.
ParsedFrame ParseFrame(std::string_view frame);

// Appends `42["control",{"next_x":[...],"next_y":[...]}]` to *out (cleared first). Only finite
// numbers are written; both arrays always have the same length.
void FormatControl(std::span<const double> x, std::span<const double> y, std::string* out);
inline constexpr std::string_view kManualFrame = R"(42["manual",{}])";

// The telemetry as the simulator writes it (field names of §3.3, mph, degrees, float32 text),
// as the JSON object alone and as a whole frame.
std::string TelemetryToJson(const plan::Telemetry& telemetry);
std::string FormatTelemetryFrame(const plan::Telemetry& telemetry);
inline constexpr std::string_view kNullTelemetryFrame = R"(42["telemetry",null])";

}  // namespace frenetic::net

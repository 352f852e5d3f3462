// libFuzzer target for the wire protocol: ParseFrame and ParseReply on arbitrary bytes, and
// properties that must hold for whatever they accept:
//   - telemetry that parses formats back (as the simulator would write it) into telemetry that
//     parses cleanly with the same number of path points and sensor rows;
//   - FormatControl always writes valid JSON with equal-length arrays of the returned size;
//   - a control frame FormatControl wrote is accepted by ParseReply unless a value is beyond
//     float32 range (which the real simulator cannot parse either).
// Build: scripts/fuzz.sh (clang, -DFRENETIC_BUILD_FUZZERS=ON).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/wire/protocol.h"

namespace {

using frenetic::wire::FormatControl;
using frenetic::wire::FormatTelemetryFrame;
using frenetic::wire::FrameKind;
using frenetic::wire::ParsedFrame;
using frenetic::wire::ParsedReply;
using frenetic::wire::ParseFrame;
using frenetic::wire::ParseReply;
using frenetic::wire::ReplyKind;

void Require(bool condition) {
  if (!condition) std::abort();
}

void CheckControl(const std::vector<double>& x, const std::vector<double>& y) {
  std::string out;
  const std::size_t n = FormatControl(x, y, &out);
  Require(n <= std::min(x.size(), y.size()));
  const auto j = nlohmann::json::parse(out.substr(2), nullptr, /*allow_exceptions=*/false);
  Require(!j.is_discarded());
  Require(j[1]["next_x"].size() == n && j[1]["next_y"].size() == n);
  ParsedReply reply;
  ParseReply(out, &reply);
  if (reply.kind != ReplyKind::kControl) {
    Require(reply.kind == ReplyKind::kMalformed &&
            reply.error.find("float32") != std::string::npos);
  } else {
    Require(reply.x.size() == n && reply.y.size() == n);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view frame(reinterpret_cast<const char*>(data), size);

  const ParsedFrame parsed = ParseFrame(frame);
  Require(parsed.error.find('\n') == std::string::npos);
  if (parsed.kind == FrameKind::kTelemetry) {
    const auto& t = parsed.telemetry;
    Require(t.previous_path_x.size() == t.previous_path_y.size());
    const ParsedFrame again = ParseFrame(FormatTelemetryFrame(t));
    Require(again.kind == FrameKind::kTelemetry && again.error.empty());
    Require(again.telemetry.previous_path_x.size() == t.previous_path_x.size());
    Require(again.telemetry.sensor_fusion.size() == t.sensor_fusion.size());
    CheckControl(t.previous_path_x, t.previous_path_y);
  }

  ParsedReply reply;
  ParseReply(frame, &reply);
  if (reply.kind == ReplyKind::kControl) Require(reply.x.size() == reply.y.size());

  // The raw bytes as doubles (any bit pattern, NaN and inf included), split into x and y.
  const std::size_t count = size / sizeof(double);
  std::vector<double> values(count);
  if (count > 0) std::memcpy(values.data(), data, count * sizeof(double));
  const std::vector<double> x(values.begin(), values.begin() + count / 2);
  const std::vector<double> y(values.begin() + count / 2, values.end());
  CheckControl(x, y);
  return 0;
}

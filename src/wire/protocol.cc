// Wire protocol: parse with nlohmann (the whole frame, unlike the starter's substring cut),
// format with std::to_chars (fast, locale-independent, no allocation beyond the output).
#include "frenetic/wire/protocol.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <nlohmann/json.hpp>

namespace frenetic::wire {
namespace {

using nlohmann::json;

// Telemetry nests four levels deep (frame array, payload, sensor_fusion, row). Deeper input is
// hostile; refusing it before parsing bounds the parser's memory and time.
constexpr int kMaxDepth = 16;
constexpr std::size_t kMaxEventNameInMessage = 40;
constexpr std::size_t kMaxJsonErrorChars = 160;

// Collects the problems of one frame: the first is reported in full, the rest are counted, so
// the message stays one short line whatever the input.
class Problems {
 public:
  void Add(std::string message) {
    if (first_.empty()) {
      first_ = std::move(message);
    } else {
      ++more_;
    }
  }
  bool empty() const { return first_.empty(); }
  std::string Take() {
    if (more_ > 0) first_ += " (and " + std::to_string(more_) + " more problems)";
    return std::move(first_);
  }

 private:
  std::string first_;
  int more_ = 0;
};

const char* TypeName(const json& j) { return j.type_name(); }

// What the linear pre-scan of a frame's JSON text found wrong; empty when nothing.
struct Scan {
  bool too_deep = false;  // malformed: no real frame nests that deep
  std::string refused;    // over the limits: why
};

std::string LimitsText(const FrameLimits& limits) {
  return "limits: " + std::to_string(limits.max_sensor_rows) + " sensor_fusion rows, " +
         std::to_string(limits.max_path_points) + " path points";
}

// One pass over the text (strings skipped by their quotes) that bounds what the JSON parser will
// be given: nesting depth and, with limits, separators (so values), string and token lengths.
// It stops at the first excess, so a hostile frame costs at most one read of its bytes.
Scan ScanFrame(std::string_view text, const FrameLimits* limits) {
  Scan scan;
  constexpr std::size_t kUnlimited = std::numeric_limits<std::size_t>::max();
  std::size_t max_separators = kUnlimited, max_string = kUnlimited, max_token = kUnlimited;
  if (limits != nullptr) {
    max_separators = 2 * static_cast<std::size_t>(limits->max_path_points) +
                     8 * static_cast<std::size_t>(limits->max_sensor_rows) + 64;
    max_string = kMaxFrameStringBytes;
    max_token = kMaxFrameTokenBytes;
    // Room for every value at its longest, with a separator and some indentation each: more
    // than this is padding (whitespace), which is otherwise unlimited.
    const std::size_t max_bytes = (max_separators + 1) * (kMaxFrameTokenBytes + 16);
    if (text.size() > max_bytes) {
      scan.refused = std::to_string(text.size()) + " bytes, more than the " +
                     std::to_string(max_bytes) + " the limits allow (" + LimitsText(*limits) + ")";
      return scan;
    }
  }
  int depth = 0;
  std::size_t separators = 0, token = 0;
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n;) {
    const char c = text[i++];
    if (c == '"') {
      const std::size_t start = i;
      while (i < n && text[i] != '"') {
        i += text[i] == '\\' ? 2 : 1;
        if (i - start > max_string) {
          scan.refused = "a string of more than " + std::to_string(max_string) + " bytes";
          return scan;
        }
      }
      ++i;  // the closing quote (a truncated string is left to the parser to report)
      token = 0;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxDepth) {
        scan.too_deep = true;
        return scan;
      }
      token = 0;
    } else if (c == ']' || c == '}' || c == ':' || c == ' ' || c == '\n' || c == '\r' ||
               c == '\t') {
      if (c == ']' || c == '}') --depth;
      token = 0;
    } else if (c == ',') {
      if (++separators > max_separators) {
        scan.refused =
            "more than " + std::to_string(max_separators) + " values (" + LimitsText(*limits) + ")";
        return scan;
      }
      token = 0;
    } else if (++token > max_token) {
      scan.refused =
          "a number or literal of more than " + std::to_string(max_token) + " characters";
      return scan;
    }
  }
  return scan;
}

// Parses the JSON after a "42" prefix; a discarded value on any syntax error, or when the scan
// refuses it under `limits` (nullptr: depth only), which sets *refused.
json ParseJson(std::string_view text, const FrameLimits* limits, std::string* error,
               bool* refused) {
  const Scan scan = ScanFrame(text, limits);
  if (scan.too_deep) {
    *error = "JSON nested deeper than " + std::to_string(kMaxDepth) + " levels";
    return json(json::value_t::discarded);
  }
  if (!scan.refused.empty()) {
    *refused = true;
    *error = "frame refused unread: " + scan.refused;
    return json(json::value_t::discarded);
  }
  // The exception is caught at once: its message locates the problem (column, token).
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::exception& e) {
    std::string what = e.what();
    if (const std::size_t close = what.find("] "); close != std::string::npos) {
      what.erase(0, close + 2);
    }
    if (what.size() > kMaxJsonErrorChars) what = what.substr(0, kMaxJsonErrorChars) + "...";
    std::replace_if(what.begin(), what.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    *error = "not valid JSON after the 42 prefix: " + what;
    return json(json::value_t::discarded);
  }
}

// A short, single-line, escaped rendering of a value for messages.
std::string Describe(const json& j) {
  std::string s = j.dump(-1, ' ', /*ensure_ascii=*/true, json::error_handler_t::replace);
  if (s.size() > kMaxEventNameInMessage) s = s.substr(0, kMaxEventNameInMessage) + "...";
  return s;
}

// Reads payload[key] as a finite number; an error naming the field otherwise.
bool ReadNumber(const json& payload, const char* key, double* value, Problems* problems) {
  const auto it = payload.find(key);
  if (it == payload.end()) {
    problems->Add(std::string("telemetry.") + key + ": missing");
    return false;
  }
  if (!it->is_number()) {
    problems->Add(std::string("telemetry.") + key + ": expected a number, got " + TypeName(*it) +
                  (it->is_string() ? " " + Describe(*it) : ""));
    return false;
  }
  *value = it->get<double>();
  if (!std::isfinite(*value)) {
    problems->Add(std::string("telemetry.") + key + ": not finite");
    return false;
  }
  return true;
}

const json* FindArray(const json& payload, const char* key, Problems* problems) {
  const auto it = payload.find(key);
  if (it == payload.end()) {
    problems->Add(std::string("telemetry.") + key + ": missing");
    return nullptr;
  }
  if (!it->is_array()) {
    problems->Add(std::string("telemetry.") + key + ": expected an array, got " + TypeName(*it));
    return nullptr;
  }
  return &*it;
}

bool FiniteNumber(const json& j, double* value) {
  if (!j.is_number()) return false;
  *value = j.get<double>();
  return std::isfinite(*value);
}

// previous_path_x/y: keep the good prefix, so the path the planner re-sends stays contiguous.
void ReadPath(const json& xs, const json& ys, plan::Telemetry* t, Problems* repairs) {
  std::size_t n = std::min(xs.size(), ys.size());
  if (xs.size() != ys.size()) {
    repairs->Add("telemetry.previous_path_x/y: unequal lengths " + std::to_string(xs.size()) +
                 " and " + std::to_string(ys.size()) + ", cut to " + std::to_string(n));
  }
  t->previous_path_x.reserve(n);
  t->previous_path_y.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    double x = 0, y = 0;
    const bool x_ok = FiniteNumber(xs[i], &x);
    if (!x_ok || !FiniteNumber(ys[i], &y)) {
      repairs->Add(std::string("telemetry.previous_path_") + (x_ok ? "y" : "x") + "[" +
                   std::to_string(i) + "]: not a finite number, path cut to " +
                   std::to_string(i) + " points");
      break;
    }
    t->previous_path_x.push_back(x);
    t->previous_path_y.push_back(y);
  }
}

// One sensor_fusion row [id, x, y, vx, vy, s, d]; false (with a reason) when it must be dropped.
bool ReadSensorRow(const json& row, plan::SensorCar* car, std::string* why) {
  if (!row.is_array()) {
    *why = std::string("expected an array, got ") + TypeName(row);
    return false;
  }
  if (row.size() != 7) {
    *why = "expected 7 elements [id,x,y,vx,vy,s,d], got " + std::to_string(row.size());
    return false;
  }
  double v[7];
  static constexpr const char* kNames[7] = {"id", "x", "y", "vx", "vy", "s", "d"};
  for (int k = 0; k < 7; ++k) {
    if (!FiniteNumber(row[k], &v[k])) {
      *why = std::string(kNames[k]) + " is not a finite number";
      return false;
    }
  }
  if (v[0] != std::floor(v[0]) || v[0] < std::numeric_limits<int>::min() ||
      v[0] > std::numeric_limits<int>::max()) {
    *why = "id is not an integer";
    return false;
  }
  car->id = static_cast<int>(v[0]);
  car->x = v[1];
  car->y = v[2];
  car->vx = v[3];
  car->vy = v[4];
  car->s = v[5];
  car->d = v[6];
  return true;
}

void ParseTelemetry(const json& payload, const FrameLimits& limits, ParsedFrame* out) {
  Problems fatal;
  plan::Telemetry& t = out->telemetry;
  double yaw_deg = 0, speed_mph = 0;
  ReadNumber(payload, "x", &t.x, &fatal);
  ReadNumber(payload, "y", &t.y, &fatal);
  ReadNumber(payload, "yaw", &yaw_deg, &fatal);
  ReadNumber(payload, "speed", &speed_mph, &fatal);
  ReadNumber(payload, "s", &t.s, &fatal);
  ReadNumber(payload, "d", &t.d, &fatal);
  ReadNumber(payload, "end_path_s", &t.end_path_s, &fatal);
  ReadNumber(payload, "end_path_d", &t.end_path_d, &fatal);
  const json* xs = FindArray(payload, "previous_path_x", &fatal);
  const json* ys = FindArray(payload, "previous_path_y", &fatal);
  const json* rows = FindArray(payload, "sensor_fusion", &fatal);
  if (!fatal.empty()) {
    out->kind = FrameKind::kMalformed;
    out->error = fatal.Take();
    out->telemetry = plan::Telemetry();
    return;
  }
  // More than the limits is refused whole: cutting rows could drop the car ahead, and no
  // simulator sends that many.
  const auto over = [&](const char* what, std::size_t n, int limit) {
    out->kind = FrameKind::kRefused;
    out->error = std::string("telemetry.") + what + ": " + std::to_string(n) +
                 (what[0] == 's' ? " rows" : " points") + ", over the limit of " +
                 std::to_string(limit) + "; frame refused";
    out->telemetry = plan::Telemetry();
  };
  const auto max_points = static_cast<std::size_t>(limits.max_path_points);
  if (rows->size() > static_cast<std::size_t>(limits.max_sensor_rows)) {
    return over("sensor_fusion", rows->size(), limits.max_sensor_rows);
  }
  if (xs->size() > max_points) return over("previous_path_x", xs->size(), limits.max_path_points);
  if (ys->size() > max_points) return over("previous_path_y", ys->size(), limits.max_path_points);
  t.yaw = YawFromDegrees(yaw_deg);
  t.speed = SpeedFromMph(speed_mph);
  Problems repairs;
  ReadPath(*xs, *ys, &t, &repairs);
  t.sensor_fusion.reserve(rows->size());
  for (std::size_t i = 0; i < rows->size(); ++i) {
    plan::SensorCar car;
    std::string why;
    if (ReadSensorRow((*rows)[i], &car, &why)) {
      t.sensor_fusion.push_back(car);
    } else {
      repairs.Add("telemetry.sensor_fusion[" + std::to_string(i) + "]: " + why + ", row dropped");
    }
  }
  out->kind = FrameKind::kTelemetry;
  if (!repairs.empty()) out->error = repairs.Take();
}

// Appends a float32 rendering like .NET float.ToString() ("G7").
void AppendFloat32(double value, std::string* out) {
  char buf[kMaxNumberChars];
  out->append(buf, FormatTelemetryNumber(value, buf));
}

void AppendInt(int value, std::string* out) {
  char buf[16];
  const auto r = std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, r.ptr);
}

void AppendFloat32Array(const std::vector<double>& values, std::string* out) {
  out->push_back('[');
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out->push_back(',');
    AppendFloat32(values[i], out);
  }
  out->push_back(']');
}

void AppendTelemetryJson(const plan::Telemetry& t, std::string* out) {
  const auto field = [out](const char* name, double v) {
    out->append(name);
    AppendFloat32(v, out);
  };
  field("{\"x\":", t.x);
  field(",\"y\":", t.y);
  field(",\"yaw\":", YawToDegrees(t.yaw));
  field(",\"speed\":", SpeedToMph(t.speed));
  field(",\"s\":", t.s);
  field(",\"d\":", t.d);
  out->append(",\"previous_path_x\":");
  AppendFloat32Array(t.previous_path_x, out);
  out->append(",\"previous_path_y\":");
  AppendFloat32Array(t.previous_path_y, out);
  field(",\"end_path_s\":", t.end_path_s);
  field(",\"end_path_d\":", t.end_path_d);
  out->append(",\"sensor_fusion\":[");
  for (std::size_t i = 0; i < t.sensor_fusion.size(); ++i) {
    const plan::SensorCar& c = t.sensor_fusion[i];
    out->append(i > 0 ? ",[" : "[");
    AppendInt(c.id, out);
    for (double v : {c.x, c.y, c.vx, c.vy, c.s, c.d}) {
      out->push_back(',');
      AppendFloat32(v, out);
    }
    out->push_back(']');
  }
  out->append("]}");
}

// Splits a "42" frame into its event name and payload; false with *error when it is not
// ["<name>", payload].
bool SplitEvent(std::string_view frame, const FrameLimits* limits, json* doc, std::string* event,
                std::string* error, bool* refused) {
  *doc = ParseJson(frame.substr(2), limits, error, refused);
  if (doc->is_discarded()) return false;
  if (!doc->is_array() || doc->empty()) {
    *error = std::string("expected [\"<event>\", payload] after 42, got ") + TypeName(*doc);
    return false;
  }
  if (!(*doc)[0].is_string()) {
    *error = std::string("event name: expected a string, got ") + TypeName((*doc)[0]);
    return false;
  }
  *event = (*doc)[0].get<std::string>();
  return true;
}

bool ReadControlArray(const json& payload, const char* key, std::vector<double>* values,
                      std::string* error) {
  const auto it = payload.find(key);
  if (it == payload.end()) {
    *error = std::string("control.") + key + ": missing";
    return false;
  }
  if (!it->is_array()) {
    *error = std::string("control.") + key + ": expected an array, got " + TypeName(*it);
    return false;
  }
  values->clear();
  values->reserve(it->size());
  for (std::size_t i = 0; i < it->size(); ++i) {
    const json& e = (*it)[i];
    double v = 0;
    // float.Parse of the simulator overflows beyond float32 range: treat that as non-finite.
    if (!FiniteNumber(e, &v) || !std::isfinite(static_cast<float>(v))) {
      *error = std::string("control.") + key + "[" + std::to_string(i) +
               "]: expected a finite number, got " + (e.is_number() ? "a number beyond float32 range" : TypeName(e));
      return false;
    }
    values->push_back(v);
  }
  return true;
}

}  // namespace

const char* ToString(FrameKind kind) {
  switch (kind) {
    case FrameKind::kTelemetry: return "telemetry";
    case FrameKind::kNullTelemetry: return "null telemetry";
    case FrameKind::kOtherEvent: return "other event";
    case FrameKind::kPing: return "ping";
    case FrameKind::kIgnored: return "ignored";
    case FrameKind::kMalformed: return "malformed";
    case FrameKind::kRefused: return "refused";
  }
  return "?";
}

const char* ToString(ReplyKind kind) {
  switch (kind) {
    case ReplyKind::kControl: return "control";
    case ReplyKind::kManual: return "manual";
    case ReplyKind::kPong: return "pong";
    case ReplyKind::kIgnored: return "ignored";
    case ReplyKind::kMalformed: return "malformed";
  }
  return "?";
}

Status FrameLimits::Validate() const {
  if (max_sensor_rows < 1 || max_sensor_rows > 100000) {
    return Status::Error("max sensor rows: " + std::to_string(max_sensor_rows) +
                         " is not in [1, 100000]");
  }
  if (max_path_points < 1 || max_path_points > 1000000) {
    return Status::Error("max path points: " + std::to_string(max_path_points) +
                         " is not in [1, 1000000]");
  }
  return Status::Ok();
}

ParsedFrame ParseFrame(std::string_view frame, const FrameLimits& limits) {
  ParsedFrame out;
  if (frame.empty()) return out;
  if (frame.substr(0, 2) != "42") {
    // engine.io: "2" (or "2probe") is a ping; everything else needs no answer.
    out.kind = frame[0] == '2' ? FrameKind::kPing : FrameKind::kIgnored;
    return out;
  }
  json doc;
  std::string event;
  bool refused = false;
  if (!SplitEvent(frame, &limits, &doc, &event, &out.error, &refused)) {
    out.kind = refused ? FrameKind::kRefused : FrameKind::kMalformed;
    return out;
  }
  if (event != "telemetry") {
    out.kind = FrameKind::kOtherEvent;
    out.error = "event " + Describe(doc[0]) + " is not telemetry";
    return out;
  }
  if (doc.size() < 2) {
    out.kind = FrameKind::kMalformed;
    out.error = "telemetry payload: missing";
    return out;
  }
  if (doc[1].is_null()) {
    out.kind = FrameKind::kNullTelemetry;
    return out;
  }
  if (!doc[1].is_object()) {
    out.kind = FrameKind::kMalformed;
    out.error = std::string("telemetry payload: expected an object or null, got ") +
                TypeName(doc[1]);
    return out;
  }
  ParseTelemetry(doc[1], limits, &out);
  return out;
}

std::size_t FormatControl(std::span<const double> x, std::span<const double> y,
                          std::string* out) {
  // A coordinate beyond float32 range is one the simulator's float.Parse cannot read (and one
  // near DBL_MAX would round up to an overflowing literal at kControlDigits): cut there too.
  const std::size_t n = ControlPoints(x, y);
  out->clear();
  // Up to ~17 characters per number plus separators; reserving avoids regrowth.
  out->reserve(40 + 2 * 18 * n);
  const auto append_array = [out, n](std::span<const double> v) {
    char buf[kMaxNumberChars];
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0) out->push_back(',');
      out->append(buf, FormatControlNumber(v[i], buf));
    }
  };
  out->append(R"(42["control",{"next_x":[)");
  append_array(x);
  out->append(R"(],"next_y":[)");
  append_array(y);
  out->append("]}]");
  return n;
}

std::string TelemetryToJson(const plan::Telemetry& telemetry) {
  std::string out;
  out.reserve(512 + 20 * (telemetry.previous_path_x.size() + telemetry.previous_path_y.size()) +
              80 * telemetry.sensor_fusion.size());
  AppendTelemetryJson(telemetry, &out);
  return out;
}

std::string FormatTelemetryFrame(const plan::Telemetry& telemetry) {
  std::string out = R"(42["telemetry",)";
  out.reserve(512 + 20 * (telemetry.previous_path_x.size() + telemetry.previous_path_y.size()) +
              80 * telemetry.sensor_fusion.size());
  AppendTelemetryJson(telemetry, &out);
  out.push_back(']');
  return out;
}

void ParseReply(std::string_view frame, ParsedReply* out) {
  out->kind = ReplyKind::kIgnored;
  out->x.clear();
  out->y.clear();
  out->error.clear();
  if (frame.substr(0, 2) != "42") {
    if (frame == kPongFrame) out->kind = ReplyKind::kPong;
    return;
  }
  json doc;
  std::string event;
  out->kind = ReplyKind::kMalformed;
  bool refused = false;
  if (!SplitEvent(frame, nullptr, &doc, &event, &out->error, &refused)) return;
  if (event == "manual") {
    out->kind = ReplyKind::kManual;
    return;
  }
  if (event != "control") {
    out->error = "event " + Describe(doc[0]) + " is neither control nor manual";
    return;
  }
  if (doc.size() < 2 || !doc[1].is_object()) {
    out->error = std::string("control payload: expected an object, got ") +
                 (doc.size() < 2 ? "nothing" : TypeName(doc[1]));
    return;
  }
  if (!ReadControlArray(doc[1], "next_x", &out->x, &out->error) ||
      !ReadControlArray(doc[1], "next_y", &out->y, &out->error)) {
    return;
  }
  if (out->x.size() != out->y.size()) {
    out->error = "control: next_x has " + std::to_string(out->x.size()) + " points, next_y " +
                 std::to_string(out->y.size());
    return;
  }
  out->kind = ReplyKind::kControl;
}

}  // namespace frenetic::wire

// Wire protocol: parse with nlohmann (the whole frame, unlike the starter's substring cut),
// format with std::to_chars (fast, locale-independent, no allocation beyond the output).
#include "frenetic/net/protocol.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <nlohmann/json.hpp>

namespace frenetic::net {
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

// Bracket depth of the JSON text, skipping strings. Cheap pre-check before the real parse.
bool DepthWithin(std::string_view text, int max_depth) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return false;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return true;
}

// Parses the JSON after a "42" prefix; a discarded value on any syntax error.
json ParseJson(std::string_view text, std::string* error) {
  if (!DepthWithin(text, kMaxDepth)) {
    *error = "JSON nested deeper than " + std::to_string(kMaxDepth) + " levels";
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

void ParseTelemetry(const json& payload, ParsedFrame* out) {
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
  t.yaw = wire::YawFromDegrees(yaw_deg);
  t.speed = wire::SpeedFromMph(speed_mph);
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
  char buf[wire::kMaxNumberChars];
  out->append(buf, wire::FormatTelemetryNumber(value, buf));
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
  field(",\"yaw\":", wire::YawToDegrees(t.yaw));
  field(",\"speed\":", wire::SpeedToMph(t.speed));
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
bool SplitEvent(std::string_view frame, json* doc, std::string* event, std::string* error) {
  *doc = ParseJson(frame.substr(2), error);
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

ParsedFrame ParseFrame(std::string_view frame) {
  ParsedFrame out;
  if (frame.empty()) return out;
  if (frame.substr(0, 2) != "42") {
    // engine.io: "2" (or "2probe") is a ping; everything else needs no answer.
    out.kind = frame[0] == '2' ? FrameKind::kPing : FrameKind::kIgnored;
    return out;
  }
  json doc;
  std::string event;
  if (!SplitEvent(frame, &doc, &event, &out.error)) {
    out.kind = FrameKind::kMalformed;
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
  ParseTelemetry(doc[1], &out);
  return out;
}

std::size_t FormatControl(std::span<const double> x, std::span<const double> y,
                          std::string* out) {
  // A coordinate beyond float32 range is one the simulator's float.Parse cannot read (and one
  // near DBL_MAX would round up to an overflowing literal at kControlDigits): cut there too.
  const std::size_t n = wire::ControlPoints(x, y);
  out->clear();
  // Up to ~17 characters per number plus separators; reserving avoids regrowth.
  out->reserve(40 + 2 * 18 * n);
  const auto append_array = [out, n](std::span<const double> v) {
    char buf[wire::kMaxNumberChars];
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0) out->push_back(',');
      out->append(buf, wire::FormatControlNumber(v[i], buf));
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
  if (!SplitEvent(frame, &doc, &event, &out->error)) return;
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

}  // namespace frenetic::net

#include "frenetic/wire/protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "frenetic/units.h"
#include "wire/frames.h"

namespace frenetic::wire {
namespace {

using nlohmann::json;
using testing::FirstTelemetryFrame;
using testing::FrameWithJunk;
using testing::FrameWithPath;
using testing::FrameWithRows;
using testing::kFirstTelemetryJson;

std::string Frame(const json& payload) { return "42[\"telemetry\"," + payload.dump() + "]"; }

json FirstPayload() { return json::parse(kFirstTelemetryJson); }

TEST(ProtocolTest, ParsesTheRealFirstMessageIntoSi) {
  const ParsedFrame p = ParseFrame(FirstTelemetryFrame());
  ASSERT_EQ(p.kind, FrameKind::kTelemetry) << p.error;
  EXPECT_TRUE(p.error.empty()) << p.error;
  const plan::Telemetry& t = p.telemetry;
  EXPECT_DOUBLE_EQ(t.x, 909.48);
  EXPECT_DOUBLE_EQ(t.y, 1128.67);
  EXPECT_DOUBLE_EQ(t.yaw, 0);
  EXPECT_DOUBLE_EQ(t.speed, 0);
  EXPECT_DOUBLE_EQ(t.s, 124.8336);
  EXPECT_DOUBLE_EQ(t.d, 6.164833);
  EXPECT_TRUE(t.previous_path_x.empty());
  EXPECT_TRUE(t.previous_path_y.empty());
  ASSERT_EQ(t.sensor_fusion.size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(t.sensor_fusion[i].id, i);
  const plan::SensorCar& car0 = t.sensor_fusion[0];
  EXPECT_DOUBLE_EQ(car0.x, 1056.788);
  EXPECT_DOUBLE_EQ(car0.vx, 37.39919);  // m/s on the wire already: not converted
  EXPECT_DOUBLE_EQ(car0.vy, 15.43803);
  EXPECT_DOUBLE_EQ(car0.d, 5.999895);
  EXPECT_DOUBLE_EQ(t.sensor_fusion[1].d, -280.1494);
}

TEST(ProtocolTest, ConvertsMphAndDegreesToSi) {
  json j = FirstPayload();
  j["speed"] = 49.5;
  j["yaw"] = 90;
  const ParsedFrame p = ParseFrame(Frame(j));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry) << p.error;
  EXPECT_NEAR(p.telemetry.speed, 49.5 / units::kSimMpsToMph, 1e-12);
  EXPECT_NEAR(p.telemetry.speed, 22.1284, 1e-4);
  EXPECT_NEAR(p.telemetry.yaw, std::numbers::pi / 2, 1e-12);
}

TEST(ProtocolTest, FirstMessageFormatsBackToTheSameText) {
  const ParsedFrame p = ParseFrame(FirstTelemetryFrame());
  ASSERT_EQ(p.kind, FrameKind::kTelemetry);
  EXPECT_EQ(TelemetryToJson(p.telemetry), kFirstTelemetryJson);
  EXPECT_EQ(FormatTelemetryFrame(p.telemetry), FirstTelemetryFrame());
}

TEST(ProtocolTest, FormatsNumbersLikeDotNetFloat) {
  plan::Telemetry t;
  t.x = 909.536123;            // float32 → 909.5361
  t.y = 0.002 / 0.02 / units::kSimMpsToMph * units::kSimMpsToMph;
  t.speed = 0.002 / 0.02;      // 0.1 m/s = 0.2236936 mph
  t.yaw = -std::numbers::pi / 2;  // -90° is written as 270
  t.sensor_fusion.push_back({7, 1.0, 2.0, 0.0, 0.0, 1e-7, 12345678.0});
  const json j = json::parse(TelemetryToJson(t));
  const std::string text = TelemetryToJson(t);
  EXPECT_NE(text.find("\"x\":909.5361,"), std::string::npos) << text;
  EXPECT_NE(text.find("\"speed\":0.2236936,"), std::string::npos) << text;
  EXPECT_NE(text.find("\"yaw\":270,"), std::string::npos) << text;
  EXPECT_NE(text.find("[7,1,2,0,0,"), std::string::npos) << text;
  EXPECT_TRUE(j["sensor_fusion"][0][0].is_number_integer());
}

TEST(ProtocolTest, NonFiniteTelemetryIsWrittenAsZero) {
  plan::Telemetry t;
  t.x = std::nan("");
  t.s = INFINITY;
  t.previous_path_x = {1e300};
  t.previous_path_y = {2};
  const ParsedFrame p = ParseFrame(FormatTelemetryFrame(t));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry) << p.error;
  EXPECT_EQ(p.telemetry.x, 0);
  EXPECT_EQ(p.telemetry.s, 0);
  ASSERT_EQ(p.telemetry.previous_path_x.size(), 1u);
  EXPECT_EQ(p.telemetry.previous_path_x[0], 0);
}

// Every line of the real recording: parse, write back, and compare as JSON values. The
// recording's numbers are float32 text, so the round trip must reproduce them exactly.
TEST(ProtocolTest, RealRecordingRoundTrips) {
  const std::string path = std::string(FRENETIC_SHARED_DIR) +
                           "/realdata/telemetry/Moecker__sdc_path_planning__input-advanced.json";
  std::ifstream in(path);
  if (!in) GTEST_SKIP() << "real recording absent: " << path;
  std::string line;
  int lines = 0, with_path = 0;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    ++lines;
    const ParsedFrame p = ParseFrame("42[\"telemetry\"," + line + "]");
    ASSERT_EQ(p.kind, FrameKind::kTelemetry) << "line " << lines << ": " << p.error;
    ASSERT_TRUE(p.error.empty()) << "line " << lines << ": " << p.error;
    if (!p.telemetry.previous_path_x.empty()) ++with_path;
    const json original = json::parse(line);
    const json written = json::parse(TelemetryToJson(p.telemetry));
    ASSERT_EQ(written, original) << "line " << lines;
    // Speed and yaw went through SI and back.
    EXPECT_NEAR(p.telemetry.speed * units::kSimMpsToMph, original["speed"].get<double>(), 1e-9);
  }
  EXPECT_EQ(lines, 1549);
  EXPECT_GT(with_path, 1500);
}

TEST(ProtocolTest, RoundTripOfArbitraryTelemetryIsFloat32Exact) {
  plan::Telemetry t;
  t.x = 1234.56789;
  t.y = -98.7654321;
  t.yaw = 1.2345;
  t.speed = 21.9876;
  t.s = 6944.999;
  t.d = 9.75;
  for (int i = 0; i < 47; ++i) {
    t.previous_path_x.push_back(1000 + 0.43 * i);
    t.previous_path_y.push_back(2000 - 0.17 * i);
  }
  t.end_path_s = 7000.5;
  t.end_path_d = -0.25;
  for (int i = 0; i < 12; ++i) t.sensor_fusion.push_back({i, 1.5 * i, 2.5, -3.25, 4, 5.5, 6});
  const ParsedFrame p = ParseFrame(FormatTelemetryFrame(t));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry) << p.error;
  const plan::Telemetry& r = p.telemetry;
  const auto f32 = [](double v) { return static_cast<double>(static_cast<float>(v)); };
  EXPECT_FLOAT_EQ(r.x, t.x);
  EXPECT_FLOAT_EQ(r.y, t.y);
  EXPECT_NEAR(r.yaw, t.yaw, 1e-6);
  EXPECT_NEAR(r.speed, t.speed, 1e-5);
  EXPECT_FLOAT_EQ(r.end_path_s, t.end_path_s);
  ASSERT_EQ(r.previous_path_x.size(), 47u);
  for (int i = 0; i < 47; ++i) {
    EXPECT_EQ(static_cast<float>(r.previous_path_x[i]), f32(t.previous_path_x[i]));
    EXPECT_EQ(static_cast<float>(r.previous_path_y[i]), f32(t.previous_path_y[i]));
  }
  ASSERT_EQ(r.sensor_fusion.size(), 12u);
  EXPECT_EQ(r.sensor_fusion[11].id, 11);
  EXPECT_DOUBLE_EQ(r.sensor_fusion[11].x, 16.5);
}

TEST(ProtocolTest, NullTelemetryAndOtherEventsAndEngineIo) {
  EXPECT_EQ(ParseFrame(kNullTelemetryFrame).kind, FrameKind::kNullTelemetry);
  EXPECT_EQ(ParseFrame(R"(42["telemetry", null ])").kind, FrameKind::kNullTelemetry);
  EXPECT_EQ(ParseFrame(R"(42["hello",{"a":1}])").kind, FrameKind::kOtherEvent);
  EXPECT_EQ(ParseFrame(R"(42["manual",{}])").kind, FrameKind::kOtherEvent);
  EXPECT_EQ(ParseFrame("2").kind, FrameKind::kPing);
  EXPECT_EQ(ParseFrame("3").kind, FrameKind::kIgnored);
  EXPECT_EQ(ParseFrame("").kind, FrameKind::kIgnored);
  EXPECT_EQ(ParseFrame(R"(0{"sid":"x"})").kind, FrameKind::kIgnored);
  EXPECT_EQ(ParseFrame("40").kind, FrameKind::kIgnored);
}

// One case per kind of hostile input: the frame, the kind it must get, and a word the one-line
// error must contain (naming the field).
struct HostileCase {
  const char* name;
  std::string frame;
  FrameKind kind;
  const char* error_mentions;
};

std::string WithField(const char* key, const json& value) {
  json j = FirstPayload();
  j[key] = value;
  return Frame(j);
}
std::string WithoutField(const char* key) {
  json j = FirstPayload();
  j.erase(key);
  return Frame(j);
}
std::string WithRawValue(const char* key, const std::string& raw) {
  json j = FirstPayload();
  j[key] = 12345.5;
  std::string s = Frame(j);
  // Appended: GCC 12 warns falsely (-Wrestrict) on "\"" + std::string(key).
  const std::string quoted = std::string("\"").append(key).append("\":");
  const std::string needle = quoted + "12345.5";
  s.replace(s.find(needle), needle.size(), quoted + raw);
  return s;
}

class HostileFrameTest : public ::testing::TestWithParam<HostileCase> {};

TEST_P(HostileFrameTest, IsReportedInOneLineNamingTheProblem) {
  const HostileCase& c = GetParam();
  const ParsedFrame p = ParseFrame(c.frame);
  EXPECT_EQ(p.kind, c.kind) << ToString(p.kind) << ": " << p.error;
  EXPECT_NE(p.error.find(c.error_mentions), std::string::npos) << p.error;
  EXPECT_EQ(p.error.find('\n'), std::string::npos) << p.error;
  EXPECT_LT(p.error.size(), 300u) << p.error;
}

std::vector<HostileCase> HostileCases() {
  std::vector<HostileCase> cases = {
      {"TruncatedJson", FirstTelemetryFrame().substr(0, 60), FrameKind::kMalformed, "JSON"},
      {"GarbageAfter42", "42hello", FrameKind::kMalformed, "JSON"},
      {"TrailingGarbage", FirstTelemetryFrame() + "xyz", FrameKind::kMalformed, "JSON"},
      {"NotAnArray", R"(42{"telemetry":1})", FrameKind::kMalformed, "object"},
      {"EmptyArray", "42[]", FrameKind::kMalformed, "array"},
      {"EventNotString", R"(42[7,{}])", FrameKind::kMalformed, "event name"},
      {"MissingPayload", R"(42["telemetry"])", FrameKind::kMalformed, "payload"},
      {"PayloadNotObject", R"(42["telemetry",[1,2]])", FrameKind::kMalformed, "payload"},
      {"MissingX", WithoutField("x"), FrameKind::kMalformed, "telemetry.x: missing"},
      {"MissingSensorFusion", WithoutField("sensor_fusion"), FrameKind::kMalformed,
       "sensor_fusion: missing"},
      {"YawAsString", WithField("yaw", "0"), FrameKind::kMalformed, "telemetry.yaw"},
      {"SpeedNull", WithField("speed", nullptr), FrameKind::kMalformed, "telemetry.speed"},
      {"NaNAsString", WithField("s", "NaN"), FrameKind::kMalformed, "telemetry.s"},
      {"InfAsString", WithField("d", "inf"), FrameKind::kMalformed, "telemetry.d"},
      {"OverflowToInf", WithRawValue("x", "1e999"), FrameKind::kMalformed, "overflow"},
      {"BareNaNToken", WithRawValue("y", "NaN"), FrameKind::kMalformed, "JSON"},
      {"PathNotArray", WithField("previous_path_x", 5), FrameKind::kMalformed,
       "previous_path_x: expected an array"},
      {"SensorFusionObject", WithField("sensor_fusion", json::object()), FrameKind::kMalformed,
       "sensor_fusion"},
      {"DeepNesting", "42[\"telemetry\"," + std::string(100000, '[') + "]", FrameKind::kMalformed,
       "nested"},
      {"InvalidUtf8", std::string("42[\"tele\xff\xfe\",{}]"), FrameKind::kMalformed, "JSON"},
      // Repaired, still planned.
      {"UnequalPath", WithField("previous_path_y", json::array({1.0})), FrameKind::kTelemetry,
       "unequal"},
      {"NaNInPath",
       [] {
         json j = FirstPayload();
         j["previous_path_x"] = {1.0, 2.0, "NaN"};
         j["previous_path_y"] = {1.0, 2.0, 3.0};
         return Frame(j);
       }(),
       FrameKind::kTelemetry, "previous_path_x[2]"},
      {"ShortSensorRow",
       [] {
         json j = FirstPayload();
         j["sensor_fusion"][3] = {3, 1, 2};
         return Frame(j);
       }(),
       FrameKind::kTelemetry, "sensor_fusion[3]"},
      {"FractionalSensorId",
       [] {
         json j = FirstPayload();
         j["sensor_fusion"][4][0] = 4.5;
         return Frame(j);
       }(),
       FrameKind::kTelemetry, "id is not an integer"},
      {"StringInSensorRow",
       [] {
         json j = FirstPayload();
         j["sensor_fusion"][5][6] = "inf";
         return Frame(j);
       }(),
       FrameKind::kTelemetry, "d is not a finite number"},
  };
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, HostileFrameTest, ::testing::ValuesIn(HostileCases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ProtocolTest, BadSensorRowsAreDroppedAndTheRestKept) {
  json j = FirstPayload();
  j["sensor_fusion"][3] = {3, 1, 2};
  j["sensor_fusion"][7][2] = nullptr;
  const ParsedFrame p = ParseFrame(Frame(j));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry);
  ASSERT_EQ(p.telemetry.sensor_fusion.size(), 10u);
  std::vector<int> ids;
  for (const auto& c : p.telemetry.sensor_fusion) ids.push_back(c.id);
  EXPECT_EQ(ids, (std::vector<int>{0, 1, 2, 4, 5, 6, 8, 9, 10, 11}));
  EXPECT_NE(p.error.find("and 1 more"), std::string::npos) << p.error;
  EXPECT_DOUBLE_EQ(p.telemetry.x, 909.48);
}

TEST(ProtocolTest, UnequalAndBrokenPathsAreCutToTheGoodPrefix) {
  json j = FirstPayload();
  j["previous_path_x"] = {1, 2, 3, 4, 5};
  j["previous_path_y"] = {6, 7, 8};
  ParsedFrame p = ParseFrame(Frame(j));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry);
  EXPECT_EQ(p.telemetry.previous_path_x, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(p.telemetry.previous_path_y, (std::vector<double>{6, 7, 8}));
  j["previous_path_y"] = {6, 7, nullptr, 9, 10};
  p = ParseFrame(Frame(j));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry);
  EXPECT_EQ(p.telemetry.previous_path_x, (std::vector<double>{1, 2}));
  EXPECT_EQ(p.telemetry.previous_path_y, (std::vector<double>{6, 7}));
}

TEST(ProtocolTest, ManyBadRowsStillGiveAShortMessage) {
  json j = FirstPayload();
  for (int i = 0; i < 50; ++i) j["sensor_fusion"].push_back({"bad", i});
  const ParsedFrame p = ParseFrame(Frame(j));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry);
  EXPECT_EQ(p.telemetry.sensor_fusion.size(), 12u);
  EXPECT_NE(p.error.find("and 49 more"), std::string::npos) << p.error;
  EXPECT_LT(p.error.size(), 200u);
}

void ExpectRefused(const ParsedFrame& p, const std::string& mentions) {
  EXPECT_EQ(p.kind, FrameKind::kRefused) << ToString(p.kind) << ": " << p.error;
  EXPECT_NE(p.error.find(mentions), std::string::npos) << p.error;
  EXPECT_EQ(p.error.find('\n'), std::string::npos) << p.error;
  EXPECT_LT(p.error.size(), 200u) << p.error;
  EXPECT_TRUE(p.telemetry.sensor_fusion.empty());
  EXPECT_TRUE(p.telemetry.previous_path_x.empty());
}

TEST(ProtocolTest, RowsAndPointsUpToTheLimitsAreKept) {
  const FrameLimits limits;
  ParsedFrame p = ParseFrame(FrameWithRows(limits.max_sensor_rows));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry) << p.error;
  EXPECT_EQ(p.telemetry.sensor_fusion.size(), static_cast<std::size_t>(limits.max_sensor_rows));
  p = ParseFrame(FrameWithPath(limits.max_path_points));
  ASSERT_EQ(p.kind, FrameKind::kTelemetry) << p.error;
  EXPECT_EQ(p.telemetry.previous_path_x.size(), static_cast<std::size_t>(limits.max_path_points));
  EXPECT_EQ(p.telemetry.previous_path_x.back(), 900 + limits.max_path_points - 1);
}

TEST(ProtocolTest, RowsOrPointsOverTheLimitsAreRefusedNamingTheField) {
  FrameLimits limits;
  limits.max_sensor_rows = 20;
  limits.max_path_points = 60;
  ExpectRefused(ParseFrame(FrameWithRows(21), limits),
                "telemetry.sensor_fusion: 21 rows, over the limit of 20");
  ExpectRefused(ParseFrame(FrameWithPath(61), limits),
                "telemetry.previous_path_x: 61 points, over the limit of 60");
  EXPECT_EQ(ParseFrame(FrameWithRows(20), limits).kind, FrameKind::kTelemetry);
  EXPECT_EQ(ParseFrame(FrameWithPath(60), limits).kind, FrameKind::kTelemetry);
}

// The frames of issue 22, each under the server's 1 MiB frame limit, and pathological ones: all
// are refused by the scan before any JSON value is built ("unread").
TEST(ProtocolTest, HugeAndPathologicalFramesAreRefusedUnread) {
  const std::size_t kMiB = 1 << 20;
  std::string rows = FrameWithRows(12500);  // ~1 MB: 50,000 rows would not fit in 1 MiB here
  ASSERT_LT(rows.size(), kMiB);
  ExpectRefused(ParseFrame(rows), "refused unread");
  ExpectRefused(ParseFrame(FrameWithPath(40000)), "refused unread");
  // Each within the byte budget, but over another bound.
  std::string values = "[1";
  for (int i = 0; i < 3000; ++i) values += ",1";
  ExpectRefused(ParseFrame(FrameWithJunk(values + "]")), "more than 2576 values");
  ExpectRefused(ParseFrame(FrameWithJunk("\"" + std::string(300, 'a') + "\"")),
                "a string of more than 256 bytes");
  ExpectRefused(ParseFrame(FrameWithJunk("0." + std::string(40, '1'))),
                "a number or literal of more than 32 characters");
  ExpectRefused(ParseFrame(FrameWithJunk(std::string(200000, ' ') + "1")),
                "more than the 123696 the limits allow");
  // Nesting is still malformed, as before.
  EXPECT_EQ(ParseFrame("42" + std::string(20000, '[')).kind, FrameKind::kMalformed);
  // Long escapes count as they are written.
  EXPECT_EQ(ParseFrame(FrameWithJunk("\"" + std::string(120, '\\') + "\"")).kind,
            FrameKind::kTelemetry);
  ExpectRefused(ParseFrame(FrameWithJunk("\"" + std::string(260, '\\') + "\"")),
                "a string of more than 256 bytes");
}

TEST(ProtocolTest, FrameLimitsAreValidated) {
  EXPECT_TRUE(FrameLimits().Validate().ok());
  FrameLimits l;
  l.max_sensor_rows = 0;
  EXPECT_NE(l.Validate().message().find("max sensor rows"), std::string::npos);
  l = FrameLimits();
  l.max_path_points = -1;
  EXPECT_NE(l.Validate().message().find("max path points"), std::string::npos);
}

TEST(ProtocolTest, FormatControlWritesEqualFiniteArrays) {
  const std::vector<double> x = {909.5361234567, -0.0, 1e-9, 6945.554};
  const std::vector<double> y = {1128.67, 2.5, -3.75, 0.1};
  std::string out = "stale";
  EXPECT_EQ(FormatControl(x, y, &out), 4u);
  ASSERT_EQ(out.rfind("42[\"control\",", 0), 0u) << out;
  const json j = json::parse(out.substr(2));
  ASSERT_EQ(j[0], "control");
  const auto& nx = j[1]["next_x"];
  const auto& ny = j[1]["next_y"];
  ASSERT_EQ(nx.size(), 4u);
  ASSERT_EQ(ny.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(nx[i].get<double>(), x[i], 1e-9 * std::max(1.0, std::abs(x[i])));
    EXPECT_NEAR(ny[i].get<double>(), y[i], 1e-9 * std::max(1.0, std::abs(y[i])));
  }
  EXPECT_FALSE(std::signbit(nx[1].get<double>())) << "no -0: " << out;
  EXPECT_EQ(out.find(' '), std::string::npos) << "compact: " << out;
}

TEST(ProtocolTest, FormatControlCutsAtTheFirstNonFinitePointAndToTheShorterArray) {
  std::string out;
  const std::vector<double> x = {1, 2, 3, NAN, 5};
  const std::vector<double> y = {1, 2, 3, 4, 5, 6, 7};
  EXPECT_EQ(FormatControl(x, y, &out), 3u);
  EXPECT_EQ(out, R"(42["control",{"next_x":[1,2,3],"next_y":[1,2,3]}])");
  const std::vector<double> y_inf = {1, INFINITY};
  EXPECT_EQ(FormatControl(std::vector<double>{1, 2}, y_inf, &out), 1u);
  EXPECT_EQ(FormatControl({}, {}, &out), 0u);
  EXPECT_EQ(out, R"(42["control",{"next_x":[],"next_y":[]}])");
}

// Found by the fuzzer: -DBL_MAX written with 10 digits rounds to -1.797693135e+308, a literal
// that overflows double and made the frame invalid JSON. Points beyond float32 range, which the
// simulator cannot parse, are cut like non-finite ones.
TEST(ProtocolTest, FormatControlCutsAtCoordinatesBeyondFloat32Range) {
  std::string out;
  const std::vector<double> x = {1, 2, -1.7976931348517495e+308};
  const std::vector<double> y = {1, 2, 3};
  EXPECT_EQ(FormatControl(x, y, &out), 2u);
  EXPECT_EQ(out, R"(42["control",{"next_x":[1,2],"next_y":[1,2]}])");
  const std::vector<double> y_big = {1, 3.5e38};
  EXPECT_EQ(FormatControl(std::vector<double>{1, 2}, y_big, &out), 1u);
  ParsedReply reply;
  const std::vector<double> tiny = {1.259867397e-321, 3.4e38};
  EXPECT_EQ(FormatControl(tiny, tiny, &out), 2u);
  ParseReply(out, &reply);
  EXPECT_EQ(reply.kind, ReplyKind::kControl) << reply.error;
}

TEST(ProtocolTest, ParseReplyReadsControlAndRejectsWhatTheSimulatorCannotUse) {
  ParsedReply r;
  std::string frame;
  FormatControl(std::vector<double>{1.5, 2.5}, std::vector<double>{3.5, 4.5}, &frame);
  ParseReply(frame, &r);
  ASSERT_EQ(r.kind, ReplyKind::kControl) << r.error;
  EXPECT_EQ(r.x, (std::vector<double>{1.5, 2.5}));
  EXPECT_EQ(r.y, (std::vector<double>{3.5, 4.5}));

  ParseReply(R"(42["control",{"next_x":[1],"next_y":[2],"debug":"extra"}])", &r);
  EXPECT_EQ(r.kind, ReplyKind::kControl) << r.error;
  ParseReply(kManualFrame, &r);
  EXPECT_EQ(r.kind, ReplyKind::kManual);
  EXPECT_TRUE(r.x.empty());
  ParseReply("3", &r);
  EXPECT_EQ(r.kind, ReplyKind::kPong);
  ParseReply("0{}", &r);
  EXPECT_EQ(r.kind, ReplyKind::kIgnored);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"(42["control",{"next_x":[1,2],"next_y":[2]}])", "next_y 1"},
      {R"(42["control",{"next_x":[1],"next_y":[2,3]}])", "next_y 2"},
      {R"(42["control",{"next_x":[1,null],"next_y":[2,3]}])", "next_x[1]"},
      {R"(42["control",{"next_x":[1,"1"],"next_y":[2,3]}])", "next_x[1]"},
      {R"(42["control",{"next_x":[1e39],"next_y":[2]}])", "float32"},
      {R"(42["control",{"next_y":[2]}])", "next_x: missing"},
      {R"(42["control",{"next_x":{},"next_y":[2]}])", "next_x: expected an array"},
      {R"(42["control",[]])", "payload"},
      {R"(42["steer",{}])", "neither control nor manual"},
      {R"(42["control",{"next_x":[1])", "JSON"},
  };
  for (const auto& [frame_text, mention] : bad) {
    ParseReply(frame_text, &r);
    EXPECT_EQ(r.kind, ReplyKind::kMalformed) << frame_text;
    EXPECT_NE(r.error.find(mention), std::string::npos) << frame_text << " -> " << r.error;
  }
}

}  // namespace
}  // namespace frenetic::wire

// The in-process drive rounds numbers with wire/precision.h instead of writing and parsing text:
// these tests hold it to the wire, bit for bit, so the two cannot drift apart.
#include "frenetic/wire/precision.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "frenetic/wire/protocol.h"

namespace frenetic::wire {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double ViaTelemetryText(double v) {
  char buf[kMaxNumberChars];
  return ParseNumber(buf, FormatTelemetryNumber(v, buf));
}
double ViaControlText(double v) {
  char buf[kMaxNumberChars];
  return ParseNumber(buf, FormatControlNumber(v, buf));
}

// Values around every power of ten, exact ties of both roundings, the float32 limits and the
// hostile ones.
std::vector<double> EdgeValues() {
  std::vector<double> v = {0.0, -0.0, kNaN, -kNaN, kInf, -kInf, 1e39, -1e39, 1e300, 5e-324,
                           std::numeric_limits<float>::max(), std::numeric_limits<float>::min(),
                           std::numeric_limits<float>::denorm_min(), 1e-45, 0.5, 1.5, 2.5,
                           909.48, 1128.67, 124.8336, 6.164833, 0.2252774, 6945.554, 359.99999,
                           360.0, -280.1494, 1.0000005, 1.00000005, 12345675.0, 1234567.5,
                           9999999.5, 99999.995, 0.1, 0.3, 2.0 / 3.0};
  for (int e = -40; e <= 40; ++e) {
    const double p = std::pow(10.0, e);
    for (double q : {p, std::nextafter(p, 0.0), std::nextafter(p, kInf), p * 0.99999995,
                     p * 1.00000005, p * 9.9999995, p * 9.999999999, p * 1.0000000005}) {
      v.push_back(q);
      v.push_back(-q);
      v.push_back(static_cast<float>(q));
    }
  }
  return v;
}

// Random values: ordinary coordinates and speeds, log-uniform magnitudes, raw bit patterns.
std::vector<double> RandomValues(std::size_t n) {
  std::mt19937_64 rng(20240613);
  std::uniform_real_distribution<double> coord(-8000.0, 8000.0), small(-50.0, 50.0),
      exponent(-15.0, 15.0);
  std::vector<double> v;
  v.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    switch (i % 5) {
      case 0: v.push_back(coord(rng)); break;
      case 1: v.push_back(small(rng)); break;
      case 2: v.push_back(std::pow(10.0, exponent(rng)) * (rng() % 2 ? 1 : -1)); break;
      case 3: v.push_back(std::bit_cast<double>(rng())); break;
      default: v.push_back(std::bit_cast<float>(static_cast<std::uint32_t>(rng()))); break;
    }
  }
  return v;
}

void ExpectSameBits(double got, double want, double input, const char* what) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want))
      << what << " of " << input << ": " << got << " vs the text's " << want;
}

TEST(WirePrecisionTest, NumbersEqualTheirTextParsedBack) {
  std::vector<double> values = EdgeValues();
  const std::vector<double> random = RandomValues(400000);
  values.insert(values.end(), random.begin(), random.end());
  int failures = 0;
  for (double v : values) {
    const double t = AsTelemetryNumber(v), c = AsControlNumber(v);
    const double tt = ViaTelemetryText(v), ct = ViaControlText(v);
    if (std::bit_cast<std::uint64_t>(t) != std::bit_cast<std::uint64_t>(tt)) {
      ExpectSameBits(t, tt, v, "AsTelemetryNumber");
      ++failures;
    }
    // Control numbers the formatter would cut (non-finite, beyond float32) never reach a parser.
    if (ControlWritable(v) && std::bit_cast<std::uint64_t>(c) != std::bit_cast<std::uint64_t>(ct)) {
      ExpectSameBits(c, ct, v, "AsControlNumber");
      ++failures;
    }
    if (failures > 20) FAIL() << "more than 20 differences";
  }
}

TEST(WirePrecisionTest, TelemetryNumbersAreAsTheSimulatorPrintsThem) {
  EXPECT_EQ(AsTelemetryNumber(909.5360107421875), 909.536);  // float32 of 909.536
  EXPECT_EQ(AsTelemetryNumber(909.53595), 909.5359);  // float32 909.5359497...
  EXPECT_EQ(AsTelemetryNumber(0.22527740895748138), 0.2252774);
  EXPECT_EQ(AsTelemetryNumber(kNaN), 0.0);
  EXPECT_EQ(AsTelemetryNumber(1e39), 0.0);  // beyond float32 range
  EXPECT_EQ(AsControlNumber(909.53598765432), 909.5359877);
}

std::vector<double> Pick(std::mt19937_64& rng, std::size_t n, const std::vector<double>& pool) {
  std::vector<double> v(n);
  for (double& e : v) e = pool[rng() % pool.size()];
  return v;
}

plan::Telemetry RandomTelemetry(std::mt19937_64& rng, const std::vector<double>& pool) {
  const auto any = [&] { return pool[rng() % pool.size()]; };
  plan::Telemetry t;
  t.x = any();
  t.y = any();
  t.yaw = any();
  t.speed = any();
  t.s = any();
  t.d = any();
  t.end_path_s = any();
  t.end_path_d = any();
  const std::size_t n = rng() % 60;
  t.previous_path_x = Pick(rng, n, pool);
  t.previous_path_y = Pick(rng, rng() % 8 == 0 ? rng() % 60 : n, pool);  // sometimes unequal
  t.sensor_fusion.resize(rng() % 14);
  for (plan::SensorCar& c : t.sensor_fusion) {
    c.id = static_cast<int>(rng() % 12);
    c.x = any();
    c.y = any();
    c.vx = any();
    c.vy = any();
    c.s = any();
    c.d = any();
  }
  return t;
}

void ExpectSameTelemetry(const plan::Telemetry& got, const plan::Telemetry& want) {
  ExpectSameBits(got.x, want.x, 0, "x");
  ExpectSameBits(got.y, want.y, 0, "y");
  ExpectSameBits(got.yaw, want.yaw, 0, "yaw");
  ExpectSameBits(got.speed, want.speed, 0, "speed");
  ExpectSameBits(got.s, want.s, 0, "s");
  ExpectSameBits(got.d, want.d, 0, "d");
  ExpectSameBits(got.end_path_s, want.end_path_s, 0, "end_path_s");
  ExpectSameBits(got.end_path_d, want.end_path_d, 0, "end_path_d");
  ASSERT_EQ(got.previous_path_x.size(), want.previous_path_x.size());
  ASSERT_EQ(got.previous_path_y.size(), want.previous_path_y.size());
  for (std::size_t i = 0; i < got.previous_path_x.size(); ++i) {
    ExpectSameBits(got.previous_path_x[i], want.previous_path_x[i], 0, "previous_path_x");
    ExpectSameBits(got.previous_path_y[i], want.previous_path_y[i], 0, "previous_path_y");
  }
  ASSERT_EQ(got.sensor_fusion.size(), want.sensor_fusion.size());
  for (std::size_t i = 0; i < got.sensor_fusion.size(); ++i) {
    const plan::SensorCar &a = got.sensor_fusion[i], &b = want.sensor_fusion[i];
    EXPECT_EQ(a.id, b.id);
    for (auto [p, q] : {std::pair{a.x, b.x}, {a.y, b.y}, {a.vx, b.vx}, {a.vy, b.vy},
                        {a.s, b.s}, {a.d, b.d}}) {
      ExpectSameBits(p, q, 0, "sensor_fusion");
    }
  }
}

TEST(WirePrecisionTest, TelemetryAsReceivedIsWhatParseFrameMakesOfTheFrame) {
  std::vector<double> pool = EdgeValues();
  const std::vector<double> random = RandomValues(2000);
  pool.insert(pool.end(), random.begin(), random.end());
  std::mt19937_64 rng(7);
  plan::Telemetry received;
  for (int i = 0; i < 300; ++i) {
    const plan::Telemetry t = RandomTelemetry(rng, pool);
    const wire::ParsedFrame parsed = wire::ParseFrame(wire::FormatTelemetryFrame(t));
    ASSERT_EQ(parsed.kind, wire::FrameKind::kTelemetry) << parsed.error;
    TelemetryAsReceived(t, &received);
    ExpectSameTelemetry(received, parsed.telemetry);
    if (HasFailure()) FAIL() << "telemetry " << i;
  }
}

TEST(WirePrecisionTest, ControlAsReceivedIsWhatParseReplyMakesOfTheControl) {
  std::vector<double> pool = EdgeValues();
  const std::vector<double> random = RandomValues(2000);
  pool.insert(pool.end(), random.begin(), random.end());
  std::mt19937_64 rng(11);
  std::string text;
  wire::ParsedReply reply;
  std::vector<double> x, y;
  for (int i = 0; i < 300; ++i) {
    // Mostly writable points, so paths are not all cut at their first point.
    const std::size_t n = rng() % 80;
    std::vector<double> px = RandomValues(n), py = RandomValues(rng() % 5 == 0 ? n + 3 : n);
    for (double& v : px) v = ControlWritable(v) && rng() % 50 != 0 ? v : pool[rng() % pool.size()];
    const std::size_t written = wire::FormatControl(px, py, &text);
    wire::ParseReply(text, &reply);
    ASSERT_EQ(reply.kind, wire::ReplyKind::kControl) << reply.error;
    ControlAsReceived(px, py, &x, &y);
    ASSERT_EQ(x.size(), written);
    ASSERT_EQ(x.size(), reply.x.size());
    ASSERT_EQ(y.size(), reply.y.size());
    for (std::size_t k = 0; k < x.size(); ++k) {
      ExpectSameBits(x[k], reply.x[k], px[k], "next_x");
      ExpectSameBits(y[k], reply.y[k], py[k], "next_y");
    }
    if (HasFailure()) FAIL() << "path " << i;
  }
}

}  // namespace
}  // namespace frenetic::wire

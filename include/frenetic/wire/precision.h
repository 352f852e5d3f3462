// The numbers of the simulator's wire (udacity-sim.md §3.2), in one place for the wire formatter
// (wire/protocol.cc) and the in-process drive (drive/episode.cc), so that a planner driven in
// process sees exactly the numbers a planner behind `frenetic serve` sees, and the simulator
// gets exactly the path it would have parsed:
//  - telemetry: every number is float32 printed with 7 significant digits (.NET
//    float.ToString()), speed in mph, yaw in degrees, and parsed by the planner as a double;
//  - control: the planner's numbers are printed with 10 significant digits and parsed by the
//    simulator as doubles (which it stores as float32, see sim/ego.h).
// Header-only and free of network types: std::to_chars / std::from_chars, no allocation once the
// output vectors have grown.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "frenetic/plan/telemetry.h"
#include "frenetic/units.h"

namespace frenetic::wire {

inline constexpr int kTelemetryDigits = 7;  // significant digits of .NET float.ToString()
inline constexpr int kControlDigits = 10;   // far below the float32 resolution the sim keeps
// Room for any number either formatter writes ("-1.234567e-38", "-1.797693135e+308").
inline constexpr std::size_t kMaxNumberChars = 32;

// Writes `value` as the simulator prints it: rounded to float32, then to 7 significant digits,
// trailing zeros dropped, plain notation for ordinary magnitudes. Non-finite values and values
// beyond float32 range (which the simulator never sends) are written as 0, and -0 as 0.
// [first, first + kMaxNumberChars) must be writable; returns the end of the text.
inline char* FormatTelemetryNumber(double value, char* first) {
  float f = std::isfinite(value) ? static_cast<float>(value) : 0.0f;
  if (!std::isfinite(f)) f = 0.0f;  // beyond float32 range
  if (f == 0.0f) f = 0.0f;          // no "-0"
  return std::to_chars(first, first + kMaxNumberChars, f, std::chars_format::general,
                       kTelemetryDigits)
      .ptr;
}

// Writes `value` as a control number: 10 significant digits, -0 as 0. The caller cuts
// non-finite values and values beyond float32 range first (see ControlPoints).
inline char* FormatControlNumber(double value, char* first) {
  if (value == 0.0) value = 0.0;  // no "-0"
  return std::to_chars(first, first + kMaxNumberChars, value, std::chars_format::general,
                       kControlDigits)
      .ptr;
}

// The double a reader parses from the text of a formatter above (both are valid decimals, so
// std::from_chars gives the correctly rounded double, as nlohmann::json does).
inline double ParseNumber(const char* first, const char* last) {
  double out = 0;
  std::from_chars(first, last, out);
  return out;
}

namespace internal {

// 10^k for k in [0, 22]: all exact doubles.
inline constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// The value of `a` (> 0) rounded to `digits` significant digits, as the decimal text of
// std::to_chars parsed back, computed without the text: n = round(a * 10^k) with a * 10^k in
// [10^(digits-1), 10^digits), then n / 10^k, a division of exact doubles that rounds once, to
// the double nearest the decimal, as std::from_chars does. Falls back to the text (false) for
// magnitudes outside [10^-max_k', 10^digits) and when a * 10^k is within `tie_guard` of a
// rounding tie, where an inexact product could round the other way.
inline bool FastRound(double a, int digits, int max_k, double tie_guard, double* out) {
  const double lo = kPow10[digits - 1], hi = kPow10[digits];
  if (!(a >= 1.0 / kPow10[max_k - digits + 1] && a < hi)) return false;
  int k = 0;
  while (k < max_k && a * kPow10[k + 1] < hi) ++k;  // the largest k with a * 10^k < 10^digits
  const double scaled = a * kPow10[k];
  if (!(scaled >= lo && scaled < hi)) return false;
  const double fraction = scaled - std::floor(scaled);
  if (std::fabs(fraction - 0.5) <= tie_guard) return false;
  *out = std::nearbyint(scaled) / kPow10[k];
  return true;
}

}  // namespace internal

// The number a planner reads for a telemetry value: ParseNumber(FormatTelemetryNumber(value)),
// with a cheaper exact path for ordinary magnitudes (a float32 times 10^k, k <= 12, is exact,
// so only true ties go to the text).
inline double AsTelemetryNumber(double value) {
  float f = std::isfinite(value) ? static_cast<float>(value) : 0.0f;
  if (!std::isfinite(f) || f == 0.0f) return 0.0;
  double rounded = 0;
  if (internal::FastRound(std::fabs(static_cast<double>(f)), kTelemetryDigits, 12, 0.0,
                          &rounded)) {
    return f < 0 ? -rounded : rounded;
  }
  char buf[kMaxNumberChars];
  return ParseNumber(buf, FormatTelemetryNumber(value, buf));
}

// The number the simulator reads for a control value: ParseNumber(FormatControlNumber(value)),
// with a cheaper path as above (a double times 10^k is inexact by at most half an ulp, < 2e-6
// below 10^10, so values that close to a tie go to the text).
inline double AsControlNumber(double value) {
  if (value == 0.0) return 0.0;
  double rounded = 0;
  if (std::isfinite(value) &&
      internal::FastRound(std::fabs(value), kControlDigits, 18, 1e-5, &rounded)) {
    return value < 0 ? -rounded : rounded;
  }
  char buf[kMaxNumberChars];
  return ParseNumber(buf, FormatControlNumber(value, buf));
}

// Heading in the simulator's unit: degrees counter-clockwise from +x in [0, 360); 0 when it is
// not finite or would print as 360. `yaw` in rad.
inline double YawToDegrees(double yaw) {
  double deg = std::fmod(yaw * units::kRadToDeg, 360.0);
  if (deg < 0) deg += 360.0;
  if (!std::isfinite(deg) || static_cast<float>(deg) >= 360.0f) deg = 0;
  return deg;
}
inline double YawFromDegrees(double deg) { return deg * units::kDegToRad; }
inline double SpeedToMph(double mps) { return mps * units::kSimMpsToMph; }
inline double SpeedFromMph(double mph) { return mph / units::kSimMpsToMph; }

// The telemetry as a planner receives it over the wire, i.e. what ParseFrame makes of
// FormatTelemetryFrame(in), without the text: every number through AsTelemetryNumber (yaw
// and speed in degrees and mph on the way), unequal previous_path arrays cut to the shorter one.
// `out` must not be `in`; its vectors are reused.
inline void TelemetryAsReceived(const plan::Telemetry& in, plan::Telemetry* out) {
  out->x = AsTelemetryNumber(in.x);
  out->y = AsTelemetryNumber(in.y);
  out->yaw = YawFromDegrees(AsTelemetryNumber(YawToDegrees(in.yaw)));
  out->speed = SpeedFromMph(AsTelemetryNumber(SpeedToMph(in.speed)));
  out->s = AsTelemetryNumber(in.s);
  out->d = AsTelemetryNumber(in.d);
  out->end_path_s = AsTelemetryNumber(in.end_path_s);
  out->end_path_d = AsTelemetryNumber(in.end_path_d);
  const std::size_t n = std::min(in.previous_path_x.size(), in.previous_path_y.size());
  out->previous_path_x.resize(n);
  out->previous_path_y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out->previous_path_x[i] = AsTelemetryNumber(in.previous_path_x[i]);
    out->previous_path_y[i] = AsTelemetryNumber(in.previous_path_y[i]);
  }
  out->sensor_fusion.resize(in.sensor_fusion.size());
  for (std::size_t i = 0; i < in.sensor_fusion.size(); ++i) {
    const plan::SensorCar& c = in.sensor_fusion[i];
    plan::SensorCar& r = out->sensor_fusion[i];
    r.id = c.id;
    r.x = AsTelemetryNumber(c.x);
    r.y = AsTelemetryNumber(c.y);
    r.vx = AsTelemetryNumber(c.vx);
    r.vy = AsTelemetryNumber(c.vy);
    r.s = AsTelemetryNumber(c.s);
    r.d = AsTelemetryNumber(c.d);
  }
}

// A control coordinate the simulator can parse: finite and within float32 range.
inline bool ControlWritable(double v) {
  return std::isfinite(v) && std::fabs(v) <= std::numeric_limits<float>::max();
}

// How many leading points a control carries: min(x.size(), y.size()), cut before the first
// point with a coordinate that is not ControlWritable.
inline std::size_t ControlPoints(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = std::min(x.size(), y.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!ControlWritable(x[i]) || !ControlWritable(y[i])) return i;
  }
  return n;
}

// The path as the simulator receives it, i.e. what ParseReply makes of
// FormatControl(x, y): ControlPoints points, each through AsControlNumber.
inline void ControlAsReceived(std::span<const double> x, std::span<const double> y,
                              std::vector<double>* out_x, std::vector<double>* out_y) {
  const std::size_t n = ControlPoints(x, y);
  out_x->resize(n);
  out_y->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    (*out_x)[i] = AsControlNumber(x[i]);
    (*out_y)[i] = AsControlNumber(y[i]);
  }
}

}  // namespace frenetic::wire

// The reference line's sample tables and the interpolants its queries and its fit share
// (reference_line.cc: queries; reference_line_fit.cc: the Ceres fit that fills them).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "frenetic/map/reference_line.h"

namespace frenetic::map::detail {

inline constexpr double kPi = std::numbers::pi;
// m: the chord offset is stored at d = 0 and d = kChordD1 (it is nearly linear in d: over
// d in [0, 12] the Udacity map's offsets bend by < 1 cm).
constexpr double kChordD1 = 12.0;

// To [-pi, pi]. The line's unwrapped headings stay within a few turns, so subtracting whole
// turns is exact enough and far cheaper than std::remainder on the per-point hot path.
inline double WrapAngle(double a) {
  if (a > kPi || a < -kPi) a -= 2 * kPi * std::nearbyint(a / (2 * kPi));
  return a;
}

struct Hermite {
  double h00, h10, h01, h11;  // values
  double d00, d10, d01, d11;  // derivatives w.r.t. t
};

inline Hermite HermiteAt(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t,    -2 * t3 + 3 * t2, t3 - t2,
          6 * t2 - 6 * t,      3 * t2 - 4 * t + 1, -6 * t2 + 6 * t,  3 * t2 - 2 * t};
}

}  // namespace frenetic::map::detail

namespace frenetic::map {

using detail::Hermite;
using detail::HermiteAt;

struct ReferenceLine::Impl {
  bool closed = true;  // a loop; else an open line with n + 1 samples, straight beyond its ends
  double length = 0;
  double step = 0;
  double inv_step = 0;
  int n = 0;
  std::vector<RefSample> samples;
  // Struct-of-arrays copies with n + 1 entries (closed: entry n repeats sample 0 at s = length,
  // heading unwrapped; open: entry n is the last sample), so segment i always interpolates
  // between entries i and i + 1.
  std::vector<double> x, y, th, tx, ty, k, dk;
  // Chord offset (ChordOffset) at each sample for d = 0 and d = kChordD1; linear in d between.
  std::vector<double> chord0, chord1;
  double max_waypoint_distance = 0;
  double max_map_s_difference = 0;

  // cos and sin of a heading th interpolated inside segment i, from the sample's stored tangent
  // (tx, ty) rotated by the small angle th - th[i] with Taylor series: within a 0.5 m segment
  // that angle is a few milliradians, where the series is exact to double rounding and far
  // cheaper than std::cos / std::sin on the per-point hot paths (ToCartesian, ToFrenet).
  void CosSin(int i, double angle, double* c, double* s) const {
    const double a = angle - th[i];
    if (!(std::abs(a) < 0.05)) {  // error bound below: a^9 / 9! < 6e-18 for |a| < 0.05
      *c = std::cos(angle);
      *s = std::sin(angle);
      return;
    }
    const double a2 = a * a;
    const double ca = 1 - a2 / 2 * (1 - a2 / 12 * (1 - a2 / 30 * (1 - a2 / 56)));
    const double sa = a * (1 - a2 / 6 * (1 - a2 / 20 * (1 - a2 / 42)));
    *c = tx[i] * ca - ty[i] * sa;
    *s = ty[i] * ca + tx[i] * sa;
  }

  // Position and direction at segment i with the Hermite weights h (ToCartesian, Centre), and
  // the heading.
  CentrePoint CentreAt(int i, const Hermite& h, double* heading) const {
    const double st = step;
    CentrePoint p;
    p.x = h.h00 * x[i] + h.h10 * st * tx[i] + h.h01 * x[i + 1] + h.h11 * st * tx[i + 1];
    p.y = h.h00 * y[i] + h.h10 * st * ty[i] + h.h01 * y[i + 1] + h.h11 * st * ty[i + 1];
    *heading = h.h00 * th[i] + h.h10 * st * k[i] + h.h01 * th[i + 1] + h.h11 * st * k[i + 1];
    CosSin(i, *heading, &p.cos, &p.sin);
    return p;
  }

  // Position, heading (with its cos and sin) and curvature at segment i, local t, plus their
  // derivatives w.r.t. s.
  struct Eval {
    double x, y, th, k;
    double dx, dy, dth;
    double c, s;
  };
  Eval At(int i, double t) const {
    const Hermite h = HermiteAt(t);
    const double st = step;
    Eval e;
    e.x = h.h00 * x[i] + h.h10 * st * tx[i] + h.h01 * x[i + 1] + h.h11 * st * tx[i + 1];
    e.y = h.h00 * y[i] + h.h10 * st * ty[i] + h.h01 * y[i + 1] + h.h11 * st * ty[i + 1];
    e.th = h.h00 * th[i] + h.h10 * st * k[i] + h.h01 * th[i + 1] + h.h11 * st * k[i + 1];
    e.k = h.h00 * k[i] + h.h10 * st * dk[i] + h.h01 * k[i + 1] + h.h11 * st * dk[i + 1];
    e.dx =
        (h.d00 * x[i] + h.d10 * st * tx[i] + h.d01 * x[i + 1] + h.d11 * st * tx[i + 1]) * inv_step;
    e.dy =
        (h.d00 * y[i] + h.d10 * st * ty[i] + h.d01 * y[i + 1] + h.d11 * st * ty[i + 1]) * inv_step;
    e.dth =
        (h.d00 * th[i] + h.d10 * st * k[i] + h.d01 * th[i + 1] + h.d11 * st * k[i + 1]) * inv_step;
    CosSin(i, e.th, &e.c, &e.s);
    return e;
  }
  // Splits an unwrapped sample coordinate sigma = s / step into (segment, t); on an open line
  // sigma must be within [0, n].
  void Split(double sigma, int* i, double* t) const {
    const double fl = std::floor(sigma);
    if (!closed) {
      const long j = std::clamp(static_cast<long>(fl), 0L, static_cast<long>(n) - 1);
      *i = static_cast<int>(j);
      *t = sigma - static_cast<double>(j);
      return;
    }
    long j = static_cast<long>(fl) % n;
    if (j < 0) j += n;
    *i = static_cast<int>(j);
    *t = sigma - fl;
  }
  // An open line's end that s lies beyond (0: before the start, n: past the end), or -1 when s
  // is on the line (always on a closed one).
  int EndBeyond(double s) const {
    if (closed) return -1;
    return s < 0 ? 0 : s > length ? n : -1;
  }
  double Dist2(int i, double px, double py) const {
    const double ex = x[i] - px, ey = y[i] - py;
    return ex * ex + ey * ey;
  }
  // A sample index: modulo n on a loop, clamped to [0, n] on an open line.
  int Wrap(long i) const {
    if (!closed) return static_cast<int>(std::clamp(i, 0L, static_cast<long>(n)));
    long j = i % n;
    return static_cast<int>(j < 0 ? j + n : j);
  }
  int SampleCount() const { return closed ? n : n + 1; }  // distinct samples to search
  int NearestGlobal(double px, double py) const;
  int NearestLocal(double px, double py, int start, bool* ok) const;
  FrenetPoint Project(double px, double py, int nearest) const;
};

}  // namespace frenetic::map

#include "frenetic/map/track_generator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <spdlog/fmt/fmt.h>

namespace frenetic::map {
namespace {

using std::numbers::pi;
constexpr int kFirstHarmonic = 2;
constexpr int kLastHarmonic = 5;
constexpr int kHarmonics = kLastHarmonic - kFirstHarmonic + 1;
constexpr int kGrid = 8192;         // polar samples for length, curvature and arc inversion
constexpr double kMaxAlpha = 0.75;  // keeps r(phi) >= 0.25 R0 since the amplitudes sum to 1
constexpr double kRadiusMargin = 1.02;
constexpr double kSpacingJitter = 0.12;
constexpr double kClearanceSeparation = 300.0;  // m of arc: nearer parts are neighbours

// std::uniform_real_distribution is implementation-defined; this is not.
double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

struct Shape {
  std::array<double, kHarmonics> amp{}, phase{};
  double alpha = 0;
  double r0 = 1;
  // r, dr/dphi, d2r/dphi2 at phi.
  void Radius(double phi, double* r, double* r1, double* r2) const {
    double a = 1, b = 0, c = 0;
    for (int i = 0; i < kHarmonics; ++i) {
      const double k = kFirstHarmonic + i;
      const double arg = k * phi + phase[i];
      const double ca = std::cos(arg), sa = std::sin(arg);
      a += alpha * amp[i] * ca;
      b -= alpha * amp[i] * k * sa;
      c -= alpha * amp[i] * k * k * ca;
    }
    *r = r0 * a;
    *r1 = r0 * b;
    *r2 = r0 * c;
  }
  double Phi(int i) const { return -0.5 * pi + 2 * pi * i / kGrid; }
};

struct ShapeStats {
  double length = 0;
  double min_radius = 0;
};

ShapeStats Measure(const Shape& sh) {
  ShapeStats st;
  double max_k = 0;
  for (int i = 0; i < kGrid; ++i) {
    double r, r1, r2;
    sh.Radius(sh.Phi(i), &r, &r1, &r2);
    const double q = r * r + r1 * r1;
    st.length += std::sqrt(q);
    max_k = std::max(max_k, std::abs(r * r + 2 * r1 * r1 - r * r2) / (q * std::sqrt(q)));
  }
  st.length *= 2 * pi / kGrid;  // periodic trapezoid rule: spectrally accurate
  st.min_radius = max_k > 0 ? 1.0 / max_k : INFINITY;
  return st;
}

// Scales the shape to the requested length and reports its tightest radius.
double ScaleTo(Shape* sh, double length) {
  sh->r0 = 1;
  sh->r0 = length / Measure(*sh).length;
  return Measure(*sh).min_radius;
}

// Least distance between points of the loop more than kClearanceSeparation apart along it.
double Clearance(const Shape& sh, double length) {
  constexpr int kStride = 8;
  std::vector<double> x, y;
  for (int i = 0; i < kGrid; i += kStride) {
    double r, r1, r2;
    const double phi = sh.Phi(i);
    sh.Radius(phi, &r, &r1, &r2);
    x.push_back(r * std::cos(phi));
    y.push_back(r * std::sin(phi));
  }
  const int m = static_cast<int>(x.size());
  // Arc positions of the points.
  std::vector<double> arc(m, 0.0);
  for (int i = 1; i < m; ++i) arc[i] = arc[i - 1] + std::hypot(x[i] - x[i - 1], y[i] - y[i - 1]);
  double best = INFINITY;
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      const double sep = std::min(arc[j] - arc[i], length - (arc[j] - arc[i]));
      if (sep < kClearanceSeparation) continue;
      best = std::min(best, std::hypot(x[j] - x[i], y[j] - y[i]));
    }
  }
  return best;
}

}  // namespace

Status TrackGeneratorOptions::Validate() const {
  if (!(length >= 1000 && length <= 100000)) {
    return Status::Error(
        fmt::format("track generator: length must be in [1000, 100000] m, got {:.6g}", length));
  }
  if (!(spacing >= 5 && spacing <= 200) || spacing * 8 > length) {
    return Status::Error(fmt::format(
        "track generator: spacing must be in [5, 200] m and at most length/8, got {:.6g}",
        spacing));
  }
  if (!(min_radius >= 20 && min_radius < length / (2 * pi))) {
    return Status::Error(fmt::format(
        "track generator: min_radius must be in [20, length/(2 pi) = {:.6g}) m, got {:.6g}",
        length / (2 * pi), min_radius));
  }
  if (!std::isfinite(centre_x) || !std::isfinite(centre_y)) {
    return Status::Error("track generator: centre must be finite");
  }
  if (!(min_clearance >= 0 && min_clearance < length / 10)) {
    return Status::Error(fmt::format(
        "track generator: min_clearance must be in [0, length/10) m, got {:.6g}", min_clearance));
  }
  return Status::Ok();
}

StatusOr<Track> GenerateTrack(const TrackGeneratorOptions& o) {
  if (Status st = o.Validate(); !st.ok()) return st;
  std::mt19937_64 rng(o.seed);
  Shape sh;
  double total = 0;
  for (int i = 0; i < kHarmonics; ++i) {
    const double k = kFirstHarmonic + i;
    // Lower harmonics dominate: an elongated, gently bent loop rather than a flower.
    sh.amp[i] = (0.3 + 0.7 * Uniform(rng)) / (k * k);
    sh.phase[i] = 2 * pi * Uniform(rng);
    total += sh.amp[i];
  }
  for (double& a : sh.amp) a /= total;

  // Largest alpha whose tightest radius stays above min_radius and whose loop keeps its clearance.
  const double target = o.min_radius * kRadiusMargin;
  auto feasible = [&](double alpha) {
    sh.alpha = alpha;
    if (ScaleTo(&sh, o.length) < target) return false;
    return Clearance(sh, o.length) >= o.min_clearance;
  };
  double lo = 0, hi = kMaxAlpha;
  if (!feasible(lo)) {
    return Status::Error(
        fmt::format("track generator: no loop meets min_clearance {:.6g} m", o.min_clearance));
  }
  if (feasible(hi)) {
    lo = hi;
  } else {
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      (feasible(mid) ? lo : hi) = mid;
    }
  }
  sh.alpha = lo;
  ScaleTo(&sh, o.length);

  // Arc-length table over the polar grid, to place waypoints by distance along the curve.
  std::vector<double> arc(kGrid + 1, 0.0);
  {
    double r, r1, r2;
    sh.Radius(sh.Phi(0), &r, &r1, &r2);
    double prev = std::hypot(r, r1);
    for (int i = 1; i <= kGrid; ++i) {
      sh.Radius(sh.Phi(i), &r, &r1, &r2);
      const double cur = std::hypot(r, r1);
      arc[i] = arc[i - 1] + 0.5 * (prev + cur) * 2 * pi / kGrid;
      prev = cur;
    }
  }
  const double loop = arc[kGrid];

  // Seeded gaps around the mean spacing, rescaled to close the loop exactly.
  const int n = std::max(8, static_cast<int>(std::lround(loop / o.spacing)));
  std::vector<double> gaps(n);
  double gsum = 0;
  for (double& g : gaps) {
    g = o.spacing * (1 + kSpacingJitter * (2 * Uniform(rng) - 1));
    gsum += g;
  }
  for (double& g : gaps) g *= loop / gsum;

  Track track;
  track.source = "generated";
  double a = 0;
  int cell = 0;
  for (int k = 0; k < n; ++k) {
    while (cell + 1 < kGrid && arc[cell + 1] <= a) ++cell;
    const double f = (a - arc[cell]) / (arc[cell + 1] - arc[cell]);
    const double phi = sh.Phi(cell) + f * 2 * pi / kGrid;
    double r, r1, r2;
    sh.Radius(phi, &r, &r1, &r2);
    const double c = std::cos(phi), s = std::sin(phi);
    const double tx = r1 * c - r * s, ty = r1 * s + r * c;  // dP/dphi: counter-clockwise
    const double tn = std::hypot(tx, ty);
    Waypoint w;
    w.x = o.centre_x + r * c;
    w.y = o.centre_y + r * s;
    w.dx = ty / tn;  // right normal of the driving direction
    w.dy = -tx / tn;
    w.s = track.waypoints.empty()
              ? 0.0
              : track.waypoints.back().s +
                    std::hypot(w.x - track.waypoints.back().x, w.y - track.waypoints.back().y);
    track.waypoints.push_back(w);
    a += gaps[k];
  }
  const Waypoint& first = track.waypoints.front();
  const Waypoint& last = track.waypoints.back();
  track.max_s = last.s + std::hypot(first.x - last.x, first.y - last.y);
  return track;
}

}  // namespace frenetic::map

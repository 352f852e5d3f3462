// The reference line is a periodic uniform quintic B-spline fitted with Ceres, then resampled by
// its own arc length. Quintic so that curvature and its derivative are continuous (C4 curve);
// periodic (control points indexed modulo N) so that nothing special happens at the seam.
//
// Fit: control points every ~control_spacing m; waypoint i is tied to the spline parameter
// u_i = N (s_i - s_0) / max_s (the map's s is the chord length, close to arc length). Residuals:
// (point(u_i) - p_i) per waypoint and sqrt(lambda w h) r'''(u)/h^3 at 3 Gauss points per span,
// i.e. lambda times the integral of |d^3 r / ds^3|^2, which is the change of curvature for a
// curve at near-constant speed. The problem is linear in the control points, so Ceres (sparse
// normal Cholesky) solves it in one Gauss-Newton step. A plain L2 balance cannot keep both the
// worst waypoint distance and the worst change of curvature small on a rough map (the Udacity
// map: 0.27 m and 1.3e-4 1/m per 0.5 m at best), so a few passes follow, each moving the
// waypoint parameters to their foot points (parameter correction) and raising the weight of the
// waypoints / spans that are worst (iterative reweighting towards the max-norm): 0.25 m and
// 8.7e-5 on that map.
//
// Queries: between two dense samples the line is a cubic Hermite in position (tangents from the
// sampled heading), in heading (slopes = curvature) and in curvature (slopes = dkappa). ToCartesian
// and ToFrenet both use exactly these interpolants, with the normal taken from the interpolated
// heading, so they are inverses of each other to Newton precision.
#include "frenetic/map/reference_line.h"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "frenetic/check.h"
#include "frenetic/map/chord_frenet.h"

namespace frenetic::map {
namespace {

constexpr int kDegree = 5;
constexpr int kOrder = kDegree + 1;  // control points per span
constexpr double kPi = std::numbers::pi;
// m: the chord offset is stored at d = 0 and d = kChordD1 (it is nearly linear in d: over
// d in [0, 12] the Udacity map's offsets bend by < 1 cm).
constexpr double kChordD1 = 12.0;
// Scales smoothness_weight = 1 to a useful balance between the data term (m^2 at ~180
// waypoints) and the integral of |r_sss|^2 (~1e-4 1/m^2 squared over ~7 km).
constexpr double kSmoothnessScale = 1e6;
constexpr int kMinControlPoints = 8;
// Refits after moving each waypoint's parameter to its foot point on the previous fit.
constexpr int kParameterCorrections = 5;
// Waypoints farther than this from a fit get a larger data weight in the next pass: the least
// squares balance alone leaves a few waypoints of a rough map far off (L-infinity by reweighting).
constexpr double kTargetDistance = 0.22;
constexpr double kMaxReweight = 2.0;
// Likewise spans whose change of curvature exceeds this (1/m^2) get more smoothness weight.
constexpr double kTargetDkappa = 1.4e-4;

// To [-pi, pi]. The line's unwrapped headings stay within a few turns, so subtracting whole
// turns is exact enough and far cheaper than std::remainder on the per-point hot path.
double WrapAngle(double a) {
  if (a > kPi || a < -kPi) a -= 2 * kPi * std::nearbyint(a / (2 * kPi));
  return a;
}

// Polynomial coefficients (in local t in [0,1)) of the six uniform quintic B-spline weights of a
// span, from the truncated-power form of the cardinal B-spline.
struct QuinticBasis {
  std::array<std::array<double, kOrder>, kOrder> m{};  // m[k][j]: weight k, coefficient of t^j
  QuinticBasis() {
    auto binom = [](int n, int k) {
      double r = 1;
      for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
      return r;
    };
    for (int k = 0; k < kOrder; ++k) {
      for (int i = 0; i <= kDegree - k; ++i) {
        const double sign = (i % 2 == 0) ? 1.0 : -1.0;
        const double a = kDegree - k - i;  // (t + a)^5
        for (int j = 0; j <= kDegree; ++j) {
          m[k][j] += sign * binom(kOrder, i) * binom(kDegree, j) * std::pow(a, kDegree - j) / 120.0;
        }
      }
    }
  }
  // Weights of derivative `order` (0..3) at t.
  void Weights(double t, int order, double* w) const {
    double tp[kOrder];
    tp[0] = 1;
    for (int j = 1; j < kOrder; ++j) tp[j] = tp[j - 1] * t;
    for (int k = 0; k < kOrder; ++k) {
      double sum = 0;
      for (int j = order; j <= kDegree; ++j) {
        double f = 1;
        for (int q = 0; q < order; ++q) f *= (j - q);
        sum += m[k][j] * f * tp[j - order];
      }
      w[k] = sum;
    }
  }
};

const QuinticBasis& Basis() {
  static const QuinticBasis basis;
  return basis;
}

// A residual that is a fixed linear combination of six 2-D control points minus a target.
class LinearResidual : public ceres::SizedCostFunction<2, 2, 2, 2, 2, 2, 2> {
 public:
  LinearResidual(const double* weights, double scale, double tx, double ty)
      : scale_(scale), tx_(tx), ty_(ty) {
    for (int k = 0; k < kOrder; ++k) w_[k] = weights[k] * scale;
  }
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    double rx = -tx_ * scale_, ry = -ty_ * scale_;
    for (int k = 0; k < kOrder; ++k) {
      rx += w_[k] * params[k][0];
      ry += w_[k] * params[k][1];
    }
    residuals[0] = rx;
    residuals[1] = ry;
    if (jacobians != nullptr) {
      for (int k = 0; k < kOrder; ++k) {
        if (jacobians[k] == nullptr) continue;
        jacobians[k][0] = w_[k];
        jacobians[k][1] = 0;
        jacobians[k][2] = 0;
        jacobians[k][3] = w_[k];
      }
    }
    return true;
  }

 private:
  double w_[kOrder];
  double scale_, tx_, ty_;
};

// The fitted spline: evaluation of position and derivatives w.r.t. the parameter u in [0, N).
struct Spline {
  std::vector<double> px, py;  // control points
  int n() const { return static_cast<int>(px.size()); }
  // Derivative `order` of the curve at u (wrapped).
  void Eval(double u, int order, double* x, double* y) const {
    const int nn = n();
    double fl = std::floor(u);
    double t = u - fl;
    long j = static_cast<long>(fl) % nn;
    if (j < 0) j += nn;
    double w[kOrder];
    Basis().Weights(t, order, w);
    double sx = 0, sy = 0;
    for (int k = 0; k < kOrder; ++k) {
      const int idx = static_cast<int>(((j + k - 2) % nn + nn) % nn);
      sx += w[k] * px[idx];
      sy += w[k] * py[idx];
    }
    *x = sx;
    *y = sy;
  }
  double DKappaDs(double u) const {
    double x1, y1, x2, y2, x3, y3;
    Eval(u, 1, &x1, &y1);
    Eval(u, 2, &x2, &y2);
    Eval(u, 3, &x3, &y3);
    const double v2 = x1 * x1 + y1 * y1, v = std::sqrt(v2);
    const double c = x1 * y2 - y1 * x2, dc = x1 * y3 - y1 * x3;
    const double dv = (x1 * x2 + y1 * y2) / v;
    return (dc * v - 3 * c * dv) / (v2 * v2 * v);
  }
  double Speed(double u) const {
    double x, y;
    Eval(u, 1, &x, &y);
    return std::hypot(x, y);
  }
};

// 5-point Gauss-Legendre on [0, 1].
constexpr std::array<double, 5> kGaussX = {0.046910077030668, 0.230765344947158, 0.5,
                                           0.769234655052842, 0.953089922969332};
constexpr std::array<double, 5> kGaussW = {0.118463442528095, 0.239314335249683, 0.284444444444444,
                                           0.239314335249683, 0.118463442528095};

double ArcLength(const Spline& sp, double u0, double u1) {
  double sum = 0;
  for (int q = 0; q < 5; ++q) sum += kGaussW[q] * sp.Speed(u0 + (u1 - u0) * kGaussX[q]);
  return sum * (u1 - u0);
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

}  // namespace

struct ReferenceLine::Impl {
  double length = 0;
  double step = 0;
  double inv_step = 0;
  int n = 0;
  std::vector<RefSample> samples;
  // Struct-of-arrays copies with n + 1 entries (entry n repeats sample 0 at s = length, heading
  // unwrapped), so segment i always interpolates between entries i and i + 1.
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
  // Splits an unwrapped sample coordinate sigma = s / step into (segment, t).
  void Split(double sigma, int* i, double* t) const {
    const double fl = std::floor(sigma);
    long j = static_cast<long>(fl) % n;
    if (j < 0) j += n;
    *i = static_cast<int>(j);
    *t = sigma - fl;
  }
  double Dist2(int i, double px, double py) const {
    const double ex = x[i] - px, ey = y[i] - py;
    return ex * ex + ey * ey;
  }
  int Wrap(long i) const {
    long j = i % n;
    return static_cast<int>(j < 0 ? j + n : j);
  }
  int NearestGlobal(double px, double py) const;
  int NearestLocal(double px, double py, int start, bool* ok) const;
  FrenetPoint Project(double px, double py, int nearest) const;
};

int ReferenceLine::Impl::NearestGlobal(double px, double py) const {
  // Coarse scan every kStride samples, then refine around every coarse sample that can still hold
  // the nearest one: a sample j is within kStride/2 samples (arc) of a coarse one, so its coarse
  // neighbour is at most kStride/2 * step farther than j itself.
  constexpr int kStride = 8;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; i += kStride) best = std::min(best, Dist2(i, px, py));
  const double margin = (kStride / 2 + 1) * step;
  const double limit = std::sqrt(best) + margin;
  const double limit2 = limit * limit;
  int best_i = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; i += kStride) {
    if (Dist2(i, px, py) > limit2) continue;
    for (int o = -kStride / 2 - 1; o <= kStride / 2 + 1; ++o) {
      const int j = Wrap(i + o);
      const double d2 = Dist2(j, px, py);
      if (d2 < best_d2 || (d2 == best_d2 && j < best_i)) {
        best_d2 = d2;
        best_i = j;
      }
    }
  }
  return best_i;
}

int ReferenceLine::Impl::NearestLocal(double px, double py, int start, bool* ok) const {
  // Downhill walk over the samples; the hint is usually within a few metres of the answer.
  constexpr int kMaxSteps = 400;
  int i = start;
  double di = Dist2(i, px, py);
  for (int steps = 0; steps < kMaxSteps; ++steps) {
    const int a = Wrap(i - 1), b = Wrap(i + 1);
    const double da = Dist2(a, px, py), db = Dist2(b, px, py);
    if (da < di && da <= db) {
      i = a;
      di = da;
    } else if (db < di) {
      i = b;
      di = db;
    } else {
      *ok = true;
      return i;
    }
  }
  *ok = false;
  return i;
}

FrenetPoint ReferenceLine::Impl::Project(double px, double py, int nearest) const {
  // f(sigma) = (p - C) . t is positive while the foot of p lies ahead of C. Bracket a sign change
  // around the nearest sample, then safeguarded Newton (bisection when Newton leaves the bracket).
  auto f_of = [&](double sigma, Eval* out) {
    int i;
    double t;
    Split(sigma, &i, &t);
    const Eval e = At(i, t);
    if (out) *out = e;
    const double c = e.c, s = e.s;
    return (px - e.x) * c + (py - e.y) * s;
  };
  auto finish = [&](double sigma, const Eval& e) {
    const double c = e.c, s = e.s;
    FrenetPoint out;
    out.d = (px - e.x) * s - (py - e.y) * c;
    double sw = std::fmod(sigma * step, length);
    if (sw < 0) sw += length;
    if (sw >= length) sw = 0;
    out.s = sw;
    return out;
  };
  // Fast path: plain Newton from the nearest sample, as long as it stays on the two segments
  // around it and descends; f is in metres, so |f| < 1e-9 is converged far below 1 cm.
  {
    double sigma = nearest;
    for (int it = 0; it < 8; ++it) {
      Eval e;
      const double f = f_of(sigma, &e);
      if (std::abs(f) < 1e-9) return finish(sigma, e);
      const double c = e.c, s = e.s;
      const double fp = -(e.dx * c + e.dy * s) - e.dth * ((px - e.x) * s - (py - e.y) * c);
      if (!(fp < 0)) break;
      sigma -= f / fp * inv_step;
      if (std::abs(sigma - nearest) > 1.0) break;
    }
  }
  double lo = nearest - 1.0, hi = nearest + 1.0;
  double flo = f_of(lo, nullptr), fhi = f_of(hi, nullptr);
  for (int ext = 0; ext < 8 && flo < 0; ++ext) {
    hi = lo;
    fhi = flo;
    lo -= 1.0;
    flo = f_of(lo, nullptr);
  }
  for (int ext = 0; ext < 8 && fhi > 0; ++ext) {
    lo = hi;
    flo = fhi;
    hi += 1.0;
    fhi = f_of(hi, nullptr);
  }
  double sigma = nearest;
  if (!(flo >= 0 && fhi <= 0)) {
    // No sign change (p at the centre of curvature, or degenerate): keep the nearest sample.
    sigma = std::abs(flo) < std::abs(fhi) ? lo : hi;
  } else {
    sigma = std::clamp(sigma, lo, hi);
    for (int it = 0; it < 60; ++it) {
      Eval e;
      const double f = f_of(sigma, &e);
      if (f > 0) {
        lo = sigma;
      } else {
        hi = sigma;
      }
      const double c = e.c, s = e.s;
      const double rx = px - e.x, ry = py - e.y;
      const double fp = -(e.dx * c + e.dy * s) - e.dth * (rx * s - ry * c);  // df/ds
      double next = sigma;
      bool newton = fp < 0;
      if (newton) {
        next = sigma - f / fp * inv_step;
        newton = next > lo && next < hi;
      }
      if (!newton) next = 0.5 * (lo + hi);
      const double delta = std::abs(next - sigma) * step;
      sigma = next;
      if (delta < 1e-10 || (hi - lo) * step < 1e-10) break;
    }
  }
  Eval e;
  f_of(sigma, &e);
  return finish(sigma, e);
}

Status ReferenceLine::Options::Validate() const {
  if (!(sample_step > 0 && sample_step <= 1.0)) {
    return Status::Error("ReferenceLine::Options: sample_step must be in (0, 1] m, got " +
                         std::to_string(sample_step));
  }
  if (!(control_spacing >= 1.0 && control_spacing <= 1000.0)) {
    return Status::Error("ReferenceLine::Options: control_spacing must be in [1, 1000] m, got " +
                         std::to_string(control_spacing));
  }
  if (!(smoothness_weight >= 0 && std::isfinite(smoothness_weight))) {
    return Status::Error("ReferenceLine::Options: smoothness_weight must be finite and >= 0, got " +
                         std::to_string(smoothness_weight));
  }
  if (max_iterations < 1) {
    return Status::Error("ReferenceLine::Options: max_iterations must be >= 1, got " +
                         std::to_string(max_iterations));
  }
  return Status::Ok();
}

StatusOr<std::shared_ptr<const ReferenceLine>> ReferenceLine::Fit(const Track& track,
                                                                  const Options& options) {
  if (Status st = options.Validate(); !st.ok()) return st;
  const auto& wps = track.waypoints;
  const int nw = static_cast<int>(wps.size());
  const std::string src = track.source.empty() ? std::string("track") : track.source;
  if (nw < 4) return Status::Error(src + ": need at least 4 waypoints to fit a reference line");
  const double s0 = wps.front().s;
  const double period = track.max_s - s0;
  if (!std::isfinite(period) || !(track.max_s > wps.back().s)) {
    return Status::Error(src + ": max_s must be greater than the last waypoint's s");
  }

  // Control points: one every ~control_spacing m.
  const int nc =
      std::max(kMinControlPoints, static_cast<int>(std::lround(period / options.control_spacing)));
  const double h = period / nc;  // metres of map s per unit of u
  Spline sp;
  sp.px.resize(nc);
  sp.py.resize(nc);
  {
    // Initial guess: the waypoint polyline at map s = m h (control point m is centred at u = m).
    int seg = 0;
    for (int m = 0; m < nc; ++m) {
      const double s = m * h;
      while (seg + 1 < nw && wps[seg + 1].s - s0 <= s) ++seg;
      const Waypoint& a = wps[seg];
      const Waypoint& b = wps[(seg + 1) % nw];
      const double sa = a.s - s0, sb = (seg + 1 < nw) ? b.s - s0 : period;
      const double f = std::clamp((s - sa) / std::max(sb - sa, 1e-9), 0.0, 1.0);
      sp.px[m] = a.x + f * (b.x - a.x);
      sp.py[m] = a.y + f * (b.y - a.y);
    }
  }

  // Waypoint parameters: the map's s first, then each waypoint's foot point on the previous fit
  // (parameter correction, Hoschek 1988), so that the data term measures the distance to the
  // curve rather than to a point forced by the chord-length parametrisation. Waypoint 0 stays at
  // u = 0: it anchors s = 0.
  std::vector<double> wp_u(nw);
  for (int i = 0; i < nw; ++i) wp_u[i] = (wps[i].s - s0) / h;
  std::vector<double> params(2 * nc);
  for (int m = 0; m < nc; ++m) {
    params[2 * m] = sp.px[m];
    params[2 * m + 1] = sp.py[m];
  }
  auto blocks_for = [&](double u, double* w, int order, std::vector<double*>* blocks) {
    const double fl = std::floor(u);
    long j = static_cast<long>(fl) % nc;
    if (j < 0) j += nc;
    Basis().Weights(u - fl, order, w);
    blocks->clear();
    for (int k = 0; k < kOrder; ++k) {
      blocks->push_back(&params[2 * (((j + k - 2) % nc + nc) % nc)]);
    }
  };
  const double lambda = options.smoothness_weight * kSmoothnessScale;
  std::vector<double> data_weight(nw, 1.0);
  std::vector<double> span_weight(nc, 1.0);
  ceres::Solver::Summary summary;
  for (int pass = 0; pass <= kParameterCorrections; ++pass) {
    ceres::Problem problem;
    std::vector<double*> blocks;
    double w[kOrder];
    for (int i = 0; i < nw; ++i) {
      blocks_for(wp_u[i], w, 0, &blocks);
      problem.AddResidualBlock(new LinearResidual(w, data_weight[i], wps[i].x, wps[i].y), nullptr,
                               blocks);
    }
    if (lambda > 0) {
      constexpr std::array<double, 3> kGx = {0.112701665379258, 0.5, 0.887298334620742};
      constexpr std::array<double, 3> kGw = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
      for (int j = 0; j < nc; ++j) {
        for (int q = 0; q < 3; ++q) {
          blocks_for(j + kGx[q], w, 3, &blocks);
          const double scale = std::sqrt(lambda * span_weight[j] * kGw[q] * h) / (h * h * h);
          problem.AddResidualBlock(new LinearResidual(w, scale, 0.0, 0.0), nullptr, blocks);
        }
      }
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    so.max_num_iterations = options.max_iterations;
    so.initial_trust_region_radius = 1e12;  // linear problem: take the full Gauss-Newton step
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.num_threads = 1;
    ceres::Solve(so, &problem, &summary);
    if (!summary.IsSolutionUsable()) {
      return Status::Error(src + ": reference line fit failed: " + summary.message);
    }
    for (int m = 0; m < nc; ++m) {
      sp.px[m] = params[2 * m];
      sp.py[m] = params[2 * m + 1];
      if (!std::isfinite(sp.px[m]) || !std::isfinite(sp.py[m])) {
        return Status::Error(src + ": reference line fit produced non-finite control points");
      }
    }
    if (pass == kParameterCorrections) break;
    if (lambda > 0) {
      for (int j = 0; j < nc; ++j) {
        double worst = 0;
        for (double t : {0.0, 0.25, 0.5, 0.75})
          worst = std::max(worst, std::abs(sp.DKappaDs(j + t)));
        if (worst > kTargetDkappa) span_weight[j] *= std::min(kMaxReweight, worst / kTargetDkappa);
      }
    }
    for (int i = 0; i < nw; ++i) {
      double u = wp_u[i];
      for (int it = 0; it < 8 && i > 0; ++it) {
        double x, y, x1, y1, x2, y2;
        sp.Eval(u, 0, &x, &y);
        sp.Eval(u, 1, &x1, &y1);
        sp.Eval(u, 2, &x2, &y2);
        const double ex = x - wps[i].x, ey = y - wps[i].y;
        const double g = ex * x1 + ey * y1;
        const double gp = x1 * x1 + y1 * y1 + ex * x2 + ey * y2;
        if (!(gp > 0)) break;
        const double du = std::clamp(g / gp, -0.5, 0.5);
        u -= du;
        if (std::abs(du) < 1e-9) break;
      }
      double x, y;
      sp.Eval(u, 0, &x, &y);
      const double dist = std::hypot(x - wps[i].x, y - wps[i].y);
      if (dist > kTargetDistance) {
        data_weight[i] *= std::min(kMaxReweight, dist / kTargetDistance);
      }
      if (i == 0) continue;
      // Keep the waypoints in order and inside the loop's parameter range.
      const double lo = wp_u[i - 1] + 1e-3;
      const double hi = (i + 1 < nw ? wp_u[i + 1] : static_cast<double>(nc)) - 1e-3;
      wp_u[i] = std::clamp(u, lo, std::max(lo, hi));
    }
  }
  spdlog::debug("reference line {}: {} control points, ceres {} iterations, cost {:.4g} -> {:.4g}",
                src, nc, summary.iterations.size(), summary.initial_cost, summary.final_cost);

  // Arc length of every span (u in [j, j+1)).
  std::vector<double> cum(nc + 1, 0.0);
  for (int j = 0; j < nc; ++j) {
    const double half = 0.5;  // two Gauss panels per span: spans are ~10 m of nearly-constant speed
    cum[j + 1] = cum[j] + ArcLength(sp, j, j + half) + ArcLength(sp, j + half, j + 1);
  }
  const double length = cum[nc];
  for (int j = 0; j < nc; ++j) {
    if (!(cum[j + 1] - cum[j] > 1e-6)) {
      return Status::Error(src + ": reference line fit is degenerate (zero-length span)");
    }
  }
  auto arc_to = [&](double u) {
    const int j = std::clamp(static_cast<int>(std::floor(u)), 0, nc - 1);
    return cum[j] + ArcLength(sp, j, u);
  };

  auto impl = std::make_unique<Impl>();
  impl->length = length;
  const int n = std::max(8, static_cast<int>(std::ceil(length / options.sample_step)));
  impl->n = n;
  impl->step = length / n;
  impl->inv_step = 1.0 / impl->step;
  impl->samples.resize(n);
  double u = 0;
  for (int i = 0; i < n; ++i) {
    const double s = i * impl->step;
    // Newton on arc(u) = s, starting from the previous sample's u.
    for (int it = 0; it < 20; ++it) {
      const double err = arc_to(u) - s;
      const double du = err / sp.Speed(u);
      u = std::clamp(u - du, 0.0, static_cast<double>(nc) - 1e-12);
      if (std::abs(err) < 1e-10) break;
    }
    double x, y, x1, y1, x2, y2, x3, y3;
    sp.Eval(u, 0, &x, &y);
    sp.Eval(u, 1, &x1, &y1);
    sp.Eval(u, 2, &x2, &y2);
    sp.Eval(u, 3, &x3, &y3);
    const double v2 = x1 * x1 + y1 * y1;
    const double v = std::sqrt(v2);
    const double c = x1 * y2 - y1 * x2;
    const double dc = x1 * y3 - y1 * x3;
    const double dv = (x1 * x2 + y1 * y2) / v;
    RefSample& r = impl->samples[i];
    r.s = s;
    r.x = x;
    r.y = y;
    r.heading = std::atan2(y1, x1);
    r.kappa = c / (v2 * v);
    r.dkappa = (dc * v - 3 * c * dv) / (v2 * v2 * v);  // (dkappa/du) / (ds/du)
    u += impl->step / v;
  }

  // Struct-of-arrays with the closing entry, heading unwrapped.
  impl->x.resize(n + 1);
  impl->y.resize(n + 1);
  impl->th.resize(n + 1);
  impl->tx.resize(n + 1);
  impl->ty.resize(n + 1);
  impl->k.resize(n + 1);
  impl->dk.resize(n + 1);
  for (int i = 0; i <= n; ++i) {
    const RefSample& r = impl->samples[i % n];
    impl->x[i] = r.x;
    impl->y[i] = r.y;
    impl->th[i] = (i == 0) ? r.heading : impl->th[i - 1] + WrapAngle(r.heading - impl->th[i - 1]);
    impl->tx[i] = std::cos(r.heading);
    impl->ty[i] = std::sin(r.heading);
    impl->k[i] = r.kappa;
    impl->dk[i] = r.dkappa;
  }
  // Entry n continues the unwrapped heading; the loop closes with a whole number of turns, which
  // only shifts heading by a multiple of 2 pi (harmless for cos/sin and wrapped output).

  std::shared_ptr<ReferenceLine> line(new ReferenceLine(std::move(impl)));
  double max_dist = 0, max_ds = 0;
  for (const Waypoint& wp : wps) {
    const FrenetPoint f = line->ToFrenet(wp.x, wp.y);
    max_dist = std::max(max_dist, std::abs(f.d));
    max_ds = std::max(max_ds, std::abs(line->DiffS(f.s, wp.s - s0)));
  }
  line->impl_->max_waypoint_distance = max_dist;
  line->impl_->max_map_s_difference = max_ds;
  // The simulator's reading of d at every sample (float32 chords, as it computes them).
  const ChordFrenet chords(track);
  Impl& m = *line->impl_;
  m.chord0.resize(n);
  m.chord1.resize(n);
  for (int i = 0; i < n; ++i) {
    const double si = i * m.step;
    const CartesianPose p0 = line->ToCartesian(si, 0.0), p1 = line->ToCartesian(si, kChordD1);
    const double c0 = chords.Convert(p0.x, p0.y).d, c1 = chords.Convert(p1.x, p1.y).d;
    m.chord0[i] = std::isfinite(c0) ? c0 : 0.0;
    m.chord1[i] = std::isfinite(c1) ? c1 - kChordD1 : 0.0;
  }
  return std::shared_ptr<const ReferenceLine>(std::move(line));
}

ReferenceLine::ReferenceLine(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {
  FRENETIC_CHECK(impl_ != nullptr);
}
ReferenceLine::~ReferenceLine() = default;

double ReferenceLine::length() const { return impl_->length; }

double ReferenceLine::WrapS(double s) const {
  const double len = impl_->length;
  if (s >= 0 && s < len) return s;  // the common case, without fmod
  if (!std::isfinite(s)) return 0;
  double r = std::fmod(s, len);
  if (r < 0) r += len;
  if (r >= len) r = 0;  // -tiny + len rounds to len
  return r;
}

double ReferenceLine::DiffS(double s_to, double s_from) const {
  const double len = impl_->length;
  double d = WrapS(s_to - s_from);  // [0, L)
  if (d >= 0.5 * len) d -= len;
  return d;
}

CartesianPose ReferenceLine::ToCartesian(double s, double d) const {
  const Impl& m = *impl_;
  const double sigma = WrapS(s) * m.inv_step;
  int i = static_cast<int>(sigma);
  if (i >= m.n) i = m.n - 1;
  const double t = sigma - i;
  const Hermite h = HermiteAt(t);
  const double st = m.step;
  const double x =
      h.h00 * m.x[i] + h.h10 * st * m.tx[i] + h.h01 * m.x[i + 1] + h.h11 * st * m.tx[i + 1];
  const double y =
      h.h00 * m.y[i] + h.h10 * st * m.ty[i] + h.h01 * m.y[i + 1] + h.h11 * st * m.ty[i + 1];
  const double th =
      h.h00 * m.th[i] + h.h10 * st * m.k[i] + h.h01 * m.th[i + 1] + h.h11 * st * m.k[i + 1];
  const double k =
      h.h00 * m.k[i] + h.h10 * st * m.dk[i] + h.h01 * m.k[i + 1] + h.h11 * st * m.dk[i + 1];
  double c, sn;
  m.CosSin(i, th, &c, &sn);
  if (!std::isfinite(d)) d = 0;
  CartesianPose p;
  p.x = x + d * sn;  // right normal (sin, -cos)
  p.y = y - d * c;
  p.heading = WrapAngle(th);
  // Offset curve C + d n with n the right normal: dn/ds = kappa t, so its speed is 1 + kappa d and
  // its curvature kappa / (1 + kappa d). Beyond the centre of curvature the offset curve has a
  // cusp; keep the value finite there.
  double denom = 1.0 + k * d;
  if (std::abs(denom) < 1e-6) denom = std::copysign(1e-6, denom);
  p.kappa = k / denom;
  return p;
}

FrenetPoint ReferenceLine::ToFrenet(double x, double y) const {
  if (!std::isfinite(x) || !std::isfinite(y)) return FrenetPoint{0, 0};
  return impl_->Project(x, y, impl_->NearestGlobal(x, y));
}

FrenetPoint ReferenceLine::ToFrenet(double x, double y, double s_hint) const {
  if (!std::isfinite(x) || !std::isfinite(y)) return FrenetPoint{0, 0};
  if (!std::isfinite(s_hint)) return ToFrenet(x, y);
  const Impl& m = *impl_;
  int start = static_cast<int>(WrapS(s_hint) * m.inv_step);
  if (start >= m.n) start = m.n - 1;
  bool ok = false;
  const int nearest = m.NearestLocal(x, y, start, &ok);
  if (!ok) return ToFrenet(x, y);
  const FrenetPoint f = m.Project(x, y, nearest);
  // A local minimum far from the road may belong to another part of the loop: confirm globally.
  constexpr double kTrustedOffset = 40.0;
  if (std::abs(f.d) > kTrustedOffset) return ToFrenet(x, y);
  return f;
}

ReferenceLine::OffsetRange ReferenceLine::ChordOffset(double s_from, double s_to,
                                                     double d) const {
  const Impl& m = *impl_;
  OffsetRange r;
  if (m.chord0.empty() || !std::isfinite(s_from) || !std::isfinite(s_to) || !std::isfinite(d)) {
    return r;
  }
  // Every sample from the one at or before s_from to the one at or after s_to.
  const double lo = WrapS(s_from) * m.inv_step;
  const int first = static_cast<int>(lo);
  // Clamped in double before the cast: a huge span (hostile input) must not overflow the int.
  const double span =
      std::ceil(lo + std::max(0.0, s_to - s_from) * m.inv_step) - static_cast<double>(first) + 1;
  const int count = static_cast<int>(std::min(static_cast<double>(m.n), span));
  const double w = d / kChordD1;
  r.lo = std::numeric_limits<double>::infinity();
  r.hi = -r.lo;
  for (int j = 0; j < count; ++j) {
    const int i = (first + j) % m.n;
    const double off = m.chord0[i] + (m.chord1[i] - m.chord0[i]) * w;
    r.lo = std::min(r.lo, off);
    r.hi = std::max(r.hi, off);
  }
  return r;
}

RefSample ReferenceLine::At(double s) const {
  const Impl& m = *impl_;
  const double sw = WrapS(s);
  const double sigma = sw * m.inv_step;
  int i = static_cast<int>(sigma);
  if (i >= m.n) i = m.n - 1;
  const double t = sigma - i;
  const Impl::Eval e = m.At(i, t);
  const Hermite h = HermiteAt(t);
  const double st = m.step;
  RefSample r;
  r.s = sw;
  r.x = e.x;
  r.y = e.y;
  r.heading = WrapAngle(e.th);
  r.kappa = e.k;
  // Derivative of the same curvature interpolant that ToCartesian uses.
  r.dkappa =
      (h.d00 * m.k[i] + h.d10 * st * m.dk[i] + h.d01 * m.k[i + 1] + h.d11 * st * m.dk[i + 1]) *
      m.inv_step;
  return r;
}

const std::vector<RefSample>& ReferenceLine::samples() const { return impl_->samples; }
double ReferenceLine::max_waypoint_distance() const { return impl_->max_waypoint_distance; }
double ReferenceLine::max_map_s_difference() const { return impl_->max_map_s_difference; }

}  // namespace frenetic::map

// The reference line's fit (see reference_line.cc for the line itself): a periodic uniform
// quintic B-spline fitted to the waypoints with Ceres, then sampled by its own arc length
// into the tables the queries interpolate.
#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "frenetic/check.h"
#include "frenetic/map/chord_frenet.h"
#include "frenetic/map/reference_line.h"
#include "map/reference_line_impl.h"

namespace frenetic::map {
namespace {

using detail::kChordD1;
using detail::kPi;
using detail::WrapAngle;

constexpr int kDegree = 5;
constexpr int kOrder = kDegree + 1;  // control points per span
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
// FitOpen: points closer than this are one; the polyline is resampled every kOpenSpacing m and
// extended straight by at least kOpenExtension m at each end, along the direction of its last
// kOpenEndProbe m.
constexpr double kOpenMinSpacing = 1e-3;
constexpr double kOpenSpacing = 2.0;
constexpr double kOpenExtension = 30.0;
constexpr double kOpenEndProbe = 5.0;
// m: the longest line fitted (Fit: the loop, FitOpen: the polyline). Memory and time grow with
// the length (a control point every control_spacing, FitOpen's samples every kOpenSpacing): one
// coordinate off by a few orders of magnitude in a map file must fail here, with a message, not
// take every gigabyte the machine has. Real roads fit so far are under 10 km.
constexpr double kMaxLineLength = 200e3;

std::string LengthError(const std::string& src, double length) {
  char text[160];
  std::snprintf(text, sizeof(text),
                ": the line is %.0f km long, more than the %.0f km a fit takes (a point far off "
                "the rest?)",
                length / 1e3, kMaxLineLength / 1e3);
  return src + text;
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
// Periodic (closed: N control points indexed modulo N, u in [0, N)) or open (N spans, u in
// [0, N], N + 5 control points: span j is shaped by points j..j + 5, none repeated).
struct Spline {
  std::vector<double> px, py;  // control points
  bool closed = true;
  int n() const { return static_cast<int>(px.size()); }
  int spans() const { return closed ? n() : n() - kDegree; }
  // The control point that weight k of span j multiplies.
  int Index(long j, int k) const {
    const long nn = n();
    return closed ? static_cast<int>(((j + k - 2) % nn + nn) % nn) : static_cast<int>(j + k);
  }
  // Derivative `order` of the curve at u (wrapped; an open one's u clamped to its spans).
  void Eval(double u, int order, double* x, double* y) const {
    const int nn = n();
    double fl = std::floor(u);
    if (!closed) fl = std::clamp(fl, 0.0, spans() - 1.0);  // the last span includes u = N
    double t = u - fl;
    long j = static_cast<long>(fl);
    if (closed) {
      j %= nn;
      if (j < 0) j += nn;
    }
    double w[kOrder];
    Basis().Weights(t, order, w);
    double sx = 0, sy = 0;
    for (int k = 0; k < kOrder; ++k) {
      const int idx = Index(j, k);
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
}  // namespace

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

// The fit of Fit (closed: the track's loop) and FitOpen (open: `open` says which waypoints are
// the line's own, the others being its straight extensions).
StatusOr<std::shared_ptr<const ReferenceLine>> ReferenceLine::FitLine(const Track& track,
                                                                      const Options& options,
                                                                      const OpenRange* open) {
  if (Status st = options.Validate(); !st.ok()) return st;
  const bool closed = open == nullptr;
  const auto& wps = track.waypoints;
  const int nw = static_cast<int>(wps.size());
  const std::string src = track.source.empty() ? std::string("track") : track.source;
  if (nw < 4) return Status::Error(src + ": need at least 4 waypoints to fit a reference line");
  const double s0 = wps.front().s;
  // Closed: the loop's length; open: the parameter range's (the last waypoint's s).
  const double period = closed ? track.max_s - s0 : wps.back().s - s0;
  if (closed && (!std::isfinite(period) || !(track.max_s > wps.back().s))) {
    return Status::Error(src + ": max_s must be greater than the last waypoint's s");
  }
  if (!(period <= kMaxLineLength)) return Status::Error(LengthError(src, period));

  // Control points: one every ~control_spacing m (spans; an open line has kDegree more).
  const int spans =
      std::max(kMinControlPoints, static_cast<int>(std::lround(period / options.control_spacing)));
  const int nc = closed ? spans : spans + kDegree;
  const double h = period / spans;  // metres of map s per unit of u
  const double u_max = spans;       // u in [0, u_max)
  Spline sp;
  sp.closed = closed;
  sp.px.resize(nc);
  sp.py.resize(nc);
  {
    // Initial guess: the waypoint polyline at map s = m h (control point m is centred at u = m;
    // an open line's at u = m - 2.5, within its ends).
    int seg = 0;
    for (int m = 0; m < nc; ++m) {
      const double s = closed ? m * h : std::clamp((m - 2.5) * h, 0.0, period);
      while (seg + 1 < nw && wps[seg + 1].s - s0 <= s) ++seg;
      const Waypoint& a = wps[seg];
      const Waypoint& b = wps[closed ? (seg + 1) % nw : std::min(seg + 1, nw - 1)];
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
    double fl = std::floor(u);
    if (!closed) fl = std::clamp(fl, 0.0, spans - 1.0);
    long j = static_cast<long>(fl);
    if (closed) {
      j %= nc;
      if (j < 0) j += nc;
    }
    Basis().Weights(u - fl, order, w);
    blocks->clear();
    for (int k = 0; k < kOrder; ++k) blocks->push_back(&params[2 * sp.Index(j, k)]);
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
      for (int j = 0; j < spans; ++j) {
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
      for (int j = 0; j < spans; ++j) {
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
      const double hi = (i + 1 < nw ? wp_u[i + 1] : u_max) - 1e-3;
      wp_u[i] = std::clamp(u, lo, std::max(lo, hi));
    }
  }
  spdlog::debug("reference line {}: {} control points, ceres {} iterations, cost {:.4g} -> {:.4g}",
                src, nc, summary.iterations.size(), summary.initial_cost, summary.final_cost);

  // Arc length of every span (u in [j, j+1)).
  std::vector<double> cum(spans + 1, 0.0);
  for (int j = 0; j < spans; ++j) {
    const double half = 0.5;  // two Gauss panels per span: spans are ~10 m of nearly-constant speed
    cum[j + 1] = cum[j] + ArcLength(sp, j, j + half) + ArcLength(sp, j + half, j + 1);
  }
  for (int j = 0; j < spans; ++j) {
    if (!(cum[j + 1] - cum[j] > 1e-6)) {
      return Status::Error(src + ": reference line fit is degenerate (zero-length span)");
    }
  }
  auto arc_to = [&](double u) {
    const int j = std::clamp(static_cast<int>(std::floor(u)), 0, spans - 1);
    return cum[j] + ArcLength(sp, j, u);
  };
  // The line's s = 0 and its length: the loop's, or the open line's own waypoints' (the
  // extensions are left to the straight continuation beyond the ends).
  const double arc0 = closed ? 0.0 : arc_to(wp_u[open->first]);
  const double length = closed ? cum[spans] : arc_to(wp_u[open->last]) - arc0;
  if (!(length > 1e-3)) return Status::Error(src + ": reference line fit is degenerate (no length)");

  auto impl = std::make_unique<Impl>();
  impl->closed = closed;
  impl->length = length;
  const int n = std::max(8, static_cast<int>(std::ceil(length / options.sample_step)));
  impl->n = n;
  impl->step = length / n;
  impl->inv_step = 1.0 / impl->step;
  const int count = closed ? n : n + 1;  // an open line's last sample is its end
  impl->samples.resize(count);
  double u = closed ? 0.0 : wp_u[open->first];
  for (int i = 0; i < count; ++i) {
    const double s = arc0 + i * impl->step;
    // Newton on arc(u) = s, starting from the previous sample's u.
    for (int it = 0; it < 20; ++it) {
      const double err = arc_to(u) - s;
      const double du = err / sp.Speed(u);
      u = std::clamp(u - du, 0.0, u_max - 1e-12);
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
    r.s = s - arc0;
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
    const RefSample& r = impl->samples[i % count];
    impl->x[i] = r.x;
    impl->y[i] = r.y;
    impl->th[i] = (i == 0) ? r.heading : impl->th[i - 1] + WrapAngle(r.heading - impl->th[i - 1]);
    impl->tx[i] = std::cos(r.heading);
    impl->ty[i] = std::sin(r.heading);
    impl->k[i] = r.kappa;
    impl->dk[i] = r.dkappa;
  }
  // Closed: entry n continues the unwrapped heading; the loop closes with a whole number of
  // turns, which only shifts heading by a multiple of 2 pi (harmless for cos/sin and wrapped
  // output).

  std::shared_ptr<ReferenceLine> line(new ReferenceLine(std::move(impl)));
  double max_dist = 0, max_ds = 0;
  const int w_first = closed ? 0 : open->first, w_last = closed ? nw - 1 : open->last;
  for (int i = w_first; i <= w_last; ++i) {
    const Waypoint& wp = wps[i];
    const FrenetPoint f = line->ToFrenet(wp.x, wp.y);
    max_dist = std::max(max_dist, std::abs(f.d));
    max_ds = std::max(max_ds, std::abs(line->DiffS(f.s, wp.s - wps[w_first].s)));
  }
  line->impl_->max_waypoint_distance = max_dist;
  line->impl_->max_map_s_difference = max_ds;
  if (!closed) return std::shared_ptr<const ReferenceLine>(std::move(line));
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

StatusOr<std::shared_ptr<const ReferenceLine>> ReferenceLine::Fit(const Track& track,
                                                                  const Options& options) {
  return FitLine(track, options, nullptr);
}

StatusOr<std::shared_ptr<const ReferenceLine>> ReferenceLine::FitOpen(
    std::span<const Point> polyline, const Options& options, std::string_view source) {
  if (Status st = options.Validate(); !st.ok()) return st;
  const std::string src = source.empty() ? std::string("polyline") : std::string(source);
  // Distinct points (consecutive repeats dropped), finite.
  std::vector<Point> pts;
  for (const Point& p : polyline) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      return Status::Error(src + ": polyline point " + std::to_string(&p - polyline.data()) +
                           " is not finite");
    }
    if (pts.empty() || std::hypot(p.x - pts.back().x, p.y - pts.back().y) > kOpenMinSpacing) {
      pts.push_back(p);
    }
  }
  if (pts.size() < 2) return Status::Error(src + ": a line needs at least 2 distinct points");
  std::vector<double> cum(pts.size(), 0.0);
  for (size_t i = 1; i < pts.size(); ++i) {
    cum[i] = cum[i - 1] + std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y);
  }
  const double total = cum.back();
  if (!(total <= kMaxLineLength)) return Status::Error(LengthError(src, total));
  // The point at chord length c along the polyline (c may lie beyond either end: straight on).
  auto at = [&](double c) {
    size_t i = std::upper_bound(cum.begin(), cum.end(), c) - cum.begin();
    i = std::clamp<size_t>(i, 1, pts.size() - 1);
    const Point& a = pts[i - 1];
    const Point& b = pts[i];
    const double f = (c - cum[i - 1]) / (cum[i] - cum[i - 1]);
    return Point{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)};
  };
  // Resampled every ~kOpenSpacing m; the ends extended straight along the direction of their
  // last few metres.
  const int inner = std::max(1, static_cast<int>(std::ceil(total / kOpenSpacing)));
  const double ext = std::max(kOpenExtension, 3 * options.control_spacing);
  const int ext_n = static_cast<int>(std::ceil(ext / kOpenSpacing));
  auto direction = [&](double c0, double c1) {
    const Point a = at(c0), b = at(c1);
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    return Point{(b.x - a.x) / len, (b.y - a.y) / len};
  };
  const double probe = std::min(kOpenEndProbe, total);
  const Point d0 = direction(0.0, probe), d1 = direction(total - probe, total);
  Track track;
  track.source = src;
  auto add = [&](double x, double y) {
    Waypoint w;
    w.x = x;
    w.y = y;
    if (!track.waypoints.empty()) {
      const Waypoint& prev = track.waypoints.back();
      w.s = prev.s + std::hypot(x - prev.x, y - prev.y);
    }
    track.waypoints.push_back(w);
  };
  for (int i = ext_n; i >= 1; --i) {
    const double c = -i * ext / ext_n;
    add(pts.front().x + c * d0.x, pts.front().y + c * d0.y);
  }
  OpenRange range;
  range.first = static_cast<int>(track.waypoints.size());
  for (int i = 0; i <= inner; ++i) {
    const Point p = at(total * i / inner);
    add(p.x, p.y);
  }
  range.last = static_cast<int>(track.waypoints.size()) - 1;
  for (int i = 1; i <= ext_n; ++i) {
    const double c = i * ext / ext_n;
    add(pts.back().x + c * d1.x, pts.back().y + c * d1.y);
  }
  for (size_t i = 0; i < track.waypoints.size(); ++i) {  // right normals, for completeness
    const Waypoint& a = track.waypoints[i == 0 ? 0 : i - 1];
    const Waypoint& b = track.waypoints[i == 0 ? 1 : i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    track.waypoints[i].dx = (b.y - a.y) / len;
    track.waypoints[i].dy = -(b.x - a.x) / len;
  }
  track.max_s = track.waypoints.back().s;
  return FitLine(track, options, &range);
}

}  // namespace frenetic::map

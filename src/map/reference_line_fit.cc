// The reference line's fit (see reference_line.cc for the line itself): a periodic uniform
// quintic B-spline fitted to the waypoints with Ceres, then sampled by its own arc length
// into the tables the queries interpolate.
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


}  // namespace frenetic::map

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

#include <algorithm>
#include <cmath>
#include <limits>

#include "frenetic/check.h"
#include "frenetic/map/chord_frenet.h"
#include "map/reference_line_impl.h"

namespace frenetic::map {

using detail::kChordD1;
using detail::WrapAngle;

int ReferenceLine::Impl::NearestGlobal(double px, double py) const {
  // Coarse scan every kStride samples, then refine around every coarse sample that can still hold
  // the nearest one: a sample j is within kStride/2 samples (arc) of a coarse one, so its coarse
  // neighbour is at most kStride/2 * step farther than j itself.
  constexpr int kStride = 8;
  // The coarse samples: every kStride-th, and an open line's last one.
  const int count = SampleCount();
  const int last_coarse = closed ? -1 : n;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count; i += kStride) best = std::min(best, Dist2(i, px, py));
  if (last_coarse >= 0) best = std::min(best, Dist2(last_coarse, px, py));
  const double margin = (kStride / 2 + 1) * step;
  const double limit = std::sqrt(best) + margin;
  const double limit2 = limit * limit;
  int best_i = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  auto refine = [&](int i) {
    if (Dist2(i, px, py) > limit2) return;
    for (int o = -kStride / 2 - 1; o <= kStride / 2 + 1; ++o) {
      const int j = Wrap(i + o);
      const double d2 = Dist2(j, px, py);
      if (d2 < best_d2 || (d2 == best_d2 && j < best_i)) {
        best_d2 = d2;
        best_i = j;
      }
    }
  };
  for (int i = 0; i < count; i += kStride) refine(i);
  if (last_coarse >= 0) refine(last_coarse);
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
  // An open line continues straight beyond its ends.
  if (!closed && (nearest == 0 || nearest == n)) {
    const int e = nearest;
    const double along = (px - x[e]) * tx[e] + (py - y[e]) * ty[e];
    if ((e == 0 && along <= 0) || (e == n && along >= 0)) {
      FrenetPoint out;
      out.s = (e == 0 ? 0.0 : length) + along;
      out.d = (px - x[e]) * ty[e] - (py - y[e]) * tx[e];
      return out;
    }
  }
  const double sigma_lo = closed ? -std::numeric_limits<double>::infinity() : 0.0;
  const double sigma_hi = closed ? std::numeric_limits<double>::infinity() : n;
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
    if (!closed) {
      out.s = sigma * step;
      return out;
    }
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
      if (std::abs(sigma - nearest) > 1.0 || !(sigma >= sigma_lo && sigma <= sigma_hi)) break;
    }
  }
  double lo = std::max(nearest - 1.0, sigma_lo), hi = std::min(nearest + 1.0, sigma_hi);
  double flo = f_of(lo, nullptr), fhi = f_of(hi, nullptr);
  for (int ext = 0; ext < 8 && flo < 0 && lo > sigma_lo; ++ext) {
    hi = lo;
    fhi = flo;
    lo = std::max(lo - 1.0, sigma_lo);
    flo = f_of(lo, nullptr);
  }
  for (int ext = 0; ext < 8 && fhi > 0 && hi < sigma_hi; ++ext) {
    lo = hi;
    flo = fhi;
    hi = std::min(hi + 1.0, sigma_hi);
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

ReferenceLine::ReferenceLine(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {
  FRENETIC_CHECK(impl_ != nullptr);
}
ReferenceLine::~ReferenceLine() = default;

double ReferenceLine::length() const { return impl_->length; }

bool ReferenceLine::closed() const { return impl_->closed; }

double ReferenceLine::WrapS(double s) const {
  if (!impl_->closed) return std::isfinite(s) ? s : 0.0;
  const double len = impl_->length;
  if (s >= 0 && s < len) return s;  // the common case, without fmod
  if (!std::isfinite(s)) return 0;
  double r = std::fmod(s, len);
  if (r < 0) r += len;
  if (r >= len) r = 0;  // -tiny + len rounds to len
  return r;
}

double ReferenceLine::DiffS(double s_to, double s_from) const {
  if (!impl_->closed) return s_to - s_from;
  const double len = impl_->length;
  double d = WrapS(s_to - s_from);  // [0, L)
  if (d >= 0.5 * len) d -= len;
  return d;
}

CartesianPose ReferenceLine::ToCartesian(double s, double d) const {
  const Impl& m = *impl_;
  if (const int e = m.EndBeyond(s); e >= 0) {  // an open line's straight continuation
    const CentrePoint cp = Centre(s);
    CartesianPose p;
    p.x = cp.OffsetX(d);
    p.y = cp.OffsetY(d);
    p.heading = WrapAngle(m.th[e]);
    p.kappa = 0;
    return p;
  }
  const double sigma = WrapS(s) * m.inv_step;
  int i = static_cast<int>(sigma);
  if (i >= m.n) i = m.n - 1;
  const double t = sigma - i;
  const Hermite h = HermiteAt(t);
  const double st = m.step;
  double th;
  const CentrePoint cp = m.CentreAt(i, h, &th);
  const double k =
      h.h00 * m.k[i] + h.h10 * st * m.dk[i] + h.h01 * m.k[i + 1] + h.h11 * st * m.dk[i + 1];
  if (!std::isfinite(d)) d = 0;
  CartesianPose p;
  p.x = cp.OffsetX(d);  // right normal (sin, -cos)
  p.y = cp.OffsetY(d);
  p.heading = WrapAngle(th);
  // Offset curve C + d n with n the right normal: dn/ds = kappa t, so its speed is 1 + kappa d and
  // its curvature kappa / (1 + kappa d). Beyond the centre of curvature the offset curve has a
  // cusp; keep the value finite there.
  double denom = 1.0 + k * d;
  if (std::abs(denom) < 1e-6) denom = std::copysign(1e-6, denom);
  p.kappa = k / denom;
  return p;
}

CentrePoint ReferenceLine::Centre(double s) const {
  const Impl& m = *impl_;
  if (const int e = m.EndBeyond(s); e >= 0) {
    const double ds = e == 0 ? s : s - m.length;
    return {m.x[e] + ds * m.tx[e], m.y[e] + ds * m.ty[e], m.tx[e], m.ty[e]};
  }
  const double sigma = WrapS(s) * m.inv_step;
  int i = static_cast<int>(sigma);
  if (i >= m.n) i = m.n - 1;
  double th;
  return m.CentreAt(i, HermiteAt(sigma - i), &th);
}

FrenetPoint ReferenceLine::ToFrenet(double x, double y) const {
  if (!std::isfinite(x) || !std::isfinite(y)) return FrenetPoint{0, 0};
  return impl_->Project(x, y, impl_->NearestGlobal(x, y));
}

int ReferenceLine::HintSample(double s_hint) const {
  if (!std::isfinite(s_hint)) return -1;
  const Impl& m = *impl_;
  const double sigma_hint = std::clamp(WrapS(s_hint) * m.inv_step, 0.0, static_cast<double>(m.n));
  int start = static_cast<int>(sigma_hint);
  if (start >= m.n && m.closed) start = m.n - 1;
  return start;
}

FrenetPoint ReferenceLine::ToFrenet(double x, double y, double s_hint) const {
  if (!std::isfinite(x) || !std::isfinite(y)) return FrenetPoint{0, 0};
  const int start = HintSample(s_hint);
  if (start < 0) return ToFrenet(x, y);
  const Impl& m = *impl_;
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
  // first is in [0, n] and count <= n: one wrap at most (no division per sample).
  for (int j = 0, i = first % m.n; j < count; ++j, i = i + 1 == m.n ? 0 : i + 1) {
    const double off = m.chord0[i] + (m.chord1[i] - m.chord0[i]) * w;
    r.lo = std::min(r.lo, off);
    r.hi = std::max(r.hi, off);
  }
  return r;
}

RefSample ReferenceLine::At(double s) const {
  const Impl& m = *impl_;
  if (const int e = m.EndBeyond(s); e >= 0) {
    const CentrePoint cp = Centre(s);
    RefSample r;
    r.s = s;
    r.x = cp.x;
    r.y = cp.y;
    r.heading = WrapAngle(m.th[e]);
    return r;
  }
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

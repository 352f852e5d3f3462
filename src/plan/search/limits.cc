#include "plan/search/limits.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace frenetic::plan::search {
namespace {

constexpr double kRoundingSlack = 1e-9;  // m/s of s' below 0 that is the polynomials' rounding

}  // namespace

LimitChecker::LimitChecker(const Settings& cfg, const map::ReferenceLine& line, Workspace& ws)
    : cfg_(cfg),
      line_(line),
      ws_(ws),
      xy_(kHistory + 64 + static_cast<int>(std::ceil(cfg.check.horizon / kTickSeconds)) +
              cfg.continuity.output_points,
          cfg.vehicle) {
  const int path_cap = kHistory + cfg.continuity.output_points + ws_.n_ticks + 8;
  chk_x_.assign(path_cap, 0.0);
  chk_y_.assign(path_cap, 0.0);
  const std::size_t n_lon = ws_.lon.capacity(), n_lat = ws_.lat.capacity();
  verdicts_.resize(ws_.order.capacity());
  lon_ticks_.Resize(n_lon, ws_.n_ticks + 1);
  lat_ticks_.Resize(n_lat, ws_.n_ticks + 1);
  lon_centre_.resize(n_lon * (ws_.n_ticks + 1));
  lon_centre_have_.assign(n_lon, 0);
}

void LimitChecker::SetXyPrefix(const double* hist_x, const double* hist_y, int hist_n,
                               const double* kept_x, const double* kept_y, int kept) {
  int n = 0;
  for (int i = 0; i < hist_n; ++i, ++n) {
    chk_x_[n] = hist_x[i];
    chk_y_[n] = hist_y[i];
  }
  for (int i = 0; i < kept; ++i, ++n) {
    chk_x_[n] = kept_x[i];
    chk_y_[n] = kept_y[i];
  }
  first_new_ = n;
  xy_.SetPrefix(chk_x_.data(), chk_y_.data(), n);
  ++prefix_stamp_;
}

LimitChecker::ReadRange LimitChecker::ReadBetween(const double* s, const double* d, int prev,
                                                  int i) const {
  const double d_lo = std::min(d[prev], d[i]), d_hi = std::max(d[prev], d[i]);
  const map::ReferenceLine::OffsetRange r =
      line_.ChordOffset(std::min(s[prev], s[i]), std::max(s[prev], s[i]), 0.5 * (d_lo + d_hi));
  return {d_lo + r.lo, d_hi + r.hi};
}

double LimitChecker::EdgeExcess(double s0, double s1, const ReadRange& read) const {
  // The bins of the workspace's edge table that [s0, s1] overlaps (clamped to the table).
  const int bins = static_cast<int>(ws_.edge_lo.size());
  const double x0 = (std::min(s0, s1) - ws_.edge_s0) / Workspace::kEdgeBin;
  const double x1 = (std::max(s0, s1) - ws_.edge_s0) / Workspace::kEdgeBin;
  if (!(x0 == x0) || !(x1 == x1)) return 1e9;  // NaN s: off any road
  const int b0 = static_cast<int>(std::clamp(std::floor(x0), 0.0, bins - 1.0));
  const int b1 = static_cast<int>(std::clamp(std::floor(x1), 0.0, bins - 1.0));
  double lo = -1e9, hi = 1e9;
  for (int b = b0; b <= b1; ++b) {
    if (!(ws_.edge_lo[b] == ws_.edge_lo[b])) return 1e9;  // no lane there
    lo = std::max(lo, ws_.edge_lo[b]);
    hi = std::min(hi, ws_.edge_hi[b]);
  }
  const double inset = 0.5 * cfg_.check.ego_width + cfg_.limits.edge_margin;
  return std::max(lo + inset - read.lo, read.hi - (hi - inset));
}

double LimitChecker::CandidateViolation(int c, Reject* reason) {
  return CandidateMeasure(c, reason, false);
}

bool LimitChecker::CandidateBreaksLimits(int c, Reject* first) {
  return CandidateMeasure(c, first, true) > 0;
}

double LimitChecker::CandidateMeasure(int c, Reject* reason, bool any) {
  const traj::FrenetTrajectory tr = ws_.Candidate(c);
  Verdict* v = c < static_cast<int>(verdicts_.size()) ? &verdicts_[c] : nullptr;
  if (v != nullptr && (any || !v->any) && v->prefix_stamp == prefix_stamp_ &&
      v->straddle == ws_.straddle_at_start && v->straddle_limit == straddle_limit_ &&
      std::memcmp(&v->tr, &tr, sizeof(tr)) == 0) {
    if (reason != nullptr) *reason = v->why;
    return v->worst;
  }
  Reject why = Reject::kCount;
  const double worst = Measure(&why, true, CandidateTicks(c, tr, ws_.CheckTicks(c)), any);
  // An early answer (worst > 0 before every limit was measured) is not the whole verdict.
  const bool partial = any && worst > 0;
  if (reason != nullptr) *reason = why;
  if (v != nullptr) {
    *v = {tr, prefix_stamp_, ws_.straddle_at_start, straddle_limit_, why, worst, partial};
  }
  return worst;
}

bool LimitChecker::CandidateBreaksLimitsBesidesTheLaneLine(int c) {
  return Measure(nullptr, false, CandidateTicks(c, ws_.Candidate(c), 0), true) > 0;
}

LimitChecker::Ticks LimitChecker::CandidateTicks(int c, const traj::FrenetTrajectory& tr, int n) {
  // FillTicks' values, from the bundles' rows: the candidates of a bundle share its ticks and
  // the centre line there.
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const auto time = [](int t) { return 0.0 + t * kTickSeconds; };  // FillTicks' time
  if (lon_ticks_.Sample(tr.lon, i, time)) lon_centre_have_[i] = 0;
  lat_ticks_.Sample(tr.lat, k, time);
  const int w = ws_.n_ticks + 1;
  return {&lon_ticks_.p[i * w], &lon_ticks_.v[i * w], &lat_ticks_.p[k * w], nullptr, i, n};
}

double LimitChecker::CurveExcess(const Ticks& ticks, int n_ticks) const {
  // The XY check's lateral acceleration at tick j is vm^2 km: the mean XY speed of the ticks
  // j - 9..j and the mean Menger curvature of the triples centred within them (feasibility.h).
  // Both are at least their block's smallest value. At a tick at offset d, e = d toward the
  // bend's outside (d grows to the right, kappa is left positive), on a line of curvature
  // kappa: the XY speed is at least s' (1 + kappa e) and the XY curvature kappa / (1 + kappa e),
  // which grows with kappa; kappa anywhere in its bin's [lo, hi] of one sign. A lateral move
  // adds its own acceleration across, d'', and the turning frame's 2 kappa s' d': both are
  // taken off. A bin across a sign change, or a tick off the table, says nothing (0).
  constexpr int kBlock = 10;
  const double limit = (1 + kCurveSlack) * cfg_.limits.max_accel;
  const int bins = static_cast<int>(ws_.kappa_lo.size());
  const double* s = ticks.s;
  const double* sd = ticks.sd;
  const double* d = ticks.d;
  constexpr double kInvDt = 1.0 / kTickSeconds;
  // Nothing to find where the bound below, with the table's largest curvature, the fastest
  // tick and the farthest across, is within the limit (a straight road's every candidate).
  double v_max = 0, d_max = 0;
  for (int i = 1; i <= n_ticks; ++i) {
    v_max = std::max(v_max, sd[i]);
    d_max = std::max(d_max, std::abs(d[i]));
  }
  const double kd = ws_.kappa_abs_max * d_max;
  if (kd < 1 && v_max * v_max * (1 + kd) * (1 + kd) * ws_.kappa_abs_max / (1 - kd) <= limit) {
    return -1.0;
  }
  double best = 0;
  for (int j0 = 1; j0 + kBlock - 1 <= n_ticks; j0 += kBlock) {
    double v_lo = 1e9, k_lo = 1e9, across = 0;
    for (int i = j0; i < j0 + kBlock; ++i) {
      const double x = (s[i] - ws_.kappa_s0) / Workspace::kEdgeBin;
      if (!(x >= 0 && x < bins)) return best / limit - 1.0;  // NaN too: no further
      const int b = static_cast<int>(x);
      const double lo = ws_.kappa_lo[b], hi = ws_.kappa_hi[b];
      if (!(lo * hi > 0)) {
        k_lo = 0;
        break;
      }
      const double sign = hi > 0 ? 1.0 : -1.0;
      const double small = std::min(std::abs(lo), std::abs(hi));
      const double big = std::max(std::abs(lo), std::abs(hi));
      const double e = sign * d[i];
      const double grow_small = 1 + small * e, grow_big = 1 + big * e;
      if (!(grow_small > 0 && grow_big > 0)) {
        k_lo = 0;
        break;
      }
      v_lo = std::min(v_lo, std::max(0.0, sd[i]) * std::min(grow_small, grow_big));
      k_lo = std::min(k_lo, small / grow_small);
      // d' and d'' by central differences (the last tick: d' backward, d'' unknown, 0).
      const int next = std::min(i + 1, n_ticks);
      const double d1 = (d[next] - d[i - 1]) * kInvDt / (next - i + 1);
      const double d2 = next > i ? (d[next] - 2 * d[i] + d[i - 1]) * kInvDt * kInvDt : 0;
      across = std::max(across, std::abs(d2) + 2 * big * std::abs(sd[i] * d1));
    }
    if (!(k_lo > 0)) continue;
    best = std::max(best, v_lo * v_lo * k_lo - across);
  }
  return best / limit - 1.0;
}

int LimitChecker::BuildXyPath(const Ticks& ticks) {
  int n = first_new_;
  const int n_ticks = ticks.n > 0 ? ticks.n : ws_.n_ticks;
  for (int i = 1; i <= n_ticks; ++i, ++n) {
    // ToCartesian's x and y without its heading and curvature.
    const map::CentrePoint p = ticks.centre != nullptr ? ticks.centre[i] : line_.Centre(ticks.s[i]);
    chk_x_[n] = p.OffsetX(ticks.d[i]);
    chk_y_[n] = p.OffsetY(ticks.d[i]);
  }
  return n;
}

double LimitChecker::Violation(Reject* reason, bool lane_line) {
  return Measure(reason, lane_line, {ws_.tk_s.data(), ws_.tk_sd.data(), ws_.tk_d.data(), nullptr});
}

double LimitChecker::Measure(Reject* reason, bool lane_line, const Ticks& ticks, bool any) {
  const int n_ticks = ticks.n > 0 ? ticks.n : ws_.n_ticks;
  const double* tk_s = ticks.s;
  const double* tk_d = ticks.d;
  double worst = -1e9;
  Reject why = Reject::kCount;
  auto take = [&](double v, Reject r) {
    if (!(v <= worst)) {  // NaN counts as a violation
      worst = Finite(v) ? v : 1e9;
      why = r;
    }
  };
  // d as the simulator reads it (from chords), bounded every 5 ticks over the s swept since
  // the previous check point.
  // The lane-line timer runs on, from the start state's count, while the read d may be astride
  // a line; a trajectory still astride at its end would stay there.
  // On a uniform road, the range of d read against d_min / d_max; on another, the largest
  // excess over the road's edges (EdgeExcess).
  double dmin = 1e9, dmax = -1e9, sdmin = 1e9, off_road = -1e9;
  int straddle = ws_.straddle_at_start, worst_straddle = straddle;
  for (int i = 1; i <= n_ticks; ++i) sdmin = std::min(sdmin, ticks.sd[i]);
  for (int prev = 1, i = std::min(5, n_ticks); n_ticks >= 1;
       prev = i, i = std::min(i + 5, n_ticks)) {
    const ReadRange read = ReadBetween(tk_s, tk_d, prev, i);
    if (cfg_.road.uniform) {
      dmin = std::min(dmin, read.lo);
      dmax = std::max(dmax, read.hi);
      straddle = StraddlesRead(cfg_, read.lo, read.hi) ? straddle + (i - prev) + (prev == 1) : 0;
      worst_straddle = std::max(worst_straddle, straddle);
    } else {
      off_road = std::max(off_road, EdgeExcess(tk_s[prev], tk_s[i], read));
    }
    if (any) {
      const bool astride = lane_line && worst_straddle > straddle_limit_;
      if (astride || cfg_.limits.d_min - dmin > 0 || dmax - cfg_.limits.d_max > 0 ||
          off_road > 0) {
        // The first one found (which one is worst is not known).
        if (reason != nullptr) *reason = astride ? Reject::kLaneLine : Reject::kOffRoad;
        return 1.0;
      }
    }
    if (i == n_ticks) break;
  }
  if (straddle > 0) worst_straddle = 1 << 20;
  if (cfg_.road.uniform) off_road = std::max(cfg_.limits.d_min - dmin, dmax - cfg_.limits.d_max);
  take(off_road / cfg_.road.lane_width, Reject::kOffRoad);
  if (lane_line) {
    take(static_cast<double>(worst_straddle - straddle_limit_) / straddle_limit_,
         Reject::kLaneLine);
  }
  // Never backwards beyond limits.backward_speed: the Udacity simulator reads a step back after
  // one forward as a reversal, a curvature of 1e6 in its acceleration (udacity-sim.md 7.2), and
  // at a crawl that alone is over the limit (0.05 m/s let a path creep back 1 mm a tick at a
  // stop: dense seed 1749).
  take(-sdmin - std::max(cfg_.limits.backward_speed, kRoundingSlack), Reject::kSpeed);
  if (cfg_.check.curve_prefilter && ticks.lon_slot >= 0 && !(worst > 0)) {
    // A candidate's verdict only (its bundle rows): the refinement's Violation weighs how far
    // its trial paths break a limit, which only the XY check measures.
    if (const double over = CurveExcess(ticks, n_ticks); over > 0) {
      take(over, Reject::kAcceleration);
    }
  }
  if (worst > 0) {                      // already infeasible: skip the XY conversion
    if (reason != nullptr) *reason = why;
    return worst;
  }
  Ticks xy_ticks = ticks;
  if (ticks.lon_slot >= 0) {
    const int i = ticks.lon_slot, w = ws_.n_ticks + 1;  // the whole row, for every candidate
    if (!lon_centre_have_[i]) {
      for (int t = 1; t <= ws_.n_ticks; ++t) lon_centre_[i * w + t] = line_.Centre(ticks.s[t]);
      lon_centre_have_[i] = 1;
    }
    xy_ticks.centre = &lon_centre_[i * w];
  }
  const int n = BuildXyPath(xy_ticks);
  // Asked only whether a limit is broken: no jerk or vehicle measure once the speed or the
  // acceleration is over (the same test as below).
  const XyLimits over{cfg_.limits.max_speed, cfg_.limits.max_accel, cfg_.limits.max_jerk};
  const XyMeasure m =
      xy_.MeasureWithPrefix(chk_x_.data(), chk_y_.data(), n, first_new_, any ? &over : nullptr);
  take(m.max_speed / cfg_.limits.max_speed - 1.0, Reject::kSpeed);
  take(m.max_accel / cfg_.limits.max_accel - 1.0, Reject::kAcceleration);
  take(m.max_jerk / cfg_.limits.max_jerk - 1.0, Reject::kJerk);
  if (cfg_.vehicle.any()) {
    // A vehicle's limits count as acceleration (steering angle: lateral; forward) and jerk
    // (the steering rate) limits.
    if (cfg_.vehicle.max_steer > 0) take(m.steer_ratio - 1.0, Reject::kAcceleration);
    if (cfg_.vehicle.max_accel > 0) take(m.forward_accel_ratio - 1.0, Reject::kAcceleration);
    if (cfg_.vehicle.max_steer_rate > 0) take(m.steer_rate_ratio - 1.0, Reject::kJerk);
  }
  if (reason != nullptr) *reason = worst > 0 ? why : Reject::kCount;
  return worst;
}

}  // namespace frenetic::plan::search

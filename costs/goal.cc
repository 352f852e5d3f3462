// goal: how far the candidate misses the nearest goal region (CostContext::goals, a CommonRoad
// planning problem's goal states) within its time window: over the window, the least of
//   out(s, [s_lo, s_hi]) / s_scale + out(d - d_slope (s - s_ref), [d_lo, d_hi]) / d_scale
//   + out(v, [v_lo, v_hi]) / v_scale + out(h, [h_lo, h_hi]) / h_scale
// with out(x, [lo, hi]) the distance of x outside the interval and h = d' / s' the tangent of
// the heading against the line's (GoalRegion's bounds are tangents too), the candidate continued
// past its samples at its last speed along its last d, or, with `lateral_pace` > 0 and a road
// whose lanes all run alongside to past the region (GoalRegion::across_open), moving across
// toward it at that pace (m/s) until its d is inside: a candidate ending short of a region in
// the next lane can still change lanes before it, one that has passed beside the region cannot,
// and one slower has longer to. 0 when it passes through a region in its window (and with no
// goal: the Udacity track), else
// `miss` plus that least sum (a goal is reached or not: missing it by a little is still missing
// it), at most `cap`. Between samples each quantity is taken linear in time, so each term is convex and
// piecewise linear and their sum is least at a window end, a sample or where a term crosses an
// interval's end: the minimum over those is exact (for h, of its linear interpolation).
// About 25 samples and a few crossings per candidate and goal: Expensive() (the scorer evaluates
// it for a candidate only when the other terms' bound leaves it a chance), as it is the dearest
// of the terms that read every sample on a problem with a goal far ahead.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "frenetic/cost/cost_registry.h"
#include "frenetic/cost/cost_term.h"

namespace frenetic::cost {
namespace {

double Out(double x, double lo, double hi) { return std::max({lo - x, 0.0, x - hi}); }

constexpr double kRounding = 1e-6;  // m

class GoalCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"s_scale", 10.0, 1.0, 100.0, true},
            {"d_scale", 1.75, 0.2, 10.0, true},
            {"v_scale", 5.0, 0.5, 30.0, true},
            {"h_scale", 0.05, 0.005, 1.0, true},
            {"miss", 1.0, 0.0, 10.0, false},
            {"cap", 10.0, 1.0, 100.0, true},
            {"approach", 1.0, 0.0, 10.0, false},
            {"approach_width", 1.0, 0.0, 3.0, false},
            {"lateral_pace", 0.0, 0.0, 5.0, false}};
  }
  void Configure(std::span<const double> v) override {
    s_scale_ = v[0];
    d_scale_ = v[1];
    v_scale_ = v[2];
    h_scale_ = v[3];
    miss_ = v[4];
    cap_ = v[5];
    approach_ = v[6];
    approach_width_ = v[7];
    lateral_pace_ = v[8];
    inv_s_ = 1 / s_scale_;
    inv_d_ = 1 / d_scale_;
    inv_v_ = 1 / v_scale_;
    inv_h_ = 1 / h_scale_;
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (ctx.num_goals <= 0 || ctx.goals == nullptr || n < 1) return 0.0;
    double best = std::numeric_limits<double>::infinity();
    bool any_open = false;
    for (int g = 0; g < std::min(ctx.num_goals, kMaxGoalRegions); ++g) {
      const GoalRegion& goal = ctx.goals[g];
      if (!(goal.t_hi >= 0)) continue;  // its window has passed
      any_open = true;
      best = std::min(best, Miss(ctx, in, goal));
      // A region crossed turned (its headings leave out the road's) is entered by a swerve from
      // beside it (the planner's lattice offers them, Lattice::AddSwerves): passing along the
      // side it is entered from, within approach_width lanes of it, at any heading, misses it
      // by `approach` plus the rest.
      const int turned = CrossedTurned(goal);
      const bool right = turned > 0;
      if (turned != 0 && approach_width_ > 0 && best > approach_) {
        GoalRegion side = goal;
        const double width = approach_width_ * ctx.lane_width;
        side.d_lo = right ? goal.d_lo - width : goal.d_hi;
        side.d_hi = right ? goal.d_lo : goal.d_hi + width;
        side.h_lo = -GoalRegion::kInf;
        side.h_hi = GoalRegion::kInf;
        best = std::min(best, approach_ + Miss(ctx, in, side));
      }
    }
    if (!any_open || !std::isfinite(best)) return 0.0;
    return best > 0 ? std::clamp(miss_ + best, 0.0, cap_) : 0.0;
  }

  // Evaluate's value with each region's miss bounded by its s part alone, over the span of s
  // the candidate covers (every sample, and the continuation to the window's close): one pass
  // over the samples, no crossings. Where every region lies far past the candidate's reach (a
  // goal kilometres on, a window it cannot make at its end speed) it is the value itself, so
  // the planner's candidates rank by their other terms without evaluating this one for each.
  double LowerBound(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (ctx.num_goals <= 0 || ctx.goals == nullptr || n < 1) return 0.0;
    // First the span of the start, the end and the continuation's close alone (within the
    // samples' span, so a region it meets bounds nothing: 0 at once, the usual case of a goal
    // near), then, if none meets it, every sample's.
    double best = Bound(ctx, in, std::min(in.s[0], in.s[n - 1]), std::max(in.s[0], in.s[n - 1]));
    if (!(best > 0)) return 0.0;
    double s_min = in.s[0], s_max = in.s[0];
    for (int k = 1; k < n; ++k) {
      s_min = std::min(s_min, in.s[k]);
      s_max = std::max(s_max, in.s[k]);
    }
    best = Bound(ctx, in, s_min, s_max);
    return best > 0 && std::isfinite(best) ? std::clamp(miss_ + best, 0.0, cap_) : 0.0;
  }

  bool Sampled() const override { return true; }
  bool Expensive() const override { return true; }

 private:
  // The candidate at time t (s after the start): sampled, then straight on. h is its heading's
  // tangent against the line's, d' / s' (s' floored at 0.1 m/s): monotone in the heading, and
  // the heading itself for small angles, without an atan2 per sample.
  struct At {
    double s, d, v, h;
  };
  // d against the region's slanted sides.
  static double Across(const GoalRegion& g, const At& a) { return a.d - g.d_slope * (a.s - g.s_ref); }
  static double Slope(double s_d, double d_d) { return d_d / std::max(s_d, 0.1); }
  At Sample(const CostInput& in, int k) const {
    return {in.s[k], in.d[k], in.s_d[k], Slope(in.s_d[k], in.d_d[k])};
  }
  // The move across the continuation makes toward region g's sides (those at the last sample),
  // m, signed as d: 0 when it is inside them, or keeps its d.
  double Move(const CostContext& ctx, const CostInput& in, const GoalRegion& g) const {
    if (!(lateral_pace_ > 0 && g.across_open)) return 0.0;
    const double across = Across(g, Sample(in, ctx.num_samples - 1));
    if (across < g.d_lo) return g.d_lo - across;
    if (across > g.d_hi) return g.d_hi - across;
    return 0.0;
  }
  // Past the samples: straight on at the last speed, d moved by `move` (Move) at lateral_pace.
  At State(const CostContext& ctx, const CostInput& in, double move, double t) const {
    const int n = ctx.num_samples;
    const double x = t / ctx.dt;
    if (x >= n - 1) {
      const double v = in.s_d[n - 1];
      const double after = t - (n - 1) * ctx.dt;
      At a{in.s[n - 1] + v * after, in.d[n - 1], v, 0.0};
      if (move != 0) a.d += std::copysign(std::min(lateral_pace_ * after, std::abs(move)), move);
      return a;
    }
    const int k = std::max(0, static_cast<int>(x));
    const double f = x - k;
    return Lerp(Sample(in, k), Sample(in, k + 1), f);
  }
  static At Lerp(const At& a, const At& b, double f) {
    return {a.s + f * (b.s - a.s), a.d + f * (b.d - a.d), a.v + f * (b.v - a.v),
            a.h + f * (b.h - a.h)};
  }
  double MissAt(const GoalRegion& g, const At& a) const {
    // Out() of an absent part (infinite bounds) is 0.
    return Out(a.s, g.s_lo, g.s_hi) * inv_s_ + Out(Across(g, a), g.d_lo, g.d_hi) * inv_d_ +
           Out(a.v, g.v_lo, g.v_hi) * inv_v_ + Out(a.h, g.h_lo, g.h_hi) * inv_h_;
  }
  // LowerBound's least miss over the open regions with the samples' s within [s_min, s_max]:
  // each region's s part alone, over that span and the continuation to its window's close (0
  // when a region has no s interval; infinite when no window is left, as Miss).
  double Bound(const CostContext& ctx, const CostInput& in, double s_min, double s_max) const {
    const int n = ctx.num_samples;
    const double t_end = (n - 1) * ctx.dt, s_end = in.s[n - 1], v_end = in.s_d[n - 1];
    double best = std::numeric_limits<double>::infinity();
    for (int g = 0; g < std::min(ctx.num_goals, kMaxGoalRegions); ++g) {
      const GoalRegion& goal = ctx.goals[g];
      if (!(goal.t_hi >= 0)) continue;  // its window has passed
      // Miss's window; none left: Miss is infinite.
      const double t0 = std::max(goal.t_lo, 0.0);
      const double t1 = std::isfinite(goal.t_hi) ? goal.t_hi : t_end + 60.0;
      if (!(t1 >= t0)) continue;
      // An empty s interval (s_lo > s_hi) or none: no bound from s.
      if (!(goal.s_lo <= goal.s_hi)) return 0.0;
      double lo = s_min, hi = s_max;
      if (t1 > t_end) {  // the continuation, straight on at the last speed until t1
        const double s_far = s_end + v_end * (t1 - t_end);
        lo = std::min(lo, s_far);
        hi = std::max(hi, s_far);
      }
      // The distance outside the interval, less a micrometre for the rounding of Miss's
      // interpolated states (a bound never above the value). The side region of a region
      // crossed turned has the same s interval and costs `approach` more: no lower.
      double miss = 0.0;
      if (hi < goal.s_lo) miss = std::max(goal.s_lo - hi - kRounding, 0.0) * inv_s_;
      if (lo > goal.s_hi) miss = std::max(lo - goal.s_hi - kRounding, 0.0) * inv_s_;
      best = std::min(best, miss);
      if (!(best > 0)) return 0.0;
    }
    return best;
  }
  // The least miss over the window, at its ends, the samples inside it and the crossings.
  double Miss(const CostContext& ctx, const CostInput& in, const GoalRegion& g) const {
    const int n = ctx.num_samples;
    const double dt = ctx.dt, t_end = (n - 1) * dt;
    const double t0 = std::max(g.t_lo, 0.0);
    // An endless window is judged up to a minute past the samples.
    const double t1 = std::isfinite(g.t_hi) ? g.t_hi : t_end + 60.0;
    if (!(t1 >= t0)) return std::numeric_limits<double>::infinity();  // no window left
    const double move = Move(ctx, in, g);
    double best =
        std::min(MissAt(g, State(ctx, in, move, t0)), MissAt(g, State(ctx, in, move, t1)));
    // The levels that bound something (an absent part's are infinite), and where a linear
    // piece from time ta (state a) to tb (b) crosses them: the state there, interpolated.
    const bool has_s = std::isfinite(g.s_lo) || std::isfinite(g.s_hi);
    const bool has_d = std::isfinite(g.d_lo) || std::isfinite(g.d_hi);
    const bool has_v = std::isfinite(g.v_lo) || std::isfinite(g.v_hi);
    const bool has_h = std::isfinite(g.h_lo) || std::isfinite(g.h_hi);
    auto cross = [&](double ta, double tb, const At& a, const At& b, double qa, double qb,
                     double level) {
      if (!((qa - level) * (qb - level) <= 0) || qa == qb) return;  // no crossing (or NaN)
      const double f = (level - qa) / (qb - qa);
      const double t = ta + f * (tb - ta);
      if (!(t >= t0 && t <= t1)) return;
      best = std::min(best, MissAt(g, Lerp(a, b, f)));
    };
    // A term's least value over a piece is 0 where its quantity passes its interval, else the
    // smaller end's: their sum bounds the piece's least miss from below, and a piece whose
    // bound is no better than the best so far needs no crossings.
    auto least = [](double qa, double qb, double lo, double hi, double inv) {
      if (std::max(qa, qb) >= lo && std::min(qa, qb) <= hi) return 0.0;
      return std::min(Out(qa, lo, hi), Out(qb, lo, hi)) * inv;
    };
    auto piece = [&](double ta, double tb, const At& a, const At& b) {
      const double da = Across(g, a), db = Across(g, b);
      const double bound = least(a.s, b.s, g.s_lo, g.s_hi, inv_s_) +
                           least(da, db, g.d_lo, g.d_hi, inv_d_) +
                           least(a.v, b.v, g.v_lo, g.v_hi, inv_v_) +
                           least(a.h, b.h, g.h_lo, g.h_hi, inv_h_);
      if (!(bound < best)) return;
      if (has_s) {
        cross(ta, tb, a, b, a.s, b.s, g.s_lo);
        cross(ta, tb, a, b, a.s, b.s, g.s_hi);
      }
      if (has_d) {
        cross(ta, tb, a, b, da, db, g.d_lo);
        cross(ta, tb, a, b, da, db, g.d_hi);
      }
      if (has_v) {
        cross(ta, tb, a, b, a.v, b.v, g.v_lo);
        cross(ta, tb, a, b, a.v, b.v, g.v_hi);
      }
      if (has_h) {
        cross(ta, tb, a, b, a.h, b.h, g.h_lo);
        cross(ta, tb, a, b, a.h, b.h, g.h_hi);
      }
    };
    const int k0 = std::max(0, static_cast<int>(std::floor(t0 / dt)));
    const int k1 = std::min(n - 1, static_cast<int>(std::ceil(t1 / dt)));
    // The samples' s span against the region's: a region far ahead (or behind) of all of them
    // bounds every piece's miss and every sample's from below, so when that bound is no better
    // than the best so far (the window's ends), the pieces can change nothing. (An empty s
    // interval, s_lo > s_hi, has no such bound: least() would overstate it.)
    bool pieces = k0 < k1 && best > 0;
    if (pieces && has_s && g.s_lo <= g.s_hi) {
      double s_min = in.s[k0], s_max = in.s[k0];
      for (int k = k0 + 1; k <= k1; ++k) {
        s_min = std::min(s_min, in.s[k]);
        s_max = std::max(s_max, in.s[k]);
      }
      pieces = !(least(s_min, s_max, g.s_lo, g.s_hi, inv_s_) >= best);
    }
    At a = pieces ? Sample(in, k0) : At{};
    for (int k = k0; pieces && k < k1 && best > 0; ++k) {  // nothing is below 0: done
      const At b = Sample(in, k + 1);
      if (k * dt >= t0) best = std::min(best, MissAt(g, a));
      piece(k * dt, (k + 1) * dt, a, b);
      a = b;
    }
    // The last sample, where the samples end and the continuation starts: the loop reads each
    // piece's first end only.
    if (t0 <= t_end && t1 > t_end && best > 0) best = std::min(best, MissAt(g, Sample(in, n - 1)));
    if (t1 > t_end && best > 0) {  // the continuation: straight on, or across and then straight
      const double ta = std::max(t_end, t0);
      // when its move across ends (none: at once)
      const double tc = move != 0 ? std::clamp(t_end + std::abs(move) / lateral_pace_, ta, t1) : ta;
      if (tc > ta) piece(ta, tc, State(ctx, in, move, ta), State(ctx, in, move, tc));
      if (t1 > tc) piece(tc, t1, State(ctx, in, move, tc), State(ctx, in, move, t1));
    }
    return best;
  }

  double s_scale_ = 10.0, d_scale_ = 1.75, v_scale_ = 5.0, h_scale_ = 0.05, miss_ = 1.0,
         cap_ = 10.0, approach_ = 1.0, approach_width_ = 1.0, lateral_pace_ = 0.0;
  double inv_s_ = 0.1, inv_d_ = 1 / 1.75, inv_v_ = 0.2, inv_h_ = 20;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(goal, frenetic::cost::GoalCost);

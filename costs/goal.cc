// goal: how far the candidate misses the nearest goal region (CostContext::goals, a CommonRoad
// planning problem's goal states) within its time window: over the window, the least of
//   out(s, [s_lo, s_hi]) / s_scale + out(d - d_slope (s - s_ref), [d_lo, d_hi]) / d_scale
//   + out(v, [v_lo, v_hi]) / v_scale + out(h, [h_lo, h_hi]) / h_scale
// with out(x, [lo, hi]) the distance of x outside the interval and h = atan2(d', s') the heading
// against the line's, the candidate continued past its samples at its last speed along its last
// d. 0 when it passes through a region in its window (and with no goal: the Udacity track), else
// `miss` plus that least sum (a goal is reached or not: missing it by a little is still missing
// it), at most `cap`. Between samples each quantity is taken linear in time, so each term is convex and
// piecewise linear and their sum is least at a window end, a sample or where a term crosses an
// interval's end: the minimum over those is exact (for h, of its linear interpolation).
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

class GoalCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"s_scale", 10.0, 1.0, 100.0, true},
            {"d_scale", 1.75, 0.2, 10.0, true},
            {"v_scale", 5.0, 0.5, 30.0, true},
            {"h_scale", 0.05, 0.005, 1.0, true},
            {"miss", 1.0, 0.0, 10.0, false},
            {"cap", 10.0, 1.0, 100.0, true}};
  }
  void Configure(std::span<const double> v) override {
    s_scale_ = v[0];
    d_scale_ = v[1];
    v_scale_ = v[2];
    h_scale_ = v[3];
    miss_ = v[4];
    cap_ = v[5];
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
    }
    if (!any_open || !std::isfinite(best)) return 0.0;
    return best > 0 ? std::clamp(miss_ + best, 0.0, cap_) : 0.0;
  }

 private:
  // The candidate at time t (s after the start): sampled, then straight on.
  struct At {
    double s, d, v, h;
  };
  // d against the region's slanted sides.
  static double Across(const GoalRegion& g, const At& a) { return a.d - g.d_slope * (a.s - g.s_ref); }
  static double Heading(double s_d, double d_d) { return std::atan2(d_d, std::max(s_d, 0.1)); }
  At State(const CostContext& ctx, const CostInput& in, double t) const {
    const int n = ctx.num_samples;
    const double x = t / ctx.dt;
    if (x >= n - 1) {
      const double v = in.s_d[n - 1];
      return {in.s[n - 1] + v * (t - (n - 1) * ctx.dt), in.d[n - 1], v, 0.0};
    }
    const int k = std::max(0, static_cast<int>(x));
    const double f = x - k;
    const double h0 = Heading(in.s_d[k], in.d_d[k]), h1 = Heading(in.s_d[k + 1], in.d_d[k + 1]);
    return {in.s[k] + f * (in.s[k + 1] - in.s[k]), in.d[k] + f * (in.d[k + 1] - in.d[k]),
            in.s_d[k] + f * (in.s_d[k + 1] - in.s_d[k]), h0 + f * (h1 - h0)};
  }
  double MissAt(const GoalRegion& g, const At& a) const {
    return Out(a.s, g.s_lo, g.s_hi) / s_scale_ + Out(Across(g, a), g.d_lo, g.d_hi) / d_scale_ +
           Out(a.v, g.v_lo, g.v_hi) / v_scale_ + Out(a.h, g.h_lo, g.h_hi) / h_scale_;
  }
  // The least miss over the window, at its ends, the samples inside it and the crossings.
  double Miss(const CostContext& ctx, const CostInput& in, const GoalRegion& g) const {
    const int n = ctx.num_samples;
    const double dt = ctx.dt, t_end = (n - 1) * dt;
    const double t0 = std::max(g.t_lo, 0.0);
    // An endless window is judged up to a minute past the samples.
    const double t1 = std::isfinite(g.t_hi) ? g.t_hi : t_end + 60.0;
    if (!(t1 >= t0)) return std::numeric_limits<double>::infinity();
    double best = std::min(MissAt(g, State(ctx, in, t0)), MissAt(g, State(ctx, in, t1)));
    // Where a linear piece from time ta (values a) to tb (b) crosses x = level.
    auto cross = [&](double ta, double tb, double a, double b, double level) {
      if (!std::isfinite(level) || (a - level) * (b - level) > 0 || a == b) return;
      const double t = ta + (level - a) / (b - a) * (tb - ta);
      if (t >= t0 && t <= t1) best = std::min(best, MissAt(g, State(ctx, in, t)));
    };
    auto piece = [&](double ta, double tb) {
      const At a = State(ctx, in, ta), b = State(ctx, in, tb);
      for (const double level : {g.s_lo, g.s_hi}) cross(ta, tb, a.s, b.s, level);
      for (const double level : {g.d_lo, g.d_hi}) cross(ta, tb, Across(g, a), Across(g, b), level);
      for (const double level : {g.v_lo, g.v_hi}) cross(ta, tb, a.v, b.v, level);
      for (const double level : {g.h_lo, g.h_hi}) cross(ta, tb, a.h, b.h, level);
    };
    for (int k = 0; k + 1 < n; ++k) {
      const double ta = k * dt, tb = (k + 1) * dt;
      if (tb < t0 || ta > t1) continue;
      if (ta >= t0) best = std::min(best, MissAt(g, State(ctx, in, ta)));
      piece(ta, tb);
    }
    if (t1 > t_end) piece(std::max(t_end, t0), t1);  // the straight continuation
    return best;
  }

  double s_scale_ = 10.0, d_scale_ = 1.75, v_scale_ = 5.0, h_scale_ = 0.05, miss_ = 1.0,
         cap_ = 10.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(goal, frenetic::cost::GoalCost);

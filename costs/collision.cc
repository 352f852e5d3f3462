// collision: predicted overlap of the oriented ego footprint (heading from the Frenet velocity)
// with predicted cars' footprints, each inflated by a safety margin. Earlier overlaps weigh more
// (1 / (1 + t / time_scale)); the value is in [0, 1].
#include <algorithm>
#include <cmath>

#include "frenetic/cost/cost_registry.h"
#include "frenetic/traj/box.h"

namespace frenetic::cost {
namespace {

class CollisionCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"margin", 0.5, 0.0, 3.0, false}, {"time_scale", 2.0, 0.2, 20.0, true}};
  }
  void Configure(std::span<const double> v) override {
    margin_ = v[0];
    time_scale_ = v[1];
  }
  bool Expensive() const override { return true; }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (n == 0 || ctx.num_cars == 0) return 0.0;
    // The ego's box and the largest car's, each inflated by the margin.
    const double hl = 0.5 * ctx.ego_length + margin_, hw = 0.5 * ctx.ego_width + margin_;
    const double hl_max = ctx.max_half_length + margin_, hw_max = ctx.max_half_width + margin_;
    // Cheap reject first: no overlap is possible beyond the boxes' circumscribed reach, nor
    // laterally beyond the ego's turned half-extent plus the car's half-width, at most
    // hl |sin| + (hw + hw_max) with |sin| <= |d'|/s' (the heading from the Frenet velocity, s'
    // floored: no spin at rest).
    const double reach = std::hypot(hl, hw) + std::hypot(hl_max, hw_max);
    double max_d_d = 0, min_s_d = 1e9;
    for (int k = 0; k < n; ++k) {
      max_d_d = std::max(max_d_d, std::abs(in.d_d[k]));
      min_s_d = std::min(min_s_d, in.s_d[k]);
    }
    const double max_sin = std::min(1.0, max_d_d / std::max(min_s_d, 0.5));
    const NearCars near(ctx, in, hl * max_sin + (hw + hw_max), reach);
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      if (near.At(k) == 0) continue;
      const double vs = std::max(in.s_d[k], 0.5), vd = in.d_d[k];
      double ch = 0, sh = 0;  // unit heading, computed for the first car within reach
      bool hit = false;
      near.ForEach(k, [&](int c) {
        const double ds = ctx.car_s[c * n + k] - in.s[k], dd = ctx.car_d[c * n + k] - in.d[k];
        if (std::abs(ds) > reach || std::abs(dd) > reach) return true;
        if (ch == 0) {
          const double inv = 1.0 / std::sqrt(vs * vs + vd * vd);
          ch = vs * inv;
          sh = vd * inv;
        }
        // The car's own axes first (two of the four separating axes, the ones that part most
        // pairs); the full test only when both overlap.
        const double chl = ctx.HalfLength(c) + margin_, chw = ctx.HalfWidth(c) + margin_;
        const double ex = hl * ch + hw * std::abs(sh), ey = hl * std::abs(sh) + hw * ch;
        if (std::abs(ds) > ex + chl || std::abs(dd) > ey + chw) return true;
        const traj::OrientedBox ego{in.s[k], in.d[k], 0.0, hl, hw};
        const traj::OrientedBox car{in.s[k] + ds, in.d[k] + dd, 0.0, chl, chw};
        hit = traj::Overlap(ego, ch, sh, car, 1.0, 0.0);
        return !hit;
      });
      if (hit) sum += 1.0 / (1.0 + k * ctx.dt / time_scale_);
    }
    return sum / n;
  }

 private:
  double margin_ = 0.5, time_scale_ = 2.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(collision, frenetic::cost::CollisionCost);

// buffer: shortfall of the gap to predicted cars in the ego's lane (ahead and behind) against a
// desired gap min_gap + headway * speed (the follower's speed), squared and averaged over the
// samples. 0 with ample room; about 1 bumper to bumper.
#include <algorithm>
#include <cmath>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class BufferCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"min_gap", 8.0, 2.0, 40.0, false}, {"headway", 1.2, 0.2, 4.0, false}};
  }
  void Configure(std::span<const double> v) override {
    min_gap_ = v[0];
    headway_ = v[1];
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (n == 0 || ctx.num_cars == 0) return 0.0;
    // Same lane: the centres are closer laterally than a car width plus a little.
    const double same_lane = ctx.car_width + 0.6;
    const double car_v_max = ctx.max_car_speed;
    double max_speed = car_v_max;
    for (int k = 0; k < n; ++k) max_speed = std::max(max_speed, in.s_d[k]);
    const double max_reach = ctx.car_length + min_gap_ + headway_ * max_speed;
    if (!AnyCarNear(ctx, in, same_lane, max_reach)) return 0.0;
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      double worst = 0;
      // The desired gap depends on the follower: the ego for a car ahead, the car for one behind.
      const double ego_speed = std::max(in.s_d[k], 0.0);
      const double desired_ahead = min_gap_ + headway_ * ego_speed;
      const double inv_ahead = 1.0 / desired_ahead;
      // No car farther in s than a car length plus the largest desired gap can fall short.
      const double reach = ctx.car_length + min_gap_ + headway_ * std::max(ego_speed, car_v_max);
      ForEachCarNear(ctx, in, k, same_lane, reach, [&](int c) {
        if (std::abs(ctx.car_d[c * n + k] - in.d[k]) > same_lane) return true;
        const double ds = ctx.car_s[c * n + k] - in.s[k];
        const double gap = std::abs(ds) - ctx.car_length;
        double ratio;  // gap / desired gap
        if (ds >= 0) {
          ratio = gap * inv_ahead;
        } else {
          ratio = gap / (min_gap_ + headway_ * std::max(ctx.car_v[c * n + k], 0.0));
        }
        const double shortfall = std::clamp(1.0 - ratio, 0.0, 3.0);
        worst = std::max(worst, shortfall * shortfall);
        return true;
      });
      sum += worst;
    }
    return sum / n;
  }

 private:
  double min_gap_ = 8.0, headway_ = 1.2;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(buffer, frenetic::cost::BufferCost);

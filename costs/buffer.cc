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
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      double worst = 0;
      for (int c = 0; c < ctx.num_cars; ++c) {
        if (std::abs(ctx.car_d[c] - in.d[k]) > same_lane) continue;
        const double ds = ctx.car_s[c * n + k] - in.s[k];
        const double follower_speed = ds >= 0 ? std::max(in.s_d[k], 0.0) : ctx.car_v[c];
        const double desired = min_gap_ + headway_ * std::max(follower_speed, 0.0);
        const double gap = std::abs(ds) - ctx.car_length;
        if (gap >= desired) continue;
        const double shortfall = std::min((desired - gap) / desired, 3.0);
        worst = std::max(worst, shortfall * shortfall);
      }
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

// efficiency: how far the candidate falls short of the target lane's speed limit, at its end
// (speed shortfall) and over the horizon (progress shortfall), each as a fraction of `scale` x
// the limit (a shortfall of scale x limit counts 1; speed matters a lot, so with scale 0.4 its
// weight stays in the 1-10 range of the others).
#include <algorithm>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class EfficiencyCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"progress_share", 0.5, 0.0, 1.0, false}, {"scale", 0.4, 0.1, 1.0, false}};
  }
  void Configure(std::span<const double> v) override {
    progress_share_ = v[0];
    scale_ = v[1];
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int lane = std::clamp(in.target_lane, 0, kMaxLanes - 1);
    const double limit = std::max(ctx.lane_speed_limit[lane], 1.0);
    const double speed_short = std::clamp((limit - in.end_speed) / limit, 0.0, 1.0);
    double progress_short = 0;
    const int n = ctx.num_samples;
    if (n >= 2) {
      const double horizon = (n - 1) * ctx.dt;
      const double best = limit * horizon;
      progress_short = std::clamp((best - (in.s[n - 1] - in.s[0])) / best, 0.0, 1.0);
    }
    return ((1.0 - progress_share_) * speed_short + progress_share_ * progress_short) / scale_;
  }

 private:
  double progress_share_ = 0.5, scale_ = 0.4;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(efficiency, frenetic::cost::EfficiencyCost);

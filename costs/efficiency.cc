// efficiency: how far the candidate falls short of the target lane's speed limit, at its end
// (speed shortfall) and over the horizon (progress shortfall), each as a fraction of the limit.
#include <algorithm>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class EfficiencyCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"progress_share", 0.5, 0.0, 1.0, false}};
  }
  void Configure(std::span<const double> v) override { progress_share_ = v[0]; }
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
    return (1.0 - progress_share_) * speed_short + progress_share_ * progress_short;
  }

 private:
  double progress_share_ = 0.5;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(efficiency, frenetic::cost::EfficiencyCost);

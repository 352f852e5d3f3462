// lane_flow: how much the target lane's traffic will slow the ego over the next `horizon` s,
// beyond the few seconds the trajectory itself covers. For each car ahead in the lane (by its d
// at the start), an ego at the lane's limit catches it after t = gap / (limit - v) and then
// drives at its speed; the lane's flow is the lowest such mean speed over the horizon. Its
// shortfall from the limit counts in units of `scale` x the limit, as in efficiency. It depends
// on the lane only: it moves the ego into the lane whose slow car is farthest or fastest before
// it gets there, where a 6 s horizon sees the queue only once the ego is stuck in it (and both
// neighbours are often taken by then).
#include <algorithm>
#include <cmath>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class LaneFlowCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"horizon", 20.0, 6.0, 60.0, false}, {"scale", 0.4, 0.1, 1.0, false}};
  }
  void Configure(std::span<const double> v) override {
    horizon_ = v[0];
    scale_ = v[1];
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int lane = std::clamp(in.target_lane, 0, kMaxLanes - 1);
    const double limit = std::max(ctx.lane_speed_limit[lane], 1.0);
    const double centre = ctx.lane_center[lane];
    const double half = 0.5 * ctx.lane_width;
    const int n = ctx.num_samples;
    double flow = limit;
    for (int c = 0; c < ctx.num_cars && n > 0; ++c) {
      const double v = ctx.car_v[c * n];
      if (!(std::abs(ctx.car_d[c * n] - centre) < half) || !(v < flow)) continue;
      const double gap = ctx.car_s[c * n] - ctx.start_s - (0.5 * ctx.ego_length + ctx.HalfLength(c));
      if (!(gap > 0)) continue;  // alongside or behind: the trajectory's own terms see it
      const double catch_up = gap / (limit - std::max(v, 0.0));
      if (catch_up >= horizon_) continue;
      flow = std::min(flow, (limit * catch_up + std::max(v, 0.0) * (horizon_ - catch_up)) / horizon_);
    }
    return std::clamp((limit - flow) / limit, 0.0, 1.0) / scale_;
  }
  bool LaneOnly() const override { return true; }

 private:
  double horizon_ = 20.0, scale_ = 0.4;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(lane_flow, frenetic::cost::LaneFlowCost);

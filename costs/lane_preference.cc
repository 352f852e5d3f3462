// lane_preference: distance of the end offset from the preferred lane's centre (the middle lane
// keeps both neighbours open), over the road's width, plus the end offset from the target lane's
// own centre, over the lane width.
#include <algorithm>
#include <cmath>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class LanePreferenceCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"preferred_lane", 1.0, 0.0, kMaxLanes - 1.0, false}};
  }
  void Configure(std::span<const double> v) override {
    preferred_lane_ = static_cast<int>(std::lround(v[0]));
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int last = std::clamp(ctx.num_lanes, 1, kMaxLanes) - 1;
    const int pref = std::clamp(preferred_lane_, 0, last);
    const int target = std::clamp(in.target_lane, 0, last);
    const double width = std::max(ctx.lane_width * std::max(last, 1), 1.0);
    return std::abs(in.end_d - ctx.lane_center[pref]) / width +
           std::abs(in.end_d - ctx.lane_center[target]) / std::max(ctx.lane_width, 1.0);
  }

 private:
  int preferred_lane_ = 1;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(lane_preference, frenetic::cost::LanePreferenceCost);

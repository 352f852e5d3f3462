// lane_change: 1 for choosing a lane other than the one targeted last cycle (so a started lane
// change is followed through: the simulator flags > 3 s astride a line), plus switch_back when
// the choice returns to the lane a lane change left less than `hold` seconds ago (hysteresis).
#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class LaneChangeCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"switch_back", 3.0, 0.0, 20.0, false}, {"hold", 4.0, 0.0, 20.0, false}};
  }
  void Configure(std::span<const double> v) override {
    switch_back_ = v[0];
    hold_ = v[1];
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int committed =
        ctx.previous_target_lane >= 0 ? ctx.previous_target_lane : ctx.current_lane;
    if (in.target_lane == committed) return 0.0;
    double value = 1.0;
    if (in.target_lane == ctx.lane_before_change && ctx.time_since_lane_change < hold_) {
      value += switch_back_;
    }
    return value;
  }

 private:
  double switch_back_ = 3.0, hold_ = 4.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(lane_change, frenetic::cost::LaneChangeCost);

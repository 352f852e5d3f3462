// jerk: integrated squared longitudinal and lateral jerk (closed form, Werling et al. ICRA
// 2010), as a mean square over the scoring horizon, normalised by (2 m/s^3)^2.
#include <algorithm>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class JerkCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"scale", 2.0, 0.5, 10.0, true}, {"lat_factor", 1.0, 0.1, 10.0, true}};
  }
  void Configure(std::span<const double> v) override {
    scale_ = v[0];
    lat_factor_ = v[1];
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const double horizon = std::max((ctx.num_samples - 1) * ctx.dt, 1.0);
    const double j2 = in.lon_jerk_squared + lat_factor_ * in.lat_jerk_squared;
    return std::max(j2, 0.0) / horizon / (scale_ * scale_);
  }

 private:
  double scale_ = 2.0, lat_factor_ = 1.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(jerk, frenetic::cost::JerkCost);

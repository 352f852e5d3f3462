// acceleration: mean squared longitudinal and lateral acceleration over the samples,
// normalised by (2 m/s^2)^2.
#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class AccelerationCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"scale", 2.0, 0.5, 10.0, true}};
  }
  void Configure(std::span<const double> v) override { scale_ = v[0]; }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (n == 0) return 0.0;
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += in.s_dd[k] * in.s_dd[k] + in.d_dd[k] * in.d_dd[k];
    return sum / n / (scale_ * scale_);
  }

  bool Sampled() const override { return true; }

 private:
  double scale_ = 2.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(acceleration, frenetic::cost::AccelerationCost);

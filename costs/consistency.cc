// consistency: mean distance between the candidate and last cycle's chosen trajectory at the
// same instants, s over s_scale plus d over the lane width (0 without a previous choice).
#include <algorithm>
#include <cmath>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class ConsistencyCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"s_scale", 10.0, 1.0, 100.0, true}};
  }
  void Configure(std::span<const double> v) override { s_scale_ = v[0]; }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (n == 0 || ctx.previous_s == nullptr || ctx.previous_d == nullptr) return 0.0;
    const double lw = std::max(ctx.lane_width, 1.0);
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      sum += std::abs(in.s[k] - ctx.previous_s[k]) / s_scale_ +
             std::abs(in.d[k] - ctx.previous_d[k]) / lw;
    }
    return std::min(sum / n, 1e6);
  }

  bool Sampled() const override { return true; }

 private:
  double s_scale_ = 10.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(consistency, frenetic::cost::ConsistencyCost);

// oncoming: time spent in a two-way road's oncoming lane (CostContext::oncoming_right; none on
// the Udacity track or on one-way roads, where it is 0): the mean over the samples of the share
// of the ego's width left of that lane's right border, from 0 (clear of it) to 1 (wholly in
// it). The lane is there for passing, against the other direction's traffic: a plan enters it
// only when what it gains (a blocked lane passed, a goal reached) outweighs this.
#include <algorithm>
#include <cmath>
#include <limits>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class OncomingCost : public CostTerm {
 public:
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (!(ctx.oncoming_right > -std::numeric_limits<double>::infinity()) || n < 1) return 0.0;
    const double w = std::max(ctx.ego_width, 0.1);
    const double left_edge = ctx.oncoming_right + 0.5 * w;  // a centre this far left is inside
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += std::clamp((left_edge - in.d[k]) / w, 0.0, 1.0);
    return sum / n;
  }
  bool Sampled() const override { return true; }
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(oncoming, frenetic::cost::OncomingCost);

// strategy: how much of the strategic layer's best lane plan the candidate gives up. The
// strategic layer (the search planner's Strategy) weighs lane sequences and gaps over the next
// ~20 s on the predicted traffic and offers, per lane, the plans a candidate bound for it can
// follow, each with its regret (m of progress lost against the best plan) and, for a plan that
// must first drop back behind a car of the next lane or get ahead of one, where along s the
// candidate has to be by then. A candidate costs the smallest regret plus window miss (m) over
// the options for its target lane, capped at `cap` m (also the value of a lane no plan uses),
// less `slack` m (the rollouts' coarse model cannot tell plans that close apart), over `scale`
// m: one unit is `scale` m of progress (about a second at the limit). 0 without a plan. Hard checks
// still decide what is feasible: this only ranks.
#include <algorithm>
#include <cmath>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class StrategyCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"scale", 20.0, 5.0, 200.0, true},
            {"cap", 100.0, 10.0, 1000.0, true},
            {"slack", 0.0, 0.0, 100.0, false}};
  }
  void Configure(std::span<const double> v) override {
    scale_ = v[0];
    cap_ = v[1];
    slack_ = v[2];
  }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const StrategyGoal* goal = ctx.strategy;
    const int n = ctx.num_samples;
    if (goal == nullptr || goal->num_options <= 0 || n <= 0) return 0.0;
    double best = cap_;
    const int count = std::min(goal->num_options, kMaxStrategyOptions);
    for (int i = 0; i < count; ++i) {
      const StrategyOption& o = goal->options[i];
      if (o.lane != in.target_lane) continue;
      const double at = ctx.dt > 0 ? o.t / ctx.dt : 0.0;
      const int k =
          std::isfinite(at)
              ? static_cast<int>(std::clamp(std::lround(at), 0L, static_cast<long>(n - 1)))
              : n - 1;
      const double s = in.s[k];
      // NaN compares false: an unknown position misses nothing (the hard checks reject it).
      const double miss = (s > o.s_hi ? s - o.s_hi : 0.0) + (s < o.s_lo ? o.s_lo - s : 0.0);
      const double value = std::max(o.regret, 0.0) + miss;
      if (value < best) best = value;
    }
    return std::max(std::min(best, cap_) - slack_, 0.0) / scale_;
  }

 private:
  double scale_ = 20.0, cap_ = 100.0, slack_ = 0.0;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(strategy, frenetic::cost::StrategyCost);

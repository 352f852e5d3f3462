// buffer: shortfall of the gap to predicted cars in the ego's lane (ahead and behind) against a
// desired gap min_gap + headway * speed (the follower's speed), squared and averaged over the
// samples. 0 with ample room; about 1 bumper to bumper.
#include <algorithm>
#include <cmath>
#include <limits>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::cost {
namespace {

class BufferCost : public CostTerm {
 public:
  std::vector<CostParamSpec> ParamSpecs() const override {
    return {{"min_gap", 8.0, 2.0, 40.0, false}, {"headway", 1.2, 0.2, 4.0, false}};
  }
  void Configure(std::span<const double> v) override {
    min_gap_ = v[0];
    headway_ = v[1];
  }
  bool Expensive() const override { return true; }
  double Evaluate(const CostContext& ctx, const CostInput& in) const override {
    const int n = ctx.num_samples;
    if (n == 0 || ctx.num_cars == 0) return 0.0;
    // Same lane: the centres are closer laterally than half the ego's width and half the car's,
    // plus a little.
    const double ego_hl = 0.5 * ctx.ego_length, ego_hw = 0.5 * ctx.ego_width;
    const double same_lane = ego_hw + ctx.max_half_width + 0.6;
    // No car farther in s than the two half lengths plus the largest desired gap can fall short.
    double max_speed = ctx.max_car_speed;
    for (int k = 0; k < n; ++k) max_speed = std::max(max_speed, in.s_d[k]);
    const NearCars near(ctx, in, same_lane,
                        ego_hl + ctx.max_half_length + min_gap_ + headway_ * max_speed);
    if (!near.Any(n)) return 0.0;
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      // The desired gap depends on the follower: the ego for a car ahead (whose nearest one
      // falls shortest), the car itself for one behind.
      double nearest_ahead = std::numeric_limits<double>::infinity(), worst = 0;
      near.ForEach(k, [&](int c) {
        if (std::abs(ctx.car_d[c * n + k] - in.d[k]) > ego_hw + ctx.HalfWidth(c) + 0.6) return true;
        const double ds = ctx.car_s[c * n + k] - in.s[k];
        const double bumpers = ego_hl + ctx.HalfLength(c);  // centre distance at contact
        if (ds >= 0) {
          nearest_ahead = std::min(nearest_ahead, ds - bumpers);
        } else {
          const double desired = min_gap_ + headway_ * std::max(ctx.car_v[c * n + k], 0.0);
          worst = std::max(worst, Shortfall(-ds - bumpers, desired));
        }
        return true;
      });
      if (nearest_ahead < std::numeric_limits<double>::infinity()) {
        const double desired = min_gap_ + headway_ * std::max(in.s_d[k], 0.0);
        worst = std::max(worst, Shortfall(nearest_ahead, desired));
      }
      sum += worst;
    }
    return sum / n;
  }

 private:
  // (1 - gap / desired)^2 where the gap falls short, capped; 0 with ample room.
  static double Shortfall(double gap, double desired) {
    const double shortfall = std::clamp(1.0 - gap / desired, 0.0, 3.0);
    return shortfall * shortfall;
  }
  double min_gap_ = 8.0, headway_ = 1.2;
};

}  // namespace
}  // namespace frenetic::cost

FRENETIC_REGISTER_COST(buffer, frenetic::cost::BufferCost);

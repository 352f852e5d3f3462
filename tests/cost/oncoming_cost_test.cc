// The oncoming term: the time a candidate spends in a two-way road's oncoming lane.
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "frenetic/cost/cost_registry.h"
#include "frenetic/cost/cost_term.h"

namespace frenetic::cost {
namespace {

struct Candidate {
  std::vector<double> d;
  CostContext ctx;
  CostInput in;
  explicit Candidate(std::vector<double> ds) : d(std::move(ds)) {
    ctx.num_samples = static_cast<int>(d.size());
    ctx.ego_width = 2.0;
    in.d = d.data();
  }
};

double Eval(const Candidate& c) {
  auto made = CostRegistry::Global().Make("oncoming");
  EXPECT_TRUE(made.ok());
  return made.value()->Evaluate(c.ctx, c.in);
}

TEST(OncomingCostTest, NothingWithoutAnOncomingLane) {
  Candidate c({-5, -4, -3, 0});
  EXPECT_EQ(c.ctx.oncoming_right, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(Eval(c), 0.0);
}

TEST(OncomingCostTest, TheShareOfTheWidthOverTheLineAveragedOverTheSamples) {
  // The oncoming lane ends at d = -2 (on the left): a 2 m wide ego centred at -2 is half in it,
  // at -3 or farther left wholly, at -1 or right of it not at all.
  Candidate c({-4, -3, -2, -1, 0});
  c.ctx.oncoming_right = -2;
  EXPECT_DOUBLE_EQ(Eval(c), (1 + 1 + 0.5 + 0 + 0) / 5);
  Candidate clear({-1, 0, 1});
  clear.ctx.oncoming_right = -2;
  EXPECT_EQ(Eval(clear), 0.0);
}

}  // namespace
}  // namespace frenetic::cost

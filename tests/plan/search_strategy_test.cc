// The search planner's strategic layer (search_strategy.h): which lane plan it chooses on a
// free road, behind a slow leader and boxed in behind a car of the next lane; the options it
// hands the `strategy` cost term; determinism, finiteness and the switch.
#include "plan/search_strategy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "frenetic/cost/cost_registry.h"
#include "plan/search_stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::SceneCar;
using testing::Stages;

// A straight-ish stretch of the Udacity loop.
constexpr double kS = 800;

PlannerConfig WithStrategy(int enabled) {
  PlannerConfig c = testing::DefaultConfig();
  EXPECT_TRUE(c.Set("strategy.enabled", enabled).ok());
  return c;
}

// Centred in `lane` at `speed`, the cars given relative to the ego (ds, lane, speed).
struct RelCar {
  double ds;
  int lane;
  double v;
};
void Prepare(Stages& st, int lane, double speed, const std::vector<RelCar>& rel) {
  std::vector<SceneCar> cars;
  for (const RelCar& c : rel) cars.push_back({kS + c.ds, 2.0 + 4.0 * c.lane, c.v});
  st.Prepare({kS, speed, 0, 2.0 + 4.0 * lane, 0, 0}, cars);
  // Once more on the lane centres the first context computed (they depend on s and speed).
  cars.clear();
  for (const RelCar& c : rel) cars.push_back({kS + c.ds, st.ws.lane_center[c.lane], c.v});
  st.Prepare({kS, speed, 0, st.ws.lane_center[lane], 0, 0}, cars);
}

const StrategyPlan& Chosen(const StrategySummary& s) {
  EXPECT_GE(s.chosen, 0);
  EXPECT_LT(s.chosen, s.num_plans);
  return s.plans[std::max(0, s.chosen)];
}

// The final lane of a plan (`from` when it keeps its lane).
int FinalLane(const StrategyPlan& p, int from) {
  return p.lanes[1] >= 0 ? p.lanes[1] : (p.lanes[0] >= 0 ? p.lanes[0] : from);
}

// The least regret (m) of the options for `lane` without a window in s; NaN: none.
double OpenRegret(const cost::StrategyGoal& g, int lane) {
  double best = NAN;
  for (int i = 0; i < g.num_options; ++i) {
    const cost::StrategyOption& o = g.options[i];
    if (o.lane != lane || std::isfinite(o.s_lo) || std::isfinite(o.s_hi)) continue;
    if (!(o.regret >= best)) best = o.regret;
  }
  return best;
}

// The `strategy` term (its shipped parameters) on a candidate bound for `lane` at constant
// speed from the start.
double TermValue(const Stages& st, int lane, double speed) {
  auto made = cost::CostRegistry::Global().Make("strategy");
  EXPECT_TRUE(made.ok());
  std::unique_ptr<cost::CostTerm> term = std::move(made.value());
  std::vector<double> params;
  for (const auto& spec : term->ParamSpecs()) params.push_back(spec.default_value);
  term->Configure(params);
  const cost::CostContext& ctx = st.ws.ctx;
  std::vector<double> s(ctx.num_samples), zero(ctx.num_samples, 0.0), v(ctx.num_samples, speed);
  for (int k = 0; k < ctx.num_samples; ++k) s[k] = st.ws.start.s + speed * k * ctx.dt;
  cost::CostInput in;
  in.s = s.data();
  in.s_d = v.data();
  in.s_dd = zero.data();
  in.d = zero.data();
  in.d_d = zero.data();
  in.d_dd = zero.data();
  in.target_lane = lane;
  return term->Evaluate(ctx, in);
}

void ExpectSane(const StrategySummary& sum, const cost::StrategyGoal& goal) {
  ASSERT_GT(sum.num_plans, 0);
  ASSERT_LE(sum.num_plans, StrategySummary::kMaxPlans);
  for (int i = 0; i < sum.num_plans; ++i) {
    EXPECT_TRUE(std::isfinite(sum.plans[i].value)) << i;
    EXPECT_TRUE(std::isfinite(sum.plans[i].progress)) << i;
    EXPECT_GE(sum.plans[i].progress, 0.0) << i;
  }
  ASSERT_GT(goal.num_options, 0);
  ASSERT_LE(goal.num_options, cost::kMaxStrategyOptions);
  double least = INFINITY;
  for (int i = 0; i < goal.num_options; ++i) {
    const cost::StrategyOption& o = goal.options[i];
    EXPECT_TRUE(std::isfinite(o.regret) && o.regret >= 0) << i;
    EXPECT_TRUE(std::isfinite(o.t) && o.t >= 0) << i;
    EXPECT_GE(o.lane, 0);
    EXPECT_LT(o.lane, 3);
    EXPECT_FALSE(std::isnan(o.s_lo) || std::isnan(o.s_hi)) << i;
    if (i > 0) {
      EXPECT_GE(o.regret, goal.options[i - 1].regret) << "least regret first";
    }
    least = std::min(least, o.regret);
  }
  EXPECT_EQ(least, 0.0) << "the chosen plan has no regret";
}

TEST(SearchStrategyTest, FreeRoadKeepsTheLane) {
  REQUIRE_UDACITY_MAP();
  Stages st(WithStrategy(1));
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  Prepare(st, 1, 20, {});
  StrategySummary sum;
  strategy.Decide(0, &sum);
  ExpectSane(sum, st.ws.strategy_goal);
  EXPECT_EQ(st.ws.ctx.strategy, &st.ws.strategy_goal);
  const StrategyPlan& p = Chosen(sum);
  EXPECT_EQ(p.lanes[0], -1) << "a lane change only costs on a free road";
  EXPECT_EQ(p.mode, StrategyPlan::Mode::kKeep);
  EXPECT_EQ(OpenRegret(st.ws.strategy_goal, 1), 0.0);
  EXPECT_EQ(TermValue(st, 1, 20), 0.0);
}

TEST(SearchStrategyTest, SlowLeaderSendsItToTheFreeNeighbourNotTheQueue) {
  REQUIRE_UDACITY_MAP();
  Stages st(WithStrategy(1));
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  // Middle lane behind a 10 m/s car; the right lane a 10 m/s queue a little further on; the
  // left lane free.
  Prepare(st, 1, 20, {{35, 1, 10}, {60, 2, 10}, {80, 2, 10}});
  StrategySummary sum;
  strategy.Decide(0, &sum);
  ExpectSane(sum, st.ws.strategy_goal);
  const StrategyPlan& p = Chosen(sum);
  EXPECT_EQ(p.lanes[0], 0);
  EXPECT_GE(p.t_change, 0.0);
  EXPECT_LT(p.t_change, 1.0) << "the left lane is open now";
  // The term ranks the candidates so: left below staying below right.
  const double left = TermValue(st, 0, 20), stay = TermValue(st, 1, 20),
               right = TermValue(st, 2, 20);
  EXPECT_EQ(left, 0.0);
  EXPECT_GT(stay, left);
  EXPECT_GE(right, stay);
  for (const double v : {left, stay, right}) EXPECT_TRUE(std::isfinite(v) && v >= 0);
}

TEST(SearchStrategyTest, BoxedInDropsBackForTheLaneBeyond) {
  REQUIRE_UDACITY_MAP();
  Stages st(WithStrategy(1));
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  // Left lane behind a 10 m/s car; the middle lane has a car alongside at 15 m/s and a 12 m/s
  // car 60 m on; the right lane is free. Getting there means dropping back behind the car
  // alongside (the ego's own leader keeps it from getting ahead of it).
  Prepare(st, 0, 15, {{25, 0, 10}, {0, 1, 15}, {60, 1, 12}});
  StrategySummary sum;
  strategy.Decide(0, &sum);
  ExpectSane(sum, st.ws.strategy_goal);
  const StrategyPlan& p = Chosen(sum);
  EXPECT_EQ(p.lanes[0], 1);
  EXPECT_EQ(FinalLane(p, 0), 2) << "the free lane two over";
  EXPECT_EQ(p.mode, StrategyPlan::Mode::kDropBack);
  EXPECT_GT(p.t_change, 0.0) << "not while the car is alongside";
  // Its options for the middle lane ask the candidate to be behind that car by then.
  bool windowed = false;
  for (int i = 0; i < st.ws.strategy_goal.num_options; ++i) {
    const cost::StrategyOption& o = st.ws.strategy_goal.options[i];
    if (o.regret == 0 && o.lane == 1) windowed = windowed || std::isfinite(o.s_hi);
  }
  EXPECT_TRUE(windowed);
  // Better than staying behind the 10 m/s car.
  for (int i = 0; i < sum.num_plans; ++i) {
    if (sum.plans[i].lanes[0] < 0) {
      EXPECT_GT(p.value, sum.plans[i].value);
    }
  }
}

TEST(SearchStrategyTest, DisabledLeavesNoPlan) {
  REQUIRE_UDACITY_MAP();
  Stages st(WithStrategy(0));
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  Prepare(st, 1, 20, {{35, 1, 10}});
  StrategySummary sum;
  sum.num_plans = 3;
  strategy.Decide(0, &sum);
  EXPECT_EQ(sum.num_plans, 0);
  EXPECT_EQ(sum.chosen, -1);
  EXPECT_EQ(st.ws.ctx.strategy, nullptr);
  EXPECT_EQ(TermValue(st, 2, 20), 0.0) << "no plan: the term charges nothing";
}

TEST(SearchStrategyTest, WithoutGapCarsOnlyLaneSequences) {
  REQUIRE_UDACITY_MAP();
  PlannerConfig c = WithStrategy(1);
  ASSERT_TRUE(c.Set("strategy.gap_cars", 0).ok());
  Stages st(c);
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  Prepare(st, 0, 15, {{25, 0, 10}, {0, 1, 15}, {60, 1, 12}});  // boxed in, as above
  StrategySummary sum;
  strategy.Decide(0, &sum);
  ExpectSane(sum, st.ws.strategy_goal);
  for (int i = 0; i < sum.num_plans; ++i) {
    EXPECT_EQ(sum.plans[i].mode, StrategyPlan::Mode::kKeep) << i;
    EXPECT_EQ(sum.plans[i].car, -1) << i;
  }
}

// One-sided: no lane is charged more than keeping the current one. On a free road (keeping is
// best) that charges nothing anywhere; behind a slow leader it still charges staying.
TEST(SearchStrategyTest, OneSidedNeverChargesMoreThanKeeping) {
  REQUIRE_UDACITY_MAP();
  PlannerConfig c = WithStrategy(1);
  ASSERT_TRUE(c.Set("strategy.one_sided", 1).ok());
  Stages st(c);
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  Prepare(st, 1, 20, {});
  StrategySummary sum;
  strategy.Decide(0, &sum);
  ExpectSane(sum, st.ws.strategy_goal);
  for (int i = 0; i < st.ws.strategy_goal.num_options; ++i) {
    EXPECT_EQ(st.ws.strategy_goal.options[i].regret, 0.0) << i;
  }
  for (int l = 0; l < 3; ++l) EXPECT_EQ(TermValue(st, l, 20), 0.0) << l;
  strategy.Reset();
  Prepare(st, 1, 20, {{35, 1, 10}, {60, 2, 10}, {80, 2, 10}});
  strategy.Decide(0, &sum);
  ExpectSane(sum, st.ws.strategy_goal);
  const double left = TermValue(st, 0, 20), stay = TermValue(st, 1, 20),
               right = TermValue(st, 2, 20);
  EXPECT_EQ(left, 0.0);
  EXPECT_GT(stay, 0.0);
  EXPECT_LE(right, stay);
}

// Random scenes: every value finite, the options sorted, and the same decision from the same
// scene after a Reset.
TEST(SearchStrategyTest, RandomScenesAreFiniteAndDeterministic) {
  REQUIRE_UDACITY_MAP();
  Stages st(WithStrategy(1));
  Strategy strategy(st.cfg, *st.predictor, st.ws);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(0, 1);
  for (int scene = 0; scene < 150; ++scene) {
    const int lane = static_cast<int>(u(rng) * 3);
    const double speed = 25 * u(rng);
    std::vector<RelCar> cars;
    const int n = static_cast<int>(u(rng) * 14);
    for (int i = 0; i < n; ++i) {
      cars.push_back({-60 + 160 * u(rng), static_cast<int>(u(rng) * 3), 22 * u(rng)});
    }
    Prepare(st, lane, speed, cars);
    StrategySummary a, b;
    strategy.Reset();
    strategy.Decide(0, &a);
    ExpectSane(a, st.ws.strategy_goal);
    const cost::StrategyGoal first = st.ws.strategy_goal;
    strategy.Reset();
    strategy.Decide(0, &b);
    ASSERT_EQ(a.num_plans, b.num_plans) << "scene " << scene;
    ASSERT_EQ(a.chosen, b.chosen) << "scene " << scene;
    for (int i = 0; i < a.num_plans; ++i) {
      EXPECT_EQ(a.plans[i].value, b.plans[i].value);
      EXPECT_EQ(a.plans[i].lanes, b.plans[i].lanes);
    }
    ASSERT_EQ(first.num_options, st.ws.strategy_goal.num_options);
    for (int i = 0; i < first.num_options; ++i) {
      EXPECT_EQ(first.options[i].regret, st.ws.strategy_goal.options[i].regret);
      EXPECT_EQ(first.options[i].lane, st.ws.strategy_goal.options[i].lane);
    }
    for (int l = 0; l < 3; ++l) {
      const double v = TermValue(st, l, speed);
      EXPECT_TRUE(std::isfinite(v) && v >= 0) << "scene " << scene << " lane " << l;
    }
  }
}

}  // namespace
}  // namespace frenetic::plan::search

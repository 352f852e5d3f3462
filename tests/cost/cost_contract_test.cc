// Every registered cost term through the same property checks, and the registry against
// config/planner.yaml.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "frenetic/cost/cost_registry.h"
#include "frenetic/cost/cost_set.h"

namespace frenetic::cost {
namespace {

constexpr int kN = 25;

// A candidate with its sample storage.
struct Fixture {
  std::vector<double> s, s_d, s_dd, d, d_d, d_dd, car_s, car_d, car_v, prev_s, prev_d;
  std::vector<GoalRegion> goals;
  CostContext ctx;
  CostInput in;

  void Wire() {
    in.s = s.data(); in.s_d = s_d.data(); in.s_dd = s_dd.data();
    in.d = d.data(); in.d_d = d_d.data(); in.d_dd = d_dd.data();
    ctx.car_s = car_s.data(); ctx.car_d = car_d.data(); ctx.car_v = car_v.data();
    ctx.num_cars = static_cast<int>(car_d.size()) / kN;
    ctx.previous_s = prev_s.empty() ? nullptr : prev_s.data();
    ctx.previous_d = prev_d.empty() ? nullptr : prev_d.data();
    ctx.num_goals = static_cast<int>(goals.size());
    ctx.goals = goals.empty() ? nullptr : goals.data();
  }
};

void SetLanes(CostContext& ctx) {
  ctx.num_samples = kN;
  ctx.dt = 0.25;
  ctx.lane_width = 4;
  ctx.num_lanes = 3;
  for (int l = 0; l < 3; ++l) {
    ctx.lane_center[l] = 2 + 4 * l;
    ctx.lane_speed_limit[l] = 22.0;
  }
}

// Ideal lane keeping: middle lane, at the limit, no traffic, same as last cycle.
Fixture IdealLaneKeeping() {
  Fixture f;
  SetLanes(f.ctx);
  for (int k = 0; k < kN; ++k) {
    f.s.push_back(100 + 22.0 * k * 0.25);
    f.s_d.push_back(22.0);
    f.s_dd.push_back(0);
    f.d.push_back(6);
    f.d_d.push_back(0);
    f.d_dd.push_back(0);
  }
  f.prev_s = f.s;
  f.prev_d = f.d;
  f.ctx.start_s = 100;
  f.ctx.start_d = 6;
  f.ctx.start_speed = 22;
  f.ctx.current_lane = 1;
  f.ctx.previous_target_lane = 1;
  f.in.end_speed = 22;
  f.in.end_d = 6;
  f.in.target_lane = 1;
  f.in.lon_duration = 3;
  f.in.lat_duration = 3;
  f.Wire();
  return f;
}

// Random, often hostile candidates and traffic (finite values).
Fixture RandomFixture(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Fixture f;
  SetLanes(f.ctx);
  double s = 50 * u(rng), v = 30 * u(rng);
  for (int k = 0; k < kN; ++k) {
    const double a = -8 + 16 * u(rng);
    f.s.push_back(s);
    f.s_d.push_back(v);
    f.s_dd.push_back(a);
    f.d.push_back(-1 + 14 * u(rng));
    f.d_d.push_back(-3 + 6 * u(rng));
    f.d_dd.push_back(-5 + 10 * u(rng));
    s += std::max(v, 0.0) * 0.25;
    v = std::max(0.0, v + a * 0.25);
  }
  const int cars = static_cast<int>(u(rng) * 12);
  for (int c = 0; c < cars; ++c) {
    // Constant speed or braking; staying in lane or moving across.
    const double s0 = -50 + 150 * u(rng), v0 = 25 * u(rng), a = u(rng) < 0.3 ? -8 * u(rng) : 0;
    const double d0 = 12 * u(rng), vd = u(rng) < 0.3 ? -3 + 6 * u(rng) : 0;
    for (int k = 0; k < kN; ++k) {
      const double t = k * 0.25, tb = a < 0 ? std::min(t, v0 / -a) : t;
      f.car_s.push_back(s0 + v0 * tb + 0.5 * a * tb * tb + (v0 + a * tb) * (t - tb));
      f.car_v.push_back(v0 + a * tb);
      f.car_d.push_back(d0 + vd * t);
    }
  }
  if (u(rng) < 0.5) {
    for (int k = 0; k < kN; ++k) {
      f.prev_s.push_back(f.s[k] + 20 * (u(rng) - 0.5));
      f.prev_d.push_back(12 * u(rng));
    }
  }
  f.ctx.current_lane = static_cast<int>(u(rng) * 3);
  f.ctx.previous_target_lane = static_cast<int>(u(rng) * 4) - 1;
  f.ctx.lane_before_change = static_cast<int>(u(rng) * 4) - 1;
  f.ctx.time_since_lane_change = 10 * u(rng);
  f.in.end_speed = v;
  f.in.end_d = f.d.back();
  f.in.target_lane = static_cast<int>(u(rng) * 3);
  f.in.lon_jerk_squared = 1000 * u(rng);
  f.in.lat_jerk_squared = 1000 * u(rng);
  f.in.lon_duration = 1.5 + 4.5 * u(rng);
  f.in.lat_duration = 2 + 2 * u(rng);
  f.in.kind = static_cast<LonKind>(static_cast<int>(u(rng) * 3));
  // Goal regions (a CommonRoad problem's) half the time, with any of their parts absent.
  if (u(rng) < 0.5) {
    const int goals = 1 + static_cast<int>(u(rng) * 2);
    for (int g = 0; g < goals; ++g) {
      GoalRegion r;
      if (u(rng) < 0.7) {
        r.s_lo = 300 * u(rng);
        r.s_hi = r.s_lo + 40 * u(rng);
        r.d_lo = 12 * u(rng);
        r.d_hi = r.d_lo + 4 * u(rng);
      }
      if (u(rng) < 0.8) {
        r.t_lo = -2 + 12 * u(rng);
        r.t_hi = r.t_lo + 5 * u(rng);
      }
      if (u(rng) < 0.5) {
        r.v_lo = 25 * u(rng);
        r.v_hi = r.v_lo + 10 * u(rng);
      }
      if (u(rng) < 0.4) {  // a heading interval, turned off the road's or not
        r.h_lo = -0.5 + u(rng);
        r.h_hi = r.h_lo + 0.4 * u(rng);
      }
      f.goals.push_back(r);
    }
  }
  f.Wire();
  // A two-way road's oncoming lane on the left half the time.
  if (u(rng) < 0.5) f.ctx.oncoming_right = -2 + 6 * u(rng);
  return f;
}

class CostContractTest : public testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<CostTerm> Make() {
    auto made = CostRegistry::Global().Make(GetParam());
    EXPECT_TRUE(made.ok()) << made.message();
    std::unique_ptr<CostTerm> term = std::move(made.value());
    std::vector<double> defaults;
    for (const auto& spec : term->ParamSpecs()) {
      EXPECT_LE(spec.lo, spec.default_value) << spec.key;
      EXPECT_LE(spec.default_value, spec.hi) << spec.key;
      if (spec.log_scale) {
        EXPECT_GT(spec.lo, 0) << spec.key;
      }
      defaults.push_back(spec.default_value);
    }
    term->Configure(defaults);
    return term;
  }
};

TEST_P(CostContractTest, FiniteNonNegativeAndDeterministic) {
  auto term = Make();
  std::mt19937 rng(1234);
  for (int i = 0; i < 2000; ++i) {
    Fixture f = RandomFixture(rng);
    const double a = term->Evaluate(f.ctx, f.in);
    const double b = term->Evaluate(f.ctx, f.in);
    ASSERT_TRUE(std::isfinite(a)) << "case " << i;
    ASSERT_GE(a, 0.0) << "case " << i;
    ASSERT_EQ(a, b) << "case " << i;
    // The bound an expensive term gives in its place: finite, >= 0, never above its value.
    const double lower = term->LowerBound(f.ctx, f.in);
    ASSERT_TRUE(std::isfinite(lower)) << "case " << i;
    ASSERT_GE(lower, 0.0) << "case " << i;
    ASSERT_LE(lower, a) << "case " << i;
  }
}

// The planner's broad-phase masks (CostInput::near_lat / near_lon) only speed a term up: with
// masks of any reach built as documented, every term returns exactly what it returns without.
TEST_P(CostContractTest, BroadPhaseMasksDoNotChangeTheValue) {
  auto term = Make();
  std::mt19937 rng(4321);
  std::uniform_real_distribution<double> u(0, 1);
  int with_cars = 0;
  for (int i = 0; i < 2000; ++i) {
    Fixture f = RandomFixture(rng);
    const double plain = term->Evaluate(f.ctx, f.in);
    // Reaches from tight to loose, so that terms sometimes use a mask and sometimes fall back.
    const double lat[2] = {1 + 3 * u(rng), 4 + 4 * u(rng)};
    const double lon[2] = {2 + 10 * u(rng), 12 + 60 * u(rng)};
    std::vector<std::uint64_t> near_lat(2 * kN, 0), near_lon(2 * kN, 0);
    for (int c = 0; c < f.ctx.num_cars; ++c) {
      for (int k = 0; k < kN; ++k) {
        const double dd = std::abs(f.car_d[c * kN + k] - f.d[k]);
        const double ds = std::abs(f.car_s[c * kN + k] - f.s[k]);
        for (int m = 0; m < 2; ++m) {
          if (dd < lat[m]) near_lat[m * kN + k] |= std::uint64_t{1} << c;
          if (ds < lon[m]) near_lon[m * kN + k] |= std::uint64_t{1} << c;
        }
      }
    }
    for (int m = 0; m < 2; ++m) {
      f.ctx.near_lateral[m] = lat[m];
      f.ctx.near_longitudinal[m] = lon[m];
      f.in.near_lat[m] = near_lat.data() + m * kN;
      f.in.near_lon[m] = near_lon.data() + m * kN;
    }
    with_cars += f.ctx.num_cars > 0 && plain > 0;
    ASSERT_EQ(term->Evaluate(f.ctx, f.in), plain) << "case " << i;
  }
  EXPECT_GT(with_cars, 0);
}

// A term that says it reads only the target lane (LaneOnly) gives the same value for any other
// input bound for that lane: the planner keeps one value per lane and cycle.
// The masks bit by bit as their definition reads: |car - x| < reach, NaN never near, for
// every sample count (the last samples of a block too) and up to 64 cars (more are left out).
TEST(NearMasksTest, EveryBitIsTheDistanceTest) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(-80.0, 80.0);
  for (const int n : {1, 3, 4, 7, 61}) {
    for (const int num_cars : {0, 1, 5, 64, 70}) {
      std::vector<double> x(n), cars(static_cast<std::size_t>(num_cars) * n);
      for (double& v : x) v = pos(rng);
      for (double& v : cars) v = pos(rng);
      if (num_cars > 2 && n > 2) {
        cars[2 * n + 1] = std::nan("");
        x[n - 1] = std::nan("");
        cars[n] = x[0] + kNearLongitudinal[0];  // exactly at the reach: not near
      }
      std::vector<std::uint64_t> near(2 * n, ~std::uint64_t{0});
      FillNearMasks(x.data(), n, num_cars, kNearLongitudinal, cars.data(), n, near.data());
      for (int k = 0; k < n; ++k) {
        for (int m = 0; m < 2; ++m) {
          std::uint64_t want = 0;
          for (int c = 0; c < std::min(num_cars, 64); ++c) {
            const bool in = std::abs(cars[c * n + k] - x[k]) < kNearLongitudinal[m];
            want |= in ? std::uint64_t{1} << c : 0;
          }
          EXPECT_EQ(near[m * n + k], want) << "n " << n << " cars " << num_cars << " k " << k;
        }
      }
    }
  }
}

TEST(CostRegistryTest, LaneOnlyTermsReadNothingButTheTargetLane) {
  int lane_only = 0;
  for (const std::string& name : CostRegistry::Global().Names()) {
    auto made = CostRegistry::Global().Make(name);
    ASSERT_TRUE(made.ok()) << made.message();
    std::unique_ptr<CostTerm> term = std::move(made.value());
    if (!term->LaneOnly()) continue;
    ++lane_only;
    std::vector<double> defaults;
    for (const auto& spec : term->ParamSpecs()) defaults.push_back(spec.default_value);
    term->Configure(defaults);
    std::mt19937 rng(777);
    int distinct = 0;
    for (int i = 0; i < 500; ++i) {
      Fixture f = RandomFixture(rng);
      const Fixture other = RandomFixture(rng);  // another candidate, the same context
      CostInput in = other.in;
      in.target_lane = f.in.target_lane;
      const double v = term->Evaluate(f.ctx, f.in);
      ASSERT_EQ(term->Evaluate(f.ctx, in), v) << name << " case " << i;
      in.target_lane = (f.in.target_lane + 1) % 3;
      distinct += term->Evaluate(f.ctx, in) != v;
    }
    EXPECT_GT(distinct, 0) << name << ": the lane matters";
  }
  EXPECT_GE(lane_only, 1);
}

// CostSet::LowerBound with a lane memo: the same bound and cheap values as without, candidate
// by candidate, while the context stays; after a new context and Clear(), the new values.
TEST(CostSetTest, LaneMemoKeepsTheValues) {
  auto set = CostSet::Build({{"efficiency", 2.0, {}},
                             {"lane_flow", 3.0, {}},
                             {"collision", 10.0, {}},
                             {"lane_change", 1.0, {}}});
  ASSERT_TRUE(set.ok()) << set.message();
  ASSERT_TRUE((*set)->term(1).LaneOnly());
  std::mt19937 rng(31);
  CostSet::LaneMemo memo;
  for (int scene = 0; scene < 20; ++scene) {
    const Fixture f = RandomFixture(rng);
    memo.Clear();
    for (int i = 0; i < 30; ++i) {
      const Fixture g = RandomFixture(rng);
      CostInput in = g.in;
      in.target_lane = i % 3;
      double plain[4], kept[4];
      const double a = (*set)->LowerBound(f.ctx, in, plain);
      const double b = (*set)->LowerBound(f.ctx, in, kept, &memo);
      ASSERT_EQ(a, b) << "scene " << scene << " candidate " << i;
      for (int t = 0; t < 4; ++t) ASSERT_EQ(plain[t], kept[t]);
    }
  }
}

// CostSet::CoarseLowerBound over every registered term: never above LowerBound, and completed
// (CompleteLowerBound) it is LowerBound, bit for bit, with the same cheap values.
TEST(CostSetTest, CoarseBoundCompletesToTheLowerBound) {
  std::vector<CostTermConfig> terms;
  int sampled = 0;
  for (const std::string& name : CostRegistry::Global().Names()) {
    terms.push_back({name, 0.5 + terms.size(), {}});
    auto made = CostRegistry::Global().Make(name);
    ASSERT_TRUE(made.ok()) << made.message();
    sampled += (*made)->Sampled() && !(*made)->Expensive();
  }
  EXPECT_GE(sampled, 1);
  auto set = CostSet::Build(terms);
  ASSERT_TRUE(set.ok()) << set.message();
  const int n = (*set)->size();
  std::mt19937 rng(57);
  CostSet::LaneMemo memo;
  for (int i = 0; i < 500; ++i) {
    const Fixture f = RandomFixture(rng);
    memo.Clear();
    std::vector<double> plain(n), coarse(n, -1.0);
    const double lower = (*set)->LowerBound(f.ctx, f.in, plain.data());
    const double bound = (*set)->CoarseLowerBound(f.ctx, f.in, coarse.data(), &memo);
    if (std::isnan(lower)) {
      EXPECT_TRUE(std::isnan((*set)->CompleteLowerBound(f.ctx, f.in, coarse.data())));
      continue;
    }
    ASSERT_FALSE(std::isnan(bound)) << "case " << i;
    ASSERT_LE(bound, lower) << "case " << i;
    for (int t = 0; t < n; ++t) {
      const CostTerm& term = (*set)->term(t);
      if (term.Sampled() || term.Expensive()) {
        ASSERT_EQ(coarse[t], 0.0) << (*set)->name(t);
      }
    }
    ASSERT_EQ((*set)->CompleteLowerBound(f.ctx, f.in, coarse.data()), lower) << "case " << i;
    for (int t = 0; t < n; ++t) ASSERT_EQ(coarse[t], plain[t]) << (*set)->name(t);
  }
}

// CostSet::SumOf over every registered term: from the bound's values (each expensive term's
// LowerBound) it is LowerBound, with some expensive terms' values in a bound between LowerBound
// and Evaluate, with all of them Evaluate, each bit for bit where it is equal.
TEST(CostSetTest, SumOfClimbsFromTheLowerBoundToTheCost) {
  std::vector<CostTermConfig> terms;
  for (const std::string& name : CostRegistry::Global().Names()) {
    terms.push_back({name, 0.5 + terms.size(), {}});
  }
  auto set = CostSet::Build(terms);
  ASSERT_TRUE(set.ok()) << set.message();
  const int n = (*set)->size();
  const std::vector<int>& expensive = (*set)->expensive_terms();
  ASSERT_GE(expensive.size(), 2u);
  for (int t = 0; t < n; ++t) {
    const bool listed = std::find(expensive.begin(), expensive.end(), t) != expensive.end();
    EXPECT_EQ(listed, (*set)->term(t).Expensive()) << (*set)->name(t);
  }
  std::mt19937 rng(91);
  int between = 0;
  for (int i = 0; i < 500; ++i) {
    const Fixture f = RandomFixture(rng);
    std::vector<double> values(n), bounds(n);
    const double cost = (*set)->Evaluate(f.ctx, f.in, values.data());
    const double lower = (*set)->LowerBound(f.ctx, f.in, bounds.data());
    if (std::isnan(cost)) continue;
    ASSERT_EQ((*set)->SumOf(bounds.data()), lower) << "case " << i;
    ASSERT_EQ((*set)->SumOf(values.data()), cost) << "case " << i;
    for (int t : expensive) ASSERT_LE(bounds[t], values[t]) << (*set)->name(t) << " case " << i;
    bounds[expensive.back()] = values[expensive.back()];
    const double one = (*set)->SumOf(bounds.data());
    ASSERT_LE(lower, one) << "case " << i;
    ASSERT_LE(one, cost) << "case " << i;
    between += lower < one && one < cost;
  }
  EXPECT_GT(between, 0) << "some partial sums lie strictly between";
}

TEST_P(CostContractTest, NearZeroOnIdealLaneKeeping) {
  auto term = Make();
  Fixture f = IdealLaneKeeping();
  EXPECT_NEAR(term->Evaluate(f.ctx, f.in), 0.0, 1e-6);
}

TEST_P(CostContractTest, DetectsSomethingOnHostileInputs) {
  // A term that is 0 everywhere measures nothing: some random case must give a positive value.
  auto term = Make();
  std::mt19937 rng(99);
  double max_value = 0;
  for (int i = 0; i < 500; ++i) {
    Fixture f = RandomFixture(rng);
    max_value = std::max(max_value, term->Evaluate(f.ctx, f.in));
  }
  EXPECT_GT(max_value, 0.0);
}

INSTANTIATE_TEST_SUITE_P(AllRegistered, CostContractTest,
                         testing::ValuesIn(CostRegistry::Global().Names()),
                         [](const testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(CostRegistryTest, RegisteredNamesEqualConfigNames) {
  const YAML::Node root = YAML::LoadFile(FRENETIC_SOURCE_DIR "/config/planner.yaml");
  std::set<std::string> config_names;
  for (const auto& kv : root["costs"]) config_names.insert(kv.first.as<std::string>());
  const std::vector<std::string> registered = CostRegistry::Global().Names();
  EXPECT_EQ(std::set<std::string>(registered.begin(), registered.end()), config_names);
  EXPECT_GE(registered.size(), 8u);
}

TEST(CostRegistryTest, UnknownTermIsAnErrorNamingIt) {
  auto made = CostRegistry::Global().Make("warp_drive");
  ASSERT_FALSE(made.ok());
  EXPECT_NE(made.message().find("warp_drive"), std::string::npos);
}

TEST(CostSetTest, WeightedSumInConfigOrderAndErrors) {
  auto set = CostSet::Build({{"efficiency", 2.0, {}}, {"lane_change", 3.0, {{"switch_back", 1.0}}}});
  ASSERT_TRUE(set.ok()) << set.message();
  ASSERT_EQ((*set)->size(), 2);
  EXPECT_EQ((*set)->name(0), "efficiency");
  Fixture f = IdealLaneKeeping();
  f.in.end_speed = 11;  // half the limit
  f.in.target_lane = 0;  // a lane change
  double per[2];
  const double total = (*set)->Evaluate(f.ctx, f.in, per);
  EXPECT_GT(per[0], 0);
  EXPECT_EQ(per[1], 1.0);
  EXPECT_DOUBLE_EQ(total, 2 * per[0] + 3 * per[1]);

  auto bad_key = CostSet::Build({{"jerk", 1.0, {{"colour", 1.0}}}});
  ASSERT_FALSE(bad_key.ok());
  EXPECT_NE(bad_key.message().find("colour"), std::string::npos);
  auto bad_value = CostSet::Build({{"jerk", 1.0, {{"scale", -1.0}}}});
  ASSERT_FALSE(bad_value.ok());
  EXPECT_NE(bad_value.message().find("jerk.scale"), std::string::npos);
  auto bad_weight = CostSet::Build({{"jerk", std::nan(""), {}}});
  EXPECT_FALSE(bad_weight.ok());
}

TEST(CostBehaviourTest, TermsRankTheObviousChoices) {
  auto collision = CostRegistry::Global().Make("collision");
  auto buffer = CostRegistry::Global().Make("buffer");
  ASSERT_TRUE(collision.ok() && buffer.ok());
  std::vector<double> c_def{0.5, 2.0}, b_def{8.0, 1.2};
  (*collision)->Configure(c_def);
  (*buffer)->Configure(b_def);
  Fixture f = IdealLaneKeeping();
  // A stopped car 30 m ahead in the ego's lane: the lane-keeping candidate runs into it.
  for (int k = 0; k < kN; ++k) {
    f.car_s.push_back(130);
    f.car_d.push_back(6);
    f.car_v.push_back(0);
  }
  f.Wire();
  EXPECT_GT((*collision)->Evaluate(f.ctx, f.in), 0.02);
  EXPECT_GT((*buffer)->Evaluate(f.ctx, f.in), 0.1);
  // The same car in the next lane is harmless.
  for (double& d : f.car_d) d = 10;
  EXPECT_EQ((*collision)->Evaluate(f.ctx, f.in), 0.0);
  EXPECT_EQ((*buffer)->Evaluate(f.ctx, f.in), 0.0);
  // ...unless it is predicted to move into the ego's lane: from 10 to 6 over the first second.
  for (int k = 0; k < kN; ++k) f.car_d[k] = std::max(6.0, 10 - 4 * k * 0.25);
  EXPECT_GT((*collision)->Evaluate(f.ctx, f.in), 0.02);
  EXPECT_GT((*buffer)->Evaluate(f.ctx, f.in), 0.1);
}

}  // namespace
}  // namespace frenetic::cost

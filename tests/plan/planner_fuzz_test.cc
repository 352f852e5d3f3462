// The planners under corrupted telemetry (never a throw, always a drivable finite path) and the
// baseline planner's walkthrough drive, in the closed loop of closed_loop_testing.h.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>

#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/sanitizers.h"
#include "frenetic/units.h"
#include "plan/closed_loop_testing.h"

namespace frenetic::plan {
namespace {

using closed_loop::Config;
using closed_loop::Loop;
using closed_loop::Make;
using closed_loop::RunFor;
using closed_loop::WorstSlidingMeasure;

// Corrupts a plausible telemetry in one of many ways.
Telemetry Corrupt(Telemetry t, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const double wild[] = {nan, inf, -inf, 1e300, -1e300, 0, 1e7, -5};
  auto pick = [&] { return wild[rng() % 8]; };
  const int kind = static_cast<int>(rng() % 12);
  switch (kind) {
    case 0:
      t.x = pick();
      break;
    case 1:
      t.y = pick();
      t.yaw = pick();
      break;
    case 2:
      t.speed = pick();
      break;
    case 3:
      t.previous_path_x.clear();
      t.previous_path_y.clear();
      break;
    case 4:
      if (!t.previous_path_x.empty()) t.previous_path_x.pop_back();
      break;
    case 5:
      for (auto& v : t.previous_path_x) v += 50 * (u(rng) - 0.5);
      break;
    case 6:
      if (!t.previous_path_y.empty()) t.previous_path_y[rng() % t.previous_path_y.size()] = pick();
      break;
    case 7:
      t.sensor_fusion.clear();
      break;
    case 8:
      for (auto& c : t.sensor_fusion) {
        c.x = u(rng) < 0.3 ? pick() : c.x;
        c.vx = u(rng) < 0.3 ? pick() : c.vx;
        c.s = 0;
        c.d = 0;
      }
      break;
    case 9:
      for (int i = 0; i < 40; ++i) {
        t.sensor_fusion.push_back({static_cast<int>(rng() % 5), t.x + 100 * (u(rng) - 0.5),
                                   t.y + 100 * (u(rng) - 0.5), 60 * u(rng), 60 * u(rng), 0, 0});
      }
      break;
    case 10:
      t.previous_path_x.assign(rng() % 300, u(rng) * 3000);
      t.previous_path_y.assign(t.previous_path_x.size(), u(rng) * 3000);
      break;
    default:
      t.x += 200 * (u(rng) - 0.5);
      t.y += 200 * (u(rng) - 0.5);
      break;
  }
  return t;
}

class FuzzTest : public testing::TestWithParam<std::string> {};

TEST_P(FuzzTest, NeverThrowsAndAlwaysReturnsFiftyFinitePoints) {
  REQUIRE_MAP(line);
  // Robustness does not need the full lattice: a small grid and a short refinement keep the
  // 10,000 cycles within a few seconds (the defaults are exercised by the scenario tests). Under
  // the sanitizers, which run the same code several times slower, 2,500 cycles.
  PlannerConfig config = Config();
  for (const auto& [key, value] : {std::pair<const char*, double>{"grid.speeds", 8},
                                   {"grid.durations", 4},
                                   {"grid.follow_gaps", 1},
                                   {"grid.lat_durations", 1},
                                   {"refine.max_iterations", 4}}) {
    ASSERT_TRUE(config.Set(key, value).ok()) << key;
  }
  auto made = MakePlanner(GetParam(), config, line);
  ASSERT_TRUE(made.ok()) << made.message();
  std::unique_ptr<Planner> planner = std::move(made).value();
  std::mt19937 rng(2024);
  Loop loop(line, planner.get(), 3000, 6.0, 18.0, 8);
  loop.cars.push_back({0, 3040, 6.0, 12.0});
  loop.cars.push_back({1, 3020, 2.0, 22.0});
  int invalid = 0;
  const int cycles = kUnderSanitizer ? 2500 : 10000;
  for (int i = 0; i < cycles; ++i) {
    if (i % 50 == 0) loop.Cycle();  // keep a live state now and then
    ASSERT_FALSE(HasFatalFailure());
    const Telemetry t = Corrupt(loop.Make(), rng);
    const PlanResult* r = nullptr;
    ASSERT_NO_THROW(r = &planner->Plan(t)) << "case " << i;
    ASSERT_GE(r->x.size(), static_cast<size_t>(kMinPathPoints)) << "case " << i;
    ASSERT_EQ(r->x.size(), r->y.size());
    for (size_t k = 0; k < r->x.size(); ++k) {
      ASSERT_TRUE(std::isfinite(r->x[k]) && std::isfinite(r->y[k])) << "case " << i;
    }
    invalid += r->status == PlanStatus::kInvalidInput;
  }
  EXPECT_GT(invalid, 0);
}

INSTANTIATE_TEST_SUITE_P(BothPlanners, FuzzTest, testing::Values("search", "baseline"));

TEST(BaselinePlannerTest, DrivesAndOvertakesLikeTheWalkthrough) {
  REQUIRE_MAP(line);
  auto planner = Make("baseline", line);
  Loop loop(line, planner.get(), 124.83, 6.0, 0.0, 9);
  RunFor(loop, 25.0);
  EXPECT_GT(loop.speed(), 45 * units::kMphToMps);
  EXPECT_LT(WorstSlidingMeasure(loop, 0).max_speed, 50 * units::kMphToMps);
  loop.cars.push_back({0, loop.s() + 40, 6.0, 12.0});
  RunFor(loop, 15.0);
  EXPECT_FALSE(loop.collided);
  const double d = loop.d();
  EXPECT_TRUE(d < 4.0 || d > 8.0) << "baseline did not overtake, d = " << d;
}

}  // namespace
}  // namespace frenetic::plan

// The suite file: strict keys (named with the file in every error), bounds checked against the
// planner's declared parameters, and the unit-box mapping of the search.
#include "frenetic/tune/suite.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace frenetic::tune {
namespace {

using ::testing::HasSubstr;

constexpr char kMinimal[] = R"(
scenarios: [udacity]
train_seeds: [1]
holdout_seeds: [2]
episode_seconds: 20
params:
  weights.efficiency: {lo: 0.1, hi: 10, scale: log}
)";

TEST(SuiteTest, BundledSuitesLoadAndValidate) {
  for (const char* name : {"smoke", "default"}) {
    const std::string path = std::string(FRENETIC_SOURCE_DIR "/config/tune/") + name + ".yaml";
    auto suite = LoadSuite(path);
    ASSERT_TRUE(suite.ok()) << suite.message();
    EXPECT_FALSE(suite->scenarios.empty());
    EXPECT_FALSE(suite->params.empty());
    auto config = LoadStartConfig(*suite);
    ASSERT_TRUE(config.ok()) << config.message();
  }
  auto smoke = LoadSuite(std::string(FRENETIC_SOURCE_DIR "/config/tune/smoke.yaml"));
  ASSERT_TRUE(smoke.ok());
  auto start = LoadStartConfig(*smoke);
  ASSERT_TRUE(start.ok());
  // The smoke suite starts from a deliberately poor efficiency weight.
  EXPECT_DOUBLE_EQ(start->value("weights.efficiency"), 0.02);
}

TEST(SuiteTest, ParsesEveryField) {
  auto suite = ParseSuite(R"(
map: tracks/loop.csv
planner: baseline
scenarios: [udacity, my/cut.yaml]
train_seeds: [3, 4]
holdout_seeds: [9]
episode_seconds: 30
start_config: poor.yaml
start_set: {weights.buffer: 2}
deterministic: false
latency: random
params:
  weights.efficiency: {lo: 0.1, hi: 10, scale: log}
  grid.follow_tau: {lo: 0.8, hi: 2}
objective:
  incidents_per_mile: {collision: 7}
  speed: 2
  speed_target_mph: 48
  comfort: 0.25
  headway: 3
  headway_target_s: 1.5
search: {global: GN_CRS2_LM, local: LN_SBPLX, budget: 9, global_fraction: 0.5, seed: 7,
         initial_step: 0.3}
)", "s.yaml", "/base");
  ASSERT_TRUE(suite.ok()) << suite.message();
  EXPECT_EQ(suite->map_path, "/base/tracks/loop.csv");
  EXPECT_EQ(suite->planner, "baseline");
  EXPECT_EQ(suite->scenarios, (std::vector<std::string>{"udacity", "/base/my/cut.yaml"}));
  EXPECT_EQ(suite->train_seeds, (std::vector<std::uint64_t>{3, 4}));
  EXPECT_EQ(suite->holdout_seeds, (std::vector<std::uint64_t>{9}));
  EXPECT_EQ(suite->episode_seconds, 30);
  EXPECT_EQ(suite->start_config, "/base/poor.yaml");
  ASSERT_EQ(suite->start_set.size(), 1u);
  EXPECT_EQ(suite->start_set[0].first, "weights.buffer");
  EXPECT_FALSE(suite->deterministic);
  EXPECT_EQ(suite->latency, "random");
  ASSERT_EQ(suite->params.size(), 2u);
  EXPECT_EQ(suite->params[0].key, "weights.efficiency");
  EXPECT_TRUE(suite->params[0].log_scale);
  EXPECT_EQ(suite->params[1].key, "grid.follow_tau");
  EXPECT_FALSE(suite->params[1].log_scale);
  EXPECT_EQ(suite->objective.incidents_per_mile[static_cast<int>(sim::IncidentKind::kCollision)], 7);
  EXPECT_EQ(suite->objective.incidents_per_mile[static_cast<int>(sim::IncidentKind::kJerk)], 0);
  EXPECT_EQ(suite->objective.speed, 2);
  EXPECT_EQ(suite->objective.headway_target_s, 1.5);
  EXPECT_EQ(suite->search.global_algorithm, "GN_CRS2_LM");
  EXPECT_EQ(suite->search.local_algorithm, "LN_SBPLX");
  EXPECT_EQ(suite->search.budget, 9);
  EXPECT_EQ(suite->search.seed, 7u);
}

struct BadSuiteCase {
  const char* yaml;
  const char* expected;  // must appear in the message, next to the file name
};

class BadSuiteTest : public ::testing::TestWithParam<BadSuiteCase> {};

TEST_P(BadSuiteTest, FailsNamingTheKeyAndFile) {
  auto suite = ParseSuite(std::string(kMinimal) + GetParam().yaml, "bad_suite.yaml", "");
  std::string message;
  if (suite.ok()) {
    auto config = LoadStartConfig(*suite);  // parameter keys are checked against the planner
    ASSERT_FALSE(config.ok()) << "accepted: " << GetParam().yaml;
    message = config.message();
  } else {
    message = suite.message();
  }
  EXPECT_THAT(message, HasSubstr("bad_suite.yaml"));
  EXPECT_THAT(message, HasSubstr(GetParam().expected));
  EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadSuiteTest,
    ::testing::Values(
        BadSuiteCase{"budgett: 3\n", "budgett"},
        BadSuiteCase{"objective: {speed: 1, sped: 2}\n", "objective.sped"},
        BadSuiteCase{"objective: {incidents_per_mile: {colision: 1}}\n", "colision"},
        BadSuiteCase{"search: {global: GN_DIRECT_L, budgte: 3}\n", "search.budgte"},
        BadSuiteCase{"search: {global: LN_SBPLX}\n", "search.global"},
        BadSuiteCase{"search: {budget: 1}\n", "search.budget"},
        BadSuiteCase{"search: {global_fraction: 1.5}\n", "global_fraction"},
        BadSuiteCase{"start_set: {weights.nonsense: 1}\n", "weights.nonsense"},
        BadSuiteCase{"latency: sometimes\n", "latency"}),
    [](const auto& info) { return "Case" + std::to_string(info.index); });

TEST(SuiteTest, UnknownParameterIsNamed) {
  auto suite = ParseSuite(R"(
scenarios: [udacity]
train_seeds: [1]
holdout_seeds: [2]
params:
  weights.teleport: {lo: 0.1, hi: 10}
)", "odd.yaml", "");
  ASSERT_TRUE(suite.ok()) << suite.message();
  auto config = LoadStartConfig(*suite);
  ASSERT_FALSE(config.ok());
  EXPECT_THAT(config.message(), HasSubstr("odd.yaml"));
  EXPECT_THAT(config.message(), HasSubstr("params.weights.teleport"));
}

TEST(SuiteTest, RejectsBadParameterDeclarations) {
  const std::string head = "scenarios: [udacity]\ntrain_seeds: [1]\nholdout_seeds: [2]\n";
  struct Case {
    std::string params, expected;
  } cases[] = {
      {"params: {weights.jerk: {lo: 0, hi: 5, scale: log}}", "lo > 0"},
      {"params: {weights.jerk: {lo: 5, hi: 1}}", "lo < hi"},
      {"params: {weights.jerk: {lo: 1}}", "needs lo and hi"},
      {"params: {weights.jerk: {lo: 1, hi: 2, scale: cubic}}", "params.weights.jerk.scale"},
      {"params: {weights.jerk: {lo: 1, hi: 2, step: 1}}", "params.weights.jerk.step"},
  };
  for (const Case& c : cases) {
    auto suite = ParseSuite(head + c.params, "p.yaml", "");
    ASSERT_FALSE(suite.ok()) << c.params;
    EXPECT_THAT(suite.message(), HasSubstr("p.yaml")) << c.params;
    EXPECT_THAT(suite.message(), HasSubstr(c.expected)) << c.params;
  }
  auto overlap = ParseSuite("scenarios: [udacity]\ntrain_seeds: [1, 2]\nholdout_seeds: [2]\n"
                            "params: {weights.jerk: {lo: 1, hi: 2}}", "o.yaml", "");
  ASSERT_FALSE(overlap.ok());
  EXPECT_THAT(overlap.message(), HasSubstr("training seed 2"));
}

TEST(SuiteTest, BoundsMustLieInTheDeclaredRange) {
  auto suite = ParseSuite(R"(
scenarios: [udacity]
train_seeds: [1]
holdout_seeds: [2]
params:
  weights.efficiency: {lo: 0.1, hi: 1.0e9, scale: log}
)", "wide.yaml", "");
  ASSERT_TRUE(suite.ok()) << suite.message();
  auto config = LoadStartConfig(*suite);
  ASSERT_FALSE(config.ok());
  EXPECT_THAT(config.message(), HasSubstr("params.weights.efficiency"));
  EXPECT_THAT(config.message(), HasSubstr("declared range"));
}

TEST(SuiteTest, MissingFileIsNamed) {
  auto suite = LoadSuite("/nonexistent/suite.yaml");
  ASSERT_FALSE(suite.ok());
  EXPECT_THAT(suite.message(), HasSubstr("/nonexistent/suite.yaml"));
}

TEST(TunedParamTest, UnitMappingLinearAndLog) {
  TunedParam lin{"k", 2, 6, false};
  EXPECT_DOUBLE_EQ(lin.FromUnit(0), 2);
  EXPECT_DOUBLE_EQ(lin.FromUnit(0.25), 3);
  EXPECT_DOUBLE_EQ(lin.FromUnit(1), 6);
  EXPECT_DOUBLE_EQ(lin.FromUnit(7), 6);  // clamped
  EXPECT_DOUBLE_EQ(lin.ToUnit(5), 0.75);
  TunedParam log{"k", 0.1, 10, true};
  EXPECT_NEAR(log.FromUnit(0.5), 1.0, 1e-12);  // the geometric middle
  EXPECT_NEAR(log.FromUnit(0.75), std::sqrt(10.0), 1e-12);
  for (double x : {0.0, 0.1, 0.37, 0.9, 1.0}) {
    EXPECT_NEAR(log.ToUnit(log.FromUnit(x)), x, 1e-12);
    EXPECT_NEAR(lin.ToUnit(lin.FromUnit(x)), x, 1e-12);
  }
  EXPECT_DOUBLE_EQ(log.ToUnit(1e-9), 0);  // clamped to lo
}

}  // namespace
}  // namespace frenetic::tune

#include "frenetic/plan/planner_config.h"

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "frenetic/cost/cost_registry.h"

namespace frenetic::plan {
namespace {

std::string DefaultYaml() {
  std::ifstream in(PlannerConfig::DefaultPath());
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(PlannerConfigTest, LoadsTheShippedFile) {
  auto c = PlannerConfig::LoadDefault();
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_DOUBLE_EQ(c->budget_ms(), 15);
  EXPECT_DOUBLE_EQ(*c->Get("limits.max_speed_mph"), 49.8);
  EXPECT_DOUBLE_EQ(*c->Get("weights.collision"), 10);
  EXPECT_EQ(c->refine_algorithm(), "LN_COBYLA");
  const auto terms = c->cost_terms();
  ASSERT_FALSE(terms.empty());
  EXPECT_EQ(terms.front().name, "collision");  // config order, not alphabetical
  EXPECT_EQ(terms.size(), cost::CostRegistry::Global().Names().size());
}

TEST(PlannerConfigTest, UnknownKeyIsAnErrorNamingKeyAndFile) {
  auto d = PlannerConfig::Parse("limits:\n  max_sped: 3\ncosts: {}\n", "my.yaml");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.message().find("limits.max_sped"), std::string::npos) << d.message();
  EXPECT_NE(d.message().find("my.yaml"), std::string::npos) << d.message();
  auto e = PlannerConfig::Parse("warp:\n  factor: 9\n", "x.yaml");
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.message().find("warp"), std::string::npos) << e.message();
}

TEST(PlannerConfigTest, UnknownCostTermAndParameterAreErrors) {
  std::string yaml = DefaultYaml();
  std::string with_term = yaml;
  with_term.replace(with_term.find("  collision:\n"), 13, "  colision:\n");
  auto t = PlannerConfig::Parse(with_term, "b.yaml");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("colision"), std::string::npos) << t.message();
  std::string with_param = yaml;
  with_param.replace(with_param.find("    margin: 0.5"), 15, "    margn: 0.5");
  auto p = PlannerConfig::Parse(with_param, "c.yaml");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.message().find("costs.collision.margn"), std::string::npos) << p.message();
}

TEST(PlannerConfigTest, MissingWeightIsAnError) {
  std::string yaml = DefaultYaml();
  // efficiency loses its weight line (whatever its value and comment).
  const size_t term = yaml.find("  efficiency:\n");
  ASSERT_NE(term, std::string::npos);
  const size_t weight = yaml.find("    weight:", term);
  ASSERT_NE(weight, std::string::npos);
  yaml.erase(weight, yaml.find('\n', weight) + 1 - weight);
  auto c = PlannerConfig::Parse(yaml, "w.yaml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.message().find("efficiency"), std::string::npos) << c.message();
  EXPECT_NE(c.message().find("weight"), std::string::npos) << c.message();
  // A term left out entirely is a missing weight too.
  std::string dropped = DefaultYaml();
  const size_t at = dropped.find("  consistency:\n");
  ASSERT_NE(at, std::string::npos);
  // The term's block: its header and every deeper-indented line after it.
  size_t end = dropped.find('\n', at) + 1;
  while (end < dropped.size() && dropped.compare(end, 4, "    ") == 0) {
    end = dropped.find('\n', end);
    end = end == std::string::npos ? dropped.size() : end + 1;
  }
  dropped.erase(at, end - at);
  auto d = PlannerConfig::Parse(dropped, "w.yaml");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.message().find("consistency"), std::string::npos) << d.message();
}

TEST(PlannerConfigTest, SetGetRangesAndRoundTrip) {
  auto c = PlannerConfig::LoadDefault();
  ASSERT_TRUE(c.ok());
  EXPECT_TRUE(c->Set("weights.efficiency", 7.5).ok());
  EXPECT_DOUBLE_EQ(*c->Get("weights.efficiency"), 7.5);
  EXPECT_TRUE(c->Set("costs.buffer.headway", 2.0).ok());
  Status bad = c->Set("limits.max_speed_mph", 130);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("limits.max_speed_mph"), std::string::npos);
  // A last resort at or under the checks' own lane-line limit would relax nothing.
  Status low = c->Set("check.last_resort_ticks", 14);
  ASSERT_FALSE(low.ok());
  EXPECT_NE(low.message().find("check.last_resort_ticks"), std::string::npos);
  EXPECT_DOUBLE_EQ(*c->Get("check.last_resort_ticks"), 145);
  EXPECT_TRUE(c->Set("check.last_resort_ticks", 0).ok());
  EXPECT_TRUE(c->Set("check.last_resort_ticks", 145).ok());
  Status unknown = c->Set("weights.nonsense", 1);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("weights.nonsense"), std::string::npos);
  EXPECT_FALSE(c->Get("no.such").ok());

  auto back = PlannerConfig::Parse(c->ToYaml(), "roundtrip");
  ASSERT_TRUE(back.ok()) << back.message() << "\n" << c->ToYaml();
  const auto a = c->Params(), b = back->Params();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].key, b[i].key);
    EXPECT_DOUBLE_EQ(a[i].value, b[i].value) << a[i].key;
  }
  EXPECT_EQ(back->refine_algorithm(), c->refine_algorithm());
}

TEST(PlannerConfigTest, ParamsCoverWeightsAndHaveSaneRanges) {
  auto c = PlannerConfig::LoadDefault();
  ASSERT_TRUE(c.ok());
  int weights = 0;
  for (const auto& p : c->Params()) {
    EXPECT_LE(p.lo, p.value) << p.key;
    EXPECT_LE(p.value, p.hi) << p.key;
    EXPECT_LT(p.lo, p.hi) << p.key;
    if (p.log_scale) {
      EXPECT_GT(p.lo, 0) << p.key;
    }
    if (p.key.rfind("weights.", 0) == 0) ++weights;
  }
  EXPECT_EQ(weights, static_cast<int>(cost::CostRegistry::Global().Names().size()));
  EXPECT_NE(PlannerConfig::Load("/nonexistent/planner.yaml").message().find("/nonexistent"),
            std::string::npos);
  auto broken = PlannerConfig::Parse("limits: [1, 2", "broken.yaml");
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.message().find("broken.yaml"), std::string::npos);
  auto text = PlannerConfig::Parse("budget_ms: fast\n", "t.yaml");
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.message().find("budget_ms"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::plan

namespace frenetic::plan {
namespace {

TEST(PlannerConfigOverlayTest, SetsTheKeysItNamesAndOnlyThose) {
  auto c = PlannerConfig::LoadDefault();
  ASSERT_TRUE(c.ok()) << c.message();
  const double jerk = c->value("weights.jerk");
  ASSERT_TRUE(c->Overlay("limits:\n  max_speed_mph: 70\ncosts:\n  goal:\n    weight: 12\n"
                         "    s_scale: 4\ngrid:\n  gap_targets: 2\n",
                         "overlay.yaml")
                  .ok());
  EXPECT_EQ(c->value("limits.max_speed_mph"), 70);
  EXPECT_EQ(c->value("weights.goal"), 12);
  EXPECT_EQ(c->value("costs.goal.s_scale"), 4);
  EXPECT_EQ(c->int_value("grid.gap_targets"), 2);
  EXPECT_EQ(c->value("weights.jerk"), jerk);
  EXPECT_TRUE(c->Overlay("", "empty.yaml").ok());
  // The shipped CommonRoad overlay applies.
  EXPECT_TRUE(c->OverlayFile(FRENETIC_SOURCE_DIR "/config/commonroad.yaml").ok());
}

TEST(PlannerConfigOverlayTest, AnErrorNamesFileAndKeyAndChangesNothing) {
  auto c = PlannerConfig::LoadDefault();
  ASSERT_TRUE(c.ok()) << c.message();
  const std::string before = c->ToYaml();
  struct Case {
    const char* yaml;
    const char* needle;
  };
  const Case cases[] = {
      {"limits:\n  max_speed_mph: 60\n  max_sped: 3\n", "over.yaml: unknown key 'limits.max_sped'"},
      {"limits:\n  max_speed_mph: 60\ngrid:\n  speeds: 1000\n", "'grid.speeds' = 1000 outside"},
      {"costs:\n  goal:\n    wieght: 3\n", "unknown key 'costs.goal.wieght'"},
      {"check:\n  margin_s: fast\n", "'check.margin_s' must be a number"},
      {"[1, 2]", "expected a mapping"},
      {"limits: {max_speed_mph: 60", "YAML error"},
  };
  for (const Case& k : cases) {
    const Status st = c->Overlay(k.yaml, "over.yaml");
    ASSERT_FALSE(st.ok()) << k.yaml;
    EXPECT_NE(st.message().find(k.needle), std::string::npos) << st.message();
    EXPECT_EQ(st.message().find('\n'), std::string::npos) << st.message();
    EXPECT_EQ(c->ToYaml(), before) << "changed by " << k.yaml;
  }
  const Status missing = c->OverlayFile("/nonexistent/over.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("/nonexistent/over.yaml"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::plan

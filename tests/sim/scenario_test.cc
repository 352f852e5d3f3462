#include "frenetic/sim/scenario.h"

#include <gtest/gtest.h>

namespace frenetic::sim {
namespace {

TEST(Scenario, EveryBundledScenarioLoads) {
  const auto names = ScenarioNames();
  for (const char* required : {"udacity", "dense", "cut-in", "hard-brake", "blocked", "seam"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
  for (const auto& name : names) {
    auto sc = LoadScenario(name);
    ASSERT_TRUE(sc.ok()) << sc.message();
    EXPECT_EQ(sc->name, name);
  }
  auto dense = LoadScenario("dense");
  ASSERT_TRUE(dense.ok());
  EXPECT_EQ(dense->traffic.cars, 24);
  auto seam = LoadScenario("seam");
  ASSERT_TRUE(seam.ok());
  EXPECT_EQ(seam->start.kind, StartPose::Kind::kFrenet);
  EXPECT_EQ(seam->start.s, -150);
  EXPECT_EQ(seam->start.d, 6);
  auto blocked = LoadScenario("blocked");
  ASSERT_TRUE(blocked.ok());
  EXPECT_TRUE(blocked->traffic.blockade);
}

TEST(Scenario, DefaultsAreTheFaithfulSimulator) {
  auto sc = ParseScenario("{}", "empty.yaml");
  ASSERT_TRUE(sc.ok()) << sc.message();
  EXPECT_EQ(sc->name, "empty");
  EXPECT_EQ(sc->traffic.cars, 12);
  EXPECT_EQ(sc->timing.mode, TimingOptions::Mode::kLockstep);
  EXPECT_EQ(sc->car_length, 4.6);
  EXPECT_EQ(sc->car_width, 2.4);
  EXPECT_EQ(sc->start.kind, StartPose::Kind::kAuto);
}

TEST(Scenario, UnknownKeysAreErrorsNamingFileAndKey) {
  auto top = ParseScenario("name: x\nspeed: 3\n", "a.yaml");
  ASSERT_FALSE(top.ok());
  EXPECT_NE(top.message().find("a.yaml"), std::string::npos);
  EXPECT_NE(top.message().find("'speed'"), std::string::npos);
  auto nested = ParseScenario("traffic:\n  cut_in:\n    rte: 1\n", "b.yaml");
  ASSERT_FALSE(nested.ok());
  EXPECT_NE(nested.message().find("b.yaml"), std::string::npos) << nested.message();
  EXPECT_NE(nested.message().find("traffic.cut_in.rte"), std::string::npos) << nested.message();
}

TEST(Scenario, BadValuesNameTheKey) {
  auto type = ParseScenario("traffic: {brake_decel: fast}", "c.yaml");
  ASSERT_FALSE(type.ok());
  EXPECT_NE(type.message().find("traffic.brake_decel"), std::string::npos) << type.message();
  auto range = ParseScenario("traffic: {brake_decel: -1}", "c.yaml");
  ASSERT_FALSE(range.ok());
  EXPECT_NE(range.message().find("brake_decel"), std::string::npos) << range.message();
  auto mode = ParseScenario("timing: {mode: sometimes}", "c.yaml");
  ASSERT_FALSE(mode.ok());
  EXPECT_NE(mode.message().find("timing.mode"), std::string::npos) << mode.message();
  auto pair = ParseScenario("traffic: {batch: [3]}", "c.yaml");
  ASSERT_FALSE(pair.ok());
  EXPECT_NE(pair.message().find("traffic.batch"), std::string::npos) << pair.message();
  auto syntax = ParseScenario("traffic: [", "c.yaml");
  ASSERT_FALSE(syntax.ok());
  EXPECT_NE(syntax.message().find("c.yaml"), std::string::npos);
  auto both = ParseScenario("start: {x: 1, y: 2, s: 3}", "c.yaml");
  EXPECT_FALSE(both.ok());
}

TEST(Scenario, LoadScenarioErrors) {
  auto unknown = LoadScenario("no-such-scenario");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("no-such-scenario"), std::string::npos);
  EXPECT_NE(unknown.message().find("udacity"), std::string::npos);  // lists the known ones
  auto missing = LoadScenario("/nonexistent/dir/x.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("/nonexistent/dir/x.yaml"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::sim

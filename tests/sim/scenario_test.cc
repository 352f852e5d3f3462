#include "frenetic/sim/scenario.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace frenetic::sim {
namespace {

TEST(Scenario, EveryBundledScenarioLoads) {
  const auto names = ScenarioNames();
  for (const char* required :
       {"udacity", "dense", "cut-in", "hard-brake", "blocked", "seam", "free"}) {
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
  auto empty = LoadScenario("free");
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->traffic.cars, 0);
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

TEST(Scenario, BundledScenariosBuildOnTheCalibratedUdacityTraffic) {
  auto udacity = LoadScenario("udacity");
  ASSERT_TRUE(udacity.ok()) << udacity.message();
  EXPECT_GT(udacity->traffic.linear_drag, 0);  // calibrated, unlike the built-in default
  for (const char* name : {"dense", "cut-in", "hard-brake", "blocked", "seam", "latency", "free"}) {
    auto sc = LoadScenario(name);
    ASSERT_TRUE(sc.ok()) << sc.message();
    EXPECT_EQ(sc->name, name);
    EXPECT_EQ(sc->traffic.linear_drag, udacity->traffic.linear_drag) << name;
    EXPECT_EQ(sc->traffic.drag, udacity->traffic.drag) << name;
    EXPECT_EQ(sc->traffic.max_accel, udacity->traffic.max_accel) << name;
    EXPECT_EQ(sc->traffic.brake_delay, udacity->traffic.brake_delay) << name;
    EXPECT_EQ(sc->traffic.frame_rate, udacity->traffic.frame_rate) << name;
    EXPECT_EQ(sc->timing.l_old_min, udacity->timing.l_old_min) << name;
    EXPECT_EQ(sc->timing.l_new_min, udacity->timing.l_new_min) << name;
    EXPECT_EQ(sc->timing.l_new_max, udacity->timing.l_new_max) << name;
    EXPECT_NE(sc->description, udacity->description) << name;
  }
  auto dense = LoadScenario("dense");
  ASSERT_TRUE(dense.ok());
  EXPECT_EQ(dense->traffic.cars, 24);  // its own key wins
  auto latency = LoadScenario("latency");
  ASSERT_TRUE(latency.ok());
  EXPECT_EQ(latency->timing.mode, TimingOptions::Mode::kRandom);
  EXPECT_EQ(udacity->timing.mode, TimingOptions::Mode::kLockstep);
}

class BaseFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("frenetic_base_" + std::string(::testing::UnitTest::GetInstance()
                                               ->current_test_info()
                                               ->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(BaseFiles, OverlayKeysWinAndNestedMapsMerge) {
  Write("parent.yaml",
        "description: parent\nseed: 9\ntraffic: {cars: 5, max_accel: 3.3, cut_in: {rate: 0.1}}\n"
        "timing: {mode: random, l_old_range: [2, 2]}\nstart: {s: 400, lane: 2}\n");
  const std::string child = Write(
      "child.yaml", "base: parent.yaml\ntraffic: {cars: 7, cut_in: {gap: [3, 4]}}\n");
  auto sc = LoadScenario(child);
  ASSERT_TRUE(sc.ok()) << sc.message();
  EXPECT_EQ(sc->name, "child");
  EXPECT_EQ(sc->source, child);
  EXPECT_EQ(sc->description, "");  // not inherited
  EXPECT_EQ(sc->seed, 9u);
  EXPECT_EQ(sc->traffic.cars, 7);
  EXPECT_EQ(sc->traffic.max_accel, 3.3);
  EXPECT_EQ(sc->traffic.cut_in_rate, 0.1);
  EXPECT_EQ(sc->traffic.cut_in_min_gap, 3);
  EXPECT_EQ(sc->timing.mode, TimingOptions::Mode::kRandom);
  EXPECT_EQ(sc->timing.l_old_min, 2);
  EXPECT_EQ(sc->start.kind, StartPose::Kind::kFrenet);
  EXPECT_EQ(sc->start.d, 10);
  // `start: auto` in an overlay goes back to the automatic pose.
  auto reset = LoadScenario(Write("reset.yaml", "base: parent.yaml\nstart: auto\n"));
  ASSERT_TRUE(reset.ok()) << reset.message();
  EXPECT_EQ(reset->start.kind, StartPose::Kind::kAuto);
  // A bundled name works as a base from any directory.
  auto named = LoadScenario(Write("named.yaml", "base: udacity\ntraffic: {cars: 3}\n"));
  ASSERT_TRUE(named.ok()) << named.message();
  EXPECT_EQ(named->traffic.cars, 3);
  EXPECT_EQ(named->traffic.linear_drag, LoadScenario("udacity")->traffic.linear_drag);
}

TEST_F(BaseFiles, UnknownKeysCyclesAndMissingBasesAreErrors) {
  Write("parent.yaml", "traffic: {cars: 5}\n");
  auto unknown = LoadScenario(Write("u.yaml", "base: parent.yaml\ntraffic: {carz: 2}\n"));
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("u.yaml"), std::string::npos) << unknown.message();
  EXPECT_NE(unknown.message().find("traffic.carz"), std::string::npos) << unknown.message();
  // An unknown key in the base names the base file.
  Write("badparent.yaml", "traffic: {speed: 2}\n");
  auto in_base = LoadScenario(Write("v.yaml", "base: badparent.yaml\n"));
  ASSERT_FALSE(in_base.ok());
  EXPECT_NE(in_base.message().find("badparent.yaml"), std::string::npos) << in_base.message();
  EXPECT_NE(in_base.message().find("traffic.speed"), std::string::npos) << in_base.message();
  // Cycles: a -> b -> a, and a file that is its own base.
  Write("a.yaml", "base: b.yaml\n");
  Write("b.yaml", "base: a.yaml\n");
  auto cycle = LoadScenario((dir_ / "a.yaml").string());
  ASSERT_FALSE(cycle.ok());
  EXPECT_NE(cycle.message().find("cycle"), std::string::npos) << cycle.message();
  EXPECT_NE(cycle.message().find("b.yaml"), std::string::npos) << cycle.message();
  auto self = LoadScenario(Write("self.yaml", "base: ./self.yaml\n"));
  ASSERT_FALSE(self.ok());
  EXPECT_NE(self.message().find("cycle"), std::string::npos) << self.message();
  auto missing = LoadScenario(Write("m.yaml", "base: nowhere.yaml\n"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("nowhere.yaml"), std::string::npos) << missing.message();
  auto not_scalar = LoadScenario(Write("n.yaml", "base: [udacity]\n"));
  ASSERT_FALSE(not_scalar.ok());
  EXPECT_NE(not_scalar.message().find("'base'"), std::string::npos) << not_scalar.message();
}

}  // namespace
}  // namespace frenetic::sim

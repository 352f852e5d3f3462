// `frenetic drive` as a user runs it: report fields, JSON, exit codes and one-line errors.
#include <gtest/gtest.h>

#include <string>

#include "apps_test_util.h"

namespace frenetic::testing {
namespace {

TEST(DriveCli, JsonReportOnBundledTrack) {
  CommandResult r = RunFrenetic("drive --seconds 20 --planner baseline --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["sim_seconds"].get<double>(), 20.0, 0.1);
  EXPECT_GT(j["distance_m"].get<double>(), 100.0);
  EXPECT_GT(j["avg_speed_mph"].get<double>(), 10.0);
  EXPECT_LE(j["max_speed_mph"].get<double>(), 50.0);
  EXPECT_TRUE(j.contains("incidents"));
}

TEST(DriveCli, BadInputGivesOneLineAndExitOne) {
  struct Case {
    std::string args, needle;
  };
  const Case cases[] = {
      {"drive --map /nonexistent.csv --seconds 1", "/nonexistent.csv"},
      {"drive --scenario no-such-scenario --seconds 1", "no-such-scenario"},
      {"drive --planner nope --seconds 1", "nope"},
      {"drive --config /nonexistent.yaml --seconds 1", "/nonexistent.yaml"},
  };
  for (const Case& c : cases) {
    CommandResult r = RunFrenetic(c.args + " 2>&1");
    EXPECT_EQ(r.exit_code, 1) << c.args << ": " << r.out;
    EXPECT_NE(r.out.find(c.needle), std::string::npos) << c.args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << c.args << ": " << r.out;
  }
}

// Incidents are judged unless --no-judge: the JSON gains fields only.
TEST(DriveCli, IncidentsAreJudgedUnlessSwitchedOff) {
  const std::string args =
      "drive --seconds 95 --seed 1 --latency random --planner baseline --scenario cut-in --json "
      "--no-timing";
  CommandResult judged = RunFrenetic(args + " 2>/dev/null");
  CommandResult plain = RunFrenetic(args + " --no-judge 2>/dev/null");
  ASSERT_EQ(judged.exit_code, 0);
  ASSERT_EQ(plain.exit_code, 0);
  auto j = nlohmann::json::parse(judged.out);
  const auto p = nlohmann::json::parse(plain.out);
  ASSERT_GT(j["incidents"].get<int>(), 0) << "the baseline crashes at 89.5 s";
  ASSERT_TRUE(j.contains("judged"));
  EXPECT_FALSE(p.contains("judged"));
  for (const auto& i : j["incident_log"]) {
    ASSERT_TRUE(i.contains("judgement"));
    EXPECT_TRUE(i["judgement"]["summary"].is_string());
  }
  j.erase("judged");
  for (auto& i : j["incident_log"]) i.erase("judgement");
  EXPECT_EQ(j.dump(), p.dump());
}

TEST(DriveCli, HelpExplainsOptionsWithDefaults) {
  CommandResult r = RunFrenetic("drive --help");
  ASSERT_EQ(r.exit_code, 0);
  for (const char* option :
       {"--map", "--scenario", "--seed", "--laps", "--planner", "--record", "--json", "--episodes",
        "--connect", "--progress", "--no-judge", "--judge-budget"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
  EXPECT_NE(r.out.find("Default"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::testing

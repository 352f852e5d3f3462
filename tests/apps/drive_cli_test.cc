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

TEST(DriveCli, HelpExplainsOptionsWithDefaults) {
  CommandResult r = RunFrenetic("drive --help");
  ASSERT_EQ(r.exit_code, 0);
  for (const char* option : {"--map", "--scenario", "--seed", "--laps", "--planner", "--record",
                             "--json", "--episodes", "--connect"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
  EXPECT_NE(r.out.find("Default"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::testing

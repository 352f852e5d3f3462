// `frenetic drive` as a user runs it: report fields, JSON, exit codes and one-line errors.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>
#include <vector>

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

// On an empty road (the bundled `free` scenario) the planner keeps its lane, with no incident,
// and once up to speed drives at the limit every second, under the simulator's cap. (Lanes'
// limits that change with every bend ahead made a planner change lanes 7-40 times a lap
// here: docs/udacity-results.md, the round of 2026-12-05.)
TEST(DriveCli, OnAnEmptyRoadThePlannerKeepsItsLaneAtTheLimit) {
  if (!HaveUdacityMap()) GTEST_SKIP() << "no " << UdacityMap();
  CommandResult r = RunFrenetic("drive --map " + UdacityMap() +
                                " --scenario free --seconds 120 --latency random --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["incidents"].get<int>(), 0) << r.out;
  EXPECT_EQ(j["lane_changes"].get<int>(), 0);
  const auto& b = j["breakdown"];
  EXPECT_GT(b["at_limit_s"].get<double>(), 120 - 5) << b.dump();  // 48 mph within 2.7 s
  EXPECT_GT(b["at_limit_mph"].get<double>(), 49.2) << b.dump();
  EXPECT_LT(j["max_speed_mph"].get<double>(), 49.9);
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

std::vector<std::string> FileLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// `--episodes N --progress` off a terminal: lines "episodes k/N  elapsed ...  ETA ...  x mi
// n incidents" on stderr, the last one for N/N; stdout is the same JSON as without it.
TEST(DriveCli, ProgressOfManyEpisodesGoesToStderr) {
  const std::string err = ::testing::TempDir() + "/progress_err.txt";
  const std::string common =
      "drive --seconds 10 --planner baseline --episodes 3 --jobs 2 --json --no-timing";
  CommandResult quiet = RunFrenetic(common + " 2>/dev/null");
  CommandResult shown = RunFrenetic(common + " --progress 2>" + err);
  ASSERT_EQ(quiet.exit_code, 0);
  ASSERT_EQ(shown.exit_code, 0);
  EXPECT_EQ(shown.out, quiet.out);
  const std::vector<std::string> lines = FileLines(err);
  ASSERT_FALSE(lines.empty());
  EXPECT_LE(lines.size(), 3u);  // one per episode at most, not a flood
  const std::regex format(
      R"(episodes ([0-3])/3  elapsed \d+:\d\d:\d\d  ETA (\d+:\d\d:\d\d|-:--:--)  \d+\.\d mi  \d+ incidents?)");
  int done = 0;
  for (const std::string& line : lines) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(line, m, format)) << line;
    EXPECT_GE(std::stoi(m[1]), done) << line;
    done = std::stoi(m[1]);
  }
  EXPECT_EQ(lines.back().rfind("episodes 3/3  ", 0), 0u) << lines.back();
  const auto j = nlohmann::json::parse(shown.out);
  const int incidents = j["incidents"].get<int>();
  std::string needle = "mi  ";
  needle += std::to_string(incidents);
  EXPECT_NE(lines.back().find(needle), std::string::npos) << lines.back();
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

// --oracle-foresight: 0 or 0.5..20 s, only with --oracle; its value is in the JSON.
TEST(DriveCli, TheOraclesForesightIsCheckedAndReported) {
  for (const char* bad : {"--oracle --oracle-foresight 0.3", "--oracle --oracle-foresight 25",
                          "--oracle --oracle-foresight nan", "--oracle-foresight 3"}) {
    CommandResult r = RunFrenetic(std::string("drive --seconds 5 ") + bad + " 2>&1");
    EXPECT_NE(r.exit_code, 0) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("--oracle"), std::string::npos) << bad << ": " << r.out;
  }
  const std::string run =
      "drive --seconds 25 --planner baseline --json --no-timing --no-judge --oracle "
      "--oracle-foresight 2.5";
  CommandResult r = RunFrenetic(run + " 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["oracle"]["foresight_s"].get<double>(), 2.5);
  EXPECT_TRUE(j["oracle"]["stuck_windows"].is_number_integer());
  ASSERT_EQ(j["oracle"]["windows"].size(), 2u);  // 20 s and 5 s
  EXPECT_TRUE(j["oracle"]["windows"][0]["stuck_stage"].is_number_integer());
  EXPECT_TRUE(j["oracle"]["windows"][0]["search_m"].is_number());
  // Over several episodes the summary has them too.
  CommandResult two = RunFrenetic(run + " --episodes 2 2>/dev/null");
  ASSERT_EQ(two.exit_code, 0) << two.out;
  const auto a = nlohmann::json::parse(two.out);
  EXPECT_DOUBLE_EQ(a["oracle"]["foresight_s"].get<double>(), 2.5);
  int stuck = 0;
  for (const auto& e : a["per_episode"]) stuck += e["oracle"]["stuck_windows"].get<int>();
  EXPECT_EQ(a["oracle"]["stuck_windows"].get<int>(), stuck);
  EXPECT_TRUE(a["oracle"]["through_search_mph"].is_number());
}

TEST(DriveCli, PerfectPredictionsAreCheckedAndInProcessOnly) {
  for (const char* bad :
       {"--perfect-predictions nan", "--perfect-predictions 0.2", "--perfect-predictions 11",
        "--perfect-predictions 2 --connect ws://127.0.0.1:1/"}) {
    CommandResult r = RunFrenetic(std::string("drive --seconds 5 ") + bad + " 2>&1");
    EXPECT_NE(r.exit_code, 0) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("--perfect-predictions"), std::string::npos) << bad << ": " << r.out;
  }
  CommandResult r = RunFrenetic(
      "drive --seconds 10 --json --no-timing --no-judge --perfect-predictions 2 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_GT(nlohmann::json::parse(r.out)["distance_m"].get<double>(), 50.0);
}

TEST(DriveCli, HelpExplainsOptionsWithDefaults) {
  CommandResult r = RunFrenetic("drive --help");
  ASSERT_EQ(r.exit_code, 0);
  for (const char* option : {"--map", "--scenario", "--seed", "--laps", "--planner", "--record",
                             "--json", "--episodes", "--connect", "--progress", "--no-judge",
                             "--judge-budget", "--oracle-foresight", "--perfect-predictions"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
  EXPECT_NE(r.out.find("Default"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::testing

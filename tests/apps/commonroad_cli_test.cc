// `frenetic commonroad` as a user runs it, on hand-made scenario files written by the test: the
// verdict in the text, the JSON's structure, solution files, one-line errors, --help, and results
// that do not depend on --jobs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "apps_test_util.h"
#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/setup.h"
#include "frenetic/commonroad/solution.h"

namespace frenetic::testing {
namespace {

namespace fs = std::filesystem;
namespace crt = commonroad::testing;
using nlohmann::json;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

// A goal 140 m ahead at the ego's speed, within 5-9 s: solved. `id`: its benchmark id, as
// written (any bytes).
std::string SolvableXml(const std::string& id = "ZAM_Reach-1_1_T-1") {
  crt::ScenarioXml xml(id);
  crt::AddStraightRoad(xml, 400).Problem(1, {10, -1.75}, 0, 20,
                                         {crt::GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90)});
  return xml.Str();
}

// 590 m in 3 s from 20 m/s: no vehicle gets there; the verdict names the goal.
std::string UnsolvableXml() {
  crt::ScenarioXml xml("ZAM_Far-1_1_T-1");
  crt::AddStraightRoad(xml, 800).Problem(1, {10, -1.75}, 0, 20,
                                         {crt::GoalRectangleXml({600, -1.75}, 10, 3, 0, 0, 30)});
  return xml.Str();
}

// A lanelet whose point has no y: the reader names this line.
std::string MalformedXml() {
  crt::ScenarioXml xml("ZAM_Broken-1_1_T-1");
  crt::AddStraightRoad(xml, 100).Raw(
      "<lanelet id=\"7\">\n<leftBound>\n<point><x>1</x></point>\n</leftBound>\n</lanelet>\n");
  return xml.Str();
}

// A parked car where the ego starts: infeasible at start.
std::string BlockedXml() {
  crt::ScenarioXml xml("ZAM_Blocked-2_1_T-1");
  crt::AddStraightRoad(xml, 400)
      .StaticObstacle(9, 4.5, 2, {12, -1.75}, 0)
      .Problem(1, {10, -1.75}, 0, 20, {crt::GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90)});
  return xml.Str();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class CommonRoadCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("frenetic_cr_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "set");
    std::ofstream(dir_ / "set" / "a_reach.xml") << SolvableXml();
    std::ofstream(dir_ / "set" / "b_far.xml") << UnsolvableXml();
    fs::create_directories(dir_ / "mixed");
    std::ofstream(dir_ / "mixed" / "a_broken.xml") << MalformedXml();
    std::ofstream(dir_ / "mixed" / "b_reach.xml") << SolvableXml();
    fs::create_directories(dir_ / "blocked");
    std::ofstream(dir_ / "blocked" / "a_reach.xml") << SolvableXml();
    std::ofstream(dir_ / "blocked" / "b_blocked.xml") << BlockedXml();
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  void SetUp() override {
    if (!fs::exists(FRENETIC_BINARY)) GTEST_SKIP() << "no executable at " << FRENETIC_BINARY;
  }

  static std::string Set() { return (dir_ / "set").string(); }
  static inline fs::path dir_;
};

TEST_F(CommonRoadCliTest, TextNamesEachProblemsVerdict) {
  CommandResult r = RunFrenetic("commonroad " + Set() + " --no-timing");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::vector<std::string> lines = Lines(r.out);
  auto verdict_after = [&](const std::string& id) -> std::string {
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
      if (lines[i].rfind(id, 0) == 0) return lines[i + 1];
    }
    return "<" + id + " not found>";
  };
  EXPECT_THAT(verdict_after("ZAM_Reach-1_1_T-1"),
              ::testing::MatchesRegex("    solved, goal at step [0-9]+"));
  EXPECT_THAT(verdict_after("ZAM_Far-1_1_T-1"), HasSubstr("FAILED: goal at step"));
  EXPECT_THAT(r.out, HasSubstr("solved 1 / 2 problems feasible at start (0 infeasible at start, 2 in all; recorded predictions, KS2)"));
  EXPECT_THAT(r.out, HasSubstr("failures: goal 1\n"));
  EXPECT_THAT(r.out, HasSubstr("WX1 "));
}

TEST_F(CommonRoadCliTest, JsonHasScenariosProblemsAndSummary) {
  CommandResult r = RunFrenetic("commonroad " + Set() + " --json --no-timing");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(r.out, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << r.out;
  ASSERT_EQ(j.at("scenarios").size(), 2u);
  int solved = 0;
  for (const json& s : j.at("scenarios")) {
    ASSERT_TRUE(s.at("path").is_string());
    ASSERT_EQ(s.at("problems").size(), 1u);
    const json& p = s.at("problems")[0];
    EXPECT_EQ(p.at("problem"), 1);
    ASSERT_TRUE(p.at("solved").is_boolean());
    ASSERT_TRUE(p.at("failures").is_array());
    for (const char* k : {"p50", "p99", "max"}) EXPECT_TRUE(p.at("plan_ms").at(k).is_number()) << k;
    for (const char* k : {"WX1", "JB1"}) {
      ASSERT_TRUE(p.at("costs").at(k).is_number()) << k;
      EXPECT_GT(p.at("costs").at(k).get<double>(), 0) << k;
    }
    const std::string id = s.at("benchmark_id");
    if (id == "ZAM_Reach-1_1_T-1") {
      EXPECT_TRUE(p.at("solved").get<bool>());
      EXPECT_TRUE(p.at("failures").empty());
      EXPECT_EQ(p.at("goal_step"), p.at("steps"));
      EXPECT_EQ(p.at("stop"), "goal");
    } else {
      EXPECT_EQ(id, "ZAM_Far-1_1_T-1");
      EXPECT_FALSE(p.at("solved").get<bool>());
      ASSERT_EQ(p.at("failures").size(), 1u) << p.dump();
      EXPECT_EQ(p.at("failures")[0].at("kind"), "goal");
      EXPECT_TRUE(p.at("failures")[0].at("step").is_number_integer());
      EXPECT_TRUE(p.at("goal_step").is_null());
    }
    solved += p.at("solved").get<bool>();
  }
  EXPECT_EQ(solved, 1);
  const json& sum = j.at("summary");
  EXPECT_EQ(sum.at("problems"), 2);
  EXPECT_EQ(sum.at("solved"), 1);
  EXPECT_EQ(sum.at("failures"), json({{"goal", 1}}));
  EXPECT_EQ(sum.at("unreadable_files"), 0);
  EXPECT_EQ(sum.at("infeasible_at_start"), 0);
  EXPECT_EQ(sum.at("unsolved"), json({{"goal", 1}}));
  ASSERT_EQ(sum.at("families").size(), 2u) << sum.dump();
  EXPECT_EQ(sum.at("families").at("ZAM_Reach").at("solved"), 1);
  EXPECT_EQ(sum.at("families").at("ZAM_Far").at("unsolved"), json({{"goal", 1}}));
  EXPECT_EQ(sum.at("prediction"), "recorded");
  for (const char* k : {"p50", "p99", "max"}) {
    EXPECT_EQ(sum.at("plan_ms").at(k), 0.0) << k << ": --no-timing reports 0";
  }
  EXPECT_GT(sum.at("cycles").get<int>(), 0);
}

// The solution file, read back, holds the trajectory the runner drove (the same config run in
// process gives the same states, bit for bit: the file's numbers round-trip).
TEST_F(CommonRoadCliTest, SolutionDirWritesFilesThatReadBack) {
  const fs::path out = dir_ / "solutions";
  CommandResult r = RunFrenetic("commonroad " + (dir_ / "set" / "a_reach.xml").string() +
                                " --json --no-timing --solution-dir " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(r.out);
  const std::string name = "solution_KS2:WX1:ZAM_Reach-1_1_T-1:2020a.xml";
  EXPECT_EQ(j.at("scenarios")[0].at("solution_file"), name);
  ASSERT_TRUE(fs::exists(out / name)) << r.out;
  auto solution = commonroad::LoadSolution((out / name).string());
  ASSERT_TRUE(solution.ok()) << solution.message();
  EXPECT_EQ(solution->scenario_id, "ZAM_Reach-1_1_T-1");
  EXPECT_FALSE(solution->computation_time.has_value()) << "--no-timing";
  ASSERT_EQ(solution->trajectories.size(), 1u);
  const commonroad::SolutionTrajectory& t = solution->trajectories[0];
  EXPECT_EQ(t.problem_id, 1);
  EXPECT_EQ(t.vehicle_type, 2);
  EXPECT_EQ(t.cost_function, "WX1");
  const int steps = j.at("scenarios")[0].at("problems")[0].at("steps");
  ASSERT_EQ(static_cast<int>(t.states.size()), steps + 1);
  EXPECT_EQ(t.states.front().time_step, 0);
  EXPECT_EQ(t.states.front().x, 10);
  EXPECT_EQ(t.states.front().y, -1.75);
  EXPECT_EQ(t.states.back().time_step, j.at("scenarios")[0].at("problems")[0].at("goal_step"));

  auto scenario = commonroad::ParseScenario(SolvableXml(), "a_reach.xml");
  ASSERT_TRUE(scenario.ok()) << scenario.message();
  auto base = commonroad::LoadBaseConfig();
  ASSERT_TRUE(base.ok()) << base.message();
  auto config = commonroad::CommonRoadConfig(*base, commonroad::VehicleParams(),
                                             commonroad::PredictionMode::kRecorded);
  ASSERT_TRUE(config.ok()) << config.message();
  commonroad::RunOptions options;
  options.timing = false;
  const commonroad::ScenarioRun run = commonroad::RunScenario(*scenario, *config, options);
  ASSERT_EQ(run.problems.size(), 1u);
  const std::vector<commonroad::KsState>& driven = run.problems[0].trajectory;
  ASSERT_EQ(driven.size(), t.states.size());
  for (std::size_t i = 0; i < driven.size(); ++i) {
    EXPECT_EQ(t.states[i].time_step, driven[i].time_step) << i;
    EXPECT_EQ(t.states[i].x, driven[i].x) << i;
    EXPECT_EQ(t.states[i].y, driven[i].y) << i;
    EXPECT_EQ(t.states[i].velocity, driven[i].velocity) << i;
    EXPECT_EQ(t.states[i].orientation, driven[i].orientation) << i;
    EXPECT_EQ(t.states[i].steering_angle, driven[i].steering_angle) << i;
  }
}

// A file in map-projection coordinates is planned in a local frame (the JSON gives its origin)
// and its solution file is in the file's own coordinates: the first state is the problem's
// initial one as the file gives it.
TEST_F(CommonRoadCliTest, AFileFarFromItsOriginGetsItsSolutionInItsOwnFrame) {
  const commonroad::Vec2 far{612345.0, 5432100.0};
  crt::ScenarioXml xml("ZAM_Utm-1_1_T-1");
  crt::AddStraightRoadAt(xml, far, 400)
      .Problem(1, far + commonroad::Vec2{10, -1.75}, 0, 20,
               {crt::GoalRectangleXml(far + commonroad::Vec2{150, -1.75}, 10, 3, 0, 50, 90)});
  const fs::path file = dir_ / "utm" / "utm.xml";
  fs::create_directories(file.parent_path());
  std::ofstream(file) << xml.Str();
  const fs::path out = dir_ / "utm_solutions";
  CommandResult r = RunFrenetic("commonroad " + file.string() +
                                " --json --no-timing --solution-dir " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(r.out);
  const json& sc = j.at("scenarios")[0];
  // The lanelets' centre (612545, 5432100) rounded to the kilometre.
  EXPECT_EQ(sc.at("frame_origin"), json({613000.0, 5432000.0}));
  EXPECT_TRUE(sc.at("problems")[0].at("solved").get<bool>()) << r.out;
  auto solution = commonroad::LoadSolution((out / sc.at("solution_file").get<std::string>()).string());
  ASSERT_TRUE(solution.ok()) << solution.message();
  ASSERT_EQ(solution->trajectories.size(), 1u);
  const commonroad::SolutionTrajectory& t = solution->trajectories[0];
  ASSERT_FALSE(t.states.empty());
  EXPECT_EQ(t.states.front().x, far.x + 10);
  EXPECT_EQ(t.states.front().y, far.y - 1.75);
  EXPECT_GT(t.states.back().x, far.x + 140);  // in the goal, 150 m on
  // A file near its origin says nothing of a frame.
  CommandResult home = RunFrenetic("commonroad " + (dir_ / "set" / "a_reach.xml").string() +
                                   " --json --no-timing");
  ASSERT_EQ(home.exit_code, 0) << home.out;
  EXPECT_FALSE(json::parse(home.out).at("scenarios")[0].contains("frame_origin"));
}

// Counted apart: not solved, not unsolved, not in the solved rate's denominator.
TEST_F(CommonRoadCliTest, InfeasibleAtStartIsCountedApart) {
  CommandResult r = RunFrenetic("commonroad " + (dir_ / "blocked").string() + " --no-timing");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_THAT(r.out, HasSubstr("    infeasible at start: collision at step 0"));
  // Nothing was planned: no costs.
  EXPECT_THAT(r.out, ::testing::ContainsRegex("\nZAM_Blocked-2_1_T-1 +#1 [^\n]*ms\n"));
  EXPECT_THAT(r.out, HasSubstr("\nsolved 1 / 1 problems feasible at start (1 infeasible at start, "
                               "2 in all; recorded predictions, KS2)\n"));
  EXPECT_THAT(r.out, Not(HasSubstr("failures:")));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("\n  ZAM_Blocked +1 +1 +0 / 0 .* -\n"));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("\n  all +2 +1 +1 / 1 .* -\n"));

  CommandResult j = RunFrenetic("commonroad " + (dir_ / "blocked").string() + " --json --no-timing");
  ASSERT_EQ(j.exit_code, 0) << j.out;
  const json doc = json::parse(j.out);
  for (const json& s : doc.at("scenarios")) {
    if (s.at("benchmark_id") == "ZAM_Blocked-2_1_T-1") {
      EXPECT_EQ(s.at("problems")[0].at("costs"), json::object());
      EXPECT_EQ(s.at("problems")[0].at("stop"), "infeasible_at_start");
    }
  }
  const json sum = doc.at("summary");
  EXPECT_EQ(sum.at("problems"), 2);
  EXPECT_EQ(sum.at("infeasible_at_start"), 1);
  EXPECT_EQ(sum.at("solved"), 1);
  EXPECT_EQ(sum.at("solved_share"), 1.0);
  EXPECT_EQ(sum.at("unsolved"), json::object());
  EXPECT_EQ(sum.at("failures"), json::object());
  const json& blocked = sum.at("families").at("ZAM_Blocked");
  EXPECT_EQ(blocked.at("problems"), 1);
  EXPECT_EQ(blocked.at("infeasible_at_start"), 1);
  EXPECT_EQ(blocked.at("solved"), 0);
  EXPECT_EQ(blocked.at("solved_share"), 0.0);

  // With timing on, a scenario in which no cycle ran writes no computation time (commonroad-io
  // asserts one above 0), and its file reads back; one that was planned writes its time.
  const fs::path out = dir_ / "blocked_solutions";
  CommandResult t = RunFrenetic("commonroad " + (dir_ / "blocked").string() +
                                " --json --solution-dir " + out.string());
  ASSERT_EQ(t.exit_code, 0) << t.out;
  auto blocked_file =
      commonroad::LoadSolution((out / "solution_KS2:WX1:ZAM_Blocked-2_1_T-1:2020a.xml").string());
  ASSERT_TRUE(blocked_file.ok()) << blocked_file.message();
  EXPECT_FALSE(blocked_file->computation_time.has_value());
  auto planned =
      commonroad::LoadSolution((out / "solution_KS2:WX1:ZAM_Reach-1_1_T-1:2020a.xml").string());
  ASSERT_TRUE(planned.ok()) << planned.message();
  ASSERT_TRUE(planned->computation_time.has_value());
  EXPECT_GT(*planned->computation_time, 0.0);
}

TEST_F(CommonRoadCliTest, MalformedFileIsOneLineAndTheOthersStillRun) {
  const std::string broken = (dir_ / "mixed" / "a_broken.xml").string();
  const int line = crt::LineOf(MalformedXml(), "<point><x>1</x></point>");
  ASSERT_GT(line, 0);
  CommandResult r = RunFrenetic("commonroad " + (dir_ / "mixed").string() + " --no-timing 2>&1");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  int naming = 0;
  for (const std::string& l : Lines(r.out)) {
    if (l.find(broken + ":") == std::string::npos) continue;
    ++naming;
    EXPECT_THAT(l, HasSubstr(broken + ":" + std::to_string(line) + ":")) << l;
  }
  EXPECT_EQ(naming, 1) << r.out;
  EXPECT_THAT(r.out, HasSubstr("solved 1 / 1 problems feasible at start"));
  EXPECT_THAT(r.out, HasSubstr("1 file(s) unreadable"));

  CommandResult j = RunFrenetic("commonroad " + (dir_ / "mixed").string() + " --json --no-timing");
  EXPECT_EQ(j.exit_code, 1);
  const json doc = json::parse(j.out, nullptr, false);
  ASSERT_FALSE(doc.is_discarded()) << j.out;
  ASSERT_EQ(doc.at("scenarios").size(), 2u);
  const std::string error = doc.at("scenarios")[0].at("error");
  EXPECT_THAT(error, HasSubstr(broken + ":" + std::to_string(line) + ":"));
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_TRUE(doc.at("scenarios")[1].at("problems")[0].at("solved").get<bool>());
  EXPECT_EQ(doc.at("summary").at("unreadable_files"), 1);
}

// Bytes that are not text, in a value the reader rejects and in a benchmark id it accepts (both
// reach the output): the run goes on, and --json writes valid JSON (nlohmann's dump throws on
// invalid UTF-8: this aborted the command).
TEST_F(CommonRoadCliTest, BytesThatAreNotTextNeverAbortTheOutput) {
  const fs::path dir = dir_ / "bytes";
  fs::create_directories(dir);
  std::string broken = SolvableXml();
  const std::size_t at = broken.find("<x>");
  ASSERT_NE(at, std::string::npos);
  broken.insert(at + 3, "\xff\x01");
  std::ofstream(dir / "a_broken.xml", std::ios::binary) << broken;
  std::ofstream(dir / "b_named.xml", std::ios::binary)
      << SolvableXml("ZAM_R\xe9" "ach-1_1_T-1");  // Latin-1, not UTF-8

  CommandResult j = RunFrenetic("commonroad " + dir.string() + " --json --no-timing");
  EXPECT_EQ(j.exit_code, 1) << j.out;  // one file unreadable
  const json doc = json::parse(j.out, nullptr, false);
  ASSERT_FALSE(doc.is_discarded()) << j.out;
  ASSERT_EQ(doc.at("scenarios").size(), 2u);
  EXPECT_THAT(doc.at("scenarios")[0].at("error").get<std::string>(),
              HasSubstr("'\\xff\\x01"));
  const json& run = doc.at("scenarios")[1];
  EXPECT_EQ(run.at("benchmark_id").get<std::string>(), "ZAM_R\xef\xbf\xbd" "ach-1_1_T-1");
  EXPECT_TRUE(run.at("problems")[0].at("solved").get<bool>());

  CommandResult t = RunFrenetic("commonroad " + dir.string() + " --no-timing 2>&1");
  EXPECT_EQ(t.exit_code, 1) << t.out;
  EXPECT_THAT(t.out, HasSubstr("'\\xff\\x01"));
  EXPECT_THAT(t.out, HasSubstr("solved 1 / 1 problems feasible at start"));
  // The text shows the id's byte escaped, in its problem's line and in the family table.
  EXPECT_THAT(t.out, HasSubstr("ZAM_R\\xe9ach-1_1_T-1"));
  EXPECT_THAT(t.out, HasSubstr("  ZAM_R\\xe9ach  "));
  EXPECT_EQ(t.out.find('\xe9'), std::string::npos);
}

// A benchmark id names the files written for it: a '/' or a control character in it stays out
// of the path (the solution lands in --solution-dir, under a name of safe bytes).
TEST_F(CommonRoadCliTest, AnIdWithASlashWritesItsSolutionInsideTheDir) {
  const fs::path dir = dir_ / "slash";
  fs::create_directories(dir);
  std::ofstream(dir / "named.xml", std::ios::binary) << SolvableXml("../ZAM_\x07Reach-1_1_T-1");
  const fs::path out = dir / "solutions";
  CommandResult r = RunFrenetic("commonroad " + (dir / "named.xml").string() +
                                " --no-timing --solution-dir " + out.string() + " 2>&1");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_THAT(r.out, HasSubstr("../ZAM_\\x07Reach-1_1_T-1"));
  std::vector<std::string> written;
  for (const auto& e : fs::directory_iterator(out)) written.push_back(e.path().filename().string());
  EXPECT_THAT(written, ElementsAre("solution_KS2:WX1:.._ZAM__Reach-1_1_T-1:2020a.xml"));
  EXPECT_FALSE(fs::exists(dir / "ZAM_\x07Reach-1_1_T-1"));
}

TEST_F(CommonRoadCliTest, BadArgumentsFailWithOneLine) {
  struct Case {
    std::string args, needle;
  };
  const Case cases[] = {
      {"commonroad /nonexistent/scenario.xml", "/nonexistent/scenario.xml: no such file"},
      {"commonroad " + Set() + " --prediction bogus", "'bogus'"},
      {"commonroad " + Set() + " --config /nonexistent/planner.yaml", "/nonexistent/planner.yaml"},
      {"commonroad " + Set() + " --commonroad-config /nonexistent/cr.yaml", "/nonexistent/cr.yaml"},
  };
  for (const Case& c : cases) {
    CommandResult r = RunFrenetic(c.args + " 2>&1");
    EXPECT_EQ(r.exit_code, 1) << c.args << ": " << r.out;
    EXPECT_THAT(r.out, HasSubstr(c.needle)) << c.args;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << c.args << ": " << r.out;
    EXPECT_EQ(r.out.rfind("frenetic commonroad: ", 0), 0u) << r.out;
  }
}

// Every option is listed; every option that takes a value gives its default.
TEST_F(CommonRoadCliTest, HelpListsEveryOptionWithItsDefault) {
  CommandResult r = RunFrenetic("commonroad --help");
  ASSERT_EQ(r.exit_code, 0);
  for (const char* option : {"--prediction", "--vehicle", "--config", "--commonroad-config",
                             "--solution-dir", "--compare", "--jobs"}) {
    const std::size_t at = r.out.find(std::string("  ") + option + " ");
    ASSERT_NE(at, std::string::npos) << option << " missing from\n" << r.out;
    const std::size_t next = r.out.find("\n  -", at + 1);
    const std::string entry =
        r.out.substr(at, next == std::string::npos ? std::string::npos : next - at);
    EXPECT_THAT(entry, HasSubstr("Default")) << entry;
  }
  for (const char* flag : {"--json", "--progress", "--no-timing", "--way-through", "paths"}) {
    EXPECT_THAT(r.out, HasSubstr(flag));
  }
}

// --way-through searches the unsolved problems only (not the solved, not the infeasible at
// start): the far goal's road has no traffic, so a way through it is found, to the search's
// default 10 steps, and none to its goal; the summary counts both. Without the flag there is
// no such field.
TEST_F(CommonRoadCliTest, WayThroughIsSearchedForTheUnsolvedOnly) {
  const std::string paths = Set() + " " + (dir_ / "blocked" / "b_blocked.xml").string();
  CommandResult r = RunFrenetic("commonroad " + paths + " --json --no-timing --way-through");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(r.out);
  int searched = 0;
  for (const json& s : j.at("scenarios")) {
    for (const json& p : s.at("problems")) {
      const bool unsolved = !p.at("solved").get<bool>() && !p.contains("infeasible_at_start");
      ASSERT_EQ(p.contains("way_through"), unsolved) << s.at("benchmark_id") << ": " << p.dump();
      if (!unsolved) continue;
      ++searched;
      const json& w = p.at("way_through");
      EXPECT_TRUE(w.at("found").get<bool>()) << w.dump();
      EXPECT_EQ(w.at("last_step"), 10);
      EXPECT_EQ(w.at("survived_to"), 10);
      EXPECT_GT(w.at("states_checked").get<int>(), 10);
      // Then on the road alone to the goal's window's close (step 30): out of reach.
      EXPECT_TRUE(w.at("goal_step").is_null()) << w.dump();
      EXPECT_EQ(w.at("goal_searched_to"), 30);
    }
  }
  EXPECT_EQ(searched, 1);
  const json& sum = j.at("summary").at("way_through");
  EXPECT_EQ(sum.at("searched"), 1);
  EXPECT_EQ(sum.at("found"), 1);
  EXPECT_EQ(sum.at("none_found"), 0);
  EXPECT_EQ(sum.at("to_the_goal"), 0);
  CommandResult text = RunFrenetic("commonroad " + paths + " --no-timing --way-through");
  EXPECT_THAT(text.out, HasSubstr("    way through: found (to step 10, the traffic's last)\n"));
  EXPECT_THAT(text.out, HasSubstr("    way to the goal: none found to step 30\n"));
  EXPECT_THAT(text.out, HasSubstr("of the 1 unsolved problems: found for 1, none found for 0"));
  EXPECT_THAT(text.out, HasSubstr("a way to a goal state found for 0\n"));
  CommandResult plain = RunFrenetic("commonroad " + paths + " --json --no-timing");
  EXPECT_THAT(plain.out, Not(HasSubstr("way_through")));
}

TEST_F(CommonRoadCliTest, JobsDoNotChangeTheResults) {
  const std::string common = "commonroad " + Set() + " " +
                             (dir_ / "mixed" / "b_reach.xml").string() + " --json --no-timing";
  CommandResult one = RunFrenetic(common + " --jobs 1");
  CommandResult two = RunFrenetic(common + " --jobs 2");
  ASSERT_EQ(one.exit_code, 0) << one.out;
  ASSERT_EQ(two.exit_code, 0) << two.out;
  EXPECT_EQ(json::parse(one.out).at("scenarios").size(), 3u);
  EXPECT_EQ(one.out, two.out);
}

}  // namespace
}  // namespace frenetic::testing

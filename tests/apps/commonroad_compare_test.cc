// `frenetic commonroad` with reference trajectories: solution files among the paths are not
// scenarios, they are paired with their scenario by the scenario id in their benchmark id, and
// each problem with one gets the reference's costs, time to the goal and verdict beside ours; the
// summary compares. Hand-made files, then the shared highD set (skipped when absent).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "apps_test_util.h"
#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/cost.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/solution.h"
#include "frenetic/commonroad/vehicle_params.h"

namespace frenetic::testing {
namespace {

namespace fs = std::filesystem;
namespace cr = commonroad;
namespace crt = commonroad::testing;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::Not;

// The CLI test's solvable scenario: a goal 140 m ahead at the ego's speed (20 m/s), x in
// [145, 155] within steps 50-90.
std::string ReachXml() {
  crt::ScenarioXml xml("ZAM_Reach-1_1_T-1");
  crt::AddStraightRoad(xml, 400).Problem(1, {10, -1.75}, 0, 20,
                                         {crt::GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90)});
  return xml.Str();
}

// 590 m in 3 s: unsolvable, and no reference for it.
std::string FarXml() {
  crt::ScenarioXml xml("ZAM_Far-1_1_T-1");
  crt::AddStraightRoad(xml, 800).Problem(1, {10, -1.75}, 0, 20,
                                         {crt::GoalRectangleXml({600, -1.75}, 10, 3, 0, 0, 30)});
  return xml.Str();
}

// A driver at a steady 20 m/s down the lane's centre from step `first` (as the highD humans,
// after the problem's initial step 0) to step 75: at x = 10 + 2 k, in the goal from step 68.
cr::Solution Human(const std::string& scenario_id, int first = 5) {
  cr::Solution s;
  s.scenario_id = scenario_id;
  cr::SolutionTrajectory t;
  t.problem_id = 1;
  t.vehicle_type = 1;
  t.cost_function = "TR2";
  for (int k = first; k <= 75; ++k) {
    cr::KsState st;
    st.time_step = k;
    st.x = 10 + 2.0 * k;
    st.y = -1.75;
    st.velocity = 20;
    t.states.push_back(st);
  }
  s.trajectories.push_back(t);
  return s;
}

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

const json* FindScenario(const json& doc, const std::string& id) {
  for (const json& s : doc.at("scenarios")) {
    if (s.value("benchmark_id", "") == id) return &s;
  }
  return nullptr;
}

class CommonRoadCompareTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("frenetic_cr_compare_" + std::to_string(::getpid()));
    // Scenarios and solution files side by side. The Reach human's file is named after the
    // other scenario: pairing goes by the benchmark id inside, not by file name.
    fs::create_directories(dir_ / "set");
    std::ofstream(dir_ / "set" / "a_reach.xml") << ReachXml();
    std::ofstream(dir_ / "set" / "b_far.xml") << FarXml();
    std::ofstream(dir_ / "set" / "b_far.solution.xml") << cr::WriteSolution(Human("ZAM_Reach-1_1_T-1"));
    std::ofstream(dir_ / "set" / "c_nowhere.solution.xml")
        << cr::WriteSolution(Human("ZAM_Nowhere-1_1_T-1"));
    // The scenarios alone, their references elsewhere (--compare).
    fs::create_directories(dir_ / "scenarios");
    std::ofstream(dir_ / "scenarios" / "a_reach.xml") << ReachXml();
    std::ofstream(dir_ / "scenarios" / "b_far.xml") << FarXml();
    fs::create_directories(dir_ / "humans");
    std::ofstream(dir_ / "humans" / "reach.xml") << cr::WriteSolution(Human("ZAM_Reach-1_1_T-1"));
    std::ofstream(dir_ / "humans" / "README.xml") << "<notes>not a solution</notes>\n";
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  void SetUp() override {
    if (!fs::exists(FRENETIC_BINARY)) GTEST_SKIP() << "no executable at " << FRENETIC_BINARY;
  }
  // Runs the command with stderr in err_.
  CommandResult Run(const std::string& args) {
    const fs::path err = dir_ / ("err_" + std::to_string(runs_++));
    CommandResult r = RunFrenetic(args + " 2>" + err.string());
    err_ = ReadFile(err);
    return r;
  }

  static inline fs::path dir_;
  static inline int runs_ = 0;
  std::string err_;
};

TEST_F(CommonRoadCompareTest, SolutionFilesBesideScenariosArePairedByBenchmarkId) {
  CommandResult r = Run("commonroad " + (dir_ / "set").string() + " --json --no-timing");
  ASSERT_EQ(r.exit_code, 0) << r.out << err_;  // solution files are not unreadable scenarios
  const json doc = json::parse(r.out);
  ASSERT_EQ(doc.at("scenarios").size(), 2u) << "only the two scenarios run";
  EXPECT_EQ(doc.at("summary").at("unreadable_files"), 0);

  const json* reach = FindScenario(doc, "ZAM_Reach-1_1_T-1");
  const json* far = FindScenario(doc, "ZAM_Far-1_1_T-1");
  ASSERT_NE(reach, nullptr);
  ASSERT_NE(far, nullptr);
  EXPECT_FALSE(far->at("problems")[0].contains("reference"));  // b_far.solution.xml is Reach's
  const json& p = reach->at("problems")[0];
  ASSERT_TRUE(p.contains("reference")) << p.dump();
  const json& ref = p.at("reference");
  EXPECT_EQ(ref.at("file"), (dir_ / "set" / "b_far.solution.xml").string());
  EXPECT_EQ(ref.at("vehicle"), "KS1");
  EXPECT_EQ(ref.at("cost_function"), "TR2");
  EXPECT_EQ(ref.at("first_step"), 5);
  EXPECT_EQ(ref.at("last_step"), 75);
  EXPECT_EQ(ref.at("states"), 71);
  EXPECT_EQ(ref.at("goal_step"), 68);  // x = 146 >= 145
  EXPECT_EQ(ref.at("time_to_goal_steps"), 63);
  EXPECT_EQ(ref.at("time_to_goal_s"), 6.3);
  // It starts at step 5, not at the problem's step 0; everything else holds.
  EXPECT_EQ(ref.at("human_verdict"), "failed: start");
  EXPECT_NEAR(ref.at("distance_ratio").get<double>(), 1.0, 1e-9);

  // The costs are those of the file's states with the file's vehicle (KS1).
  auto scenario = cr::ParseScenario(ReachXml(), "a_reach.xml");
  ASSERT_TRUE(scenario.ok()) << scenario.message();
  const cr::Solution human = Human("ZAM_Reach-1_1_T-1");
  for (const char* id : {"WX1", "JB1"}) {
    auto c = cr::EvaluateCost(id, *scenario, scenario->problems[0], *cr::VehicleParamsForType(1),
                              human.trajectories[0].states);
    ASSERT_TRUE(c.ok()) << c.message();
    EXPECT_DOUBLE_EQ(ref.at("costs").at(id).get<double>(), c->total) << id;
  }
  EXPECT_DOUBLE_EQ(ref.at("costs").at("JB1").get<double>(), 7.0);  // 70 steps of 0.1 s

  // Ours beside it.
  ASSERT_TRUE(p.at("solved").get<bool>()) << p.dump();
  EXPECT_EQ(ref.at("ours_time_to_goal_steps"), p.at("goal_step"));  // ours starts at step 0
  EXPECT_EQ(ref.at("outcome"), "both_reach_goal");
  const bool cheaper = p.at("costs").at("WX1").get<double>() < ref.at("costs").at("WX1").get<double>();
  EXPECT_EQ(ref.at("ours_cheaper_wx1"), cheaper);

  const json& c = doc.at("summary").at("comparison");
  EXPECT_EQ(c.at("solution_files"), 2);
  EXPECT_EQ(c.at("with_reference"), 1);
  EXPECT_EQ(c.at("compared"), 1);
  EXPECT_EQ(c.at("infeasible_at_start"), 0);
  EXPECT_EQ(c.at("both_reach_goal"), 1);
  EXPECT_EQ(c.at("ours_cheaper_wx1"), cheaper ? 1 : 0);
  EXPECT_EQ(c.at("ours_cheaper_wx1_share"), cheaper ? 1.0 : 0.0);
  EXPECT_EQ(c.at("only_ours"), 0);
  EXPECT_EQ(c.at("only_human"), 0);
  EXPECT_EQ(c.at("neither"), 0);
  // The file for a scenario not among the paths: listed, and noted once on stderr.
  const std::string nowhere = (dir_ / "set" / "c_nowhere.solution.xml").string();
  EXPECT_EQ(c.at("unpaired_solution_files"), json::array({nowhere}));
  EXPECT_THAT(err_, HasSubstr("1 solution file(s) without their scenario among the paths: " +
                              nowhere + "\n"));
  EXPECT_EQ(std::count(err_.begin(), err_.end(), '\n'), 1) << err_;
}

TEST_F(CommonRoadCompareTest, TextGivesTheHumanLineAndTheComparison) {
  CommandResult r = Run("commonroad " + (dir_ / "set").string() + " --no-timing");
  ASSERT_EQ(r.exit_code, 0) << r.out << err_;
  EXPECT_THAT(r.out, ::testing::ContainsRegex(
                         "\n    human \\(KS1, steps 5-75\\):  WX1 [0-9.]+  JB1 7.0  to goal 63 "
                         "steps / 6.3 s \\(ours [0-9]+ steps / [0-9.]+ s\\)  moves 1.00x its "
                         "speed  human_verdict failed: start  -> (ours|human) cheaper\n"));
  EXPECT_THAT(r.out, HasSubstr("vs the reference (human) trajectories: 1 problem(s) with one, 0 "
                               "infeasible at start (not compared)\n  both reach the goal 1: "));
  EXPECT_THAT(r.out, HasSubstr("  only ours reaches the goal 0, only the human 0, neither 0\n"));
  // No solution files, no comparison.
  CommandResult plain = Run("commonroad " + (dir_ / "scenarios").string() + " --no-timing");
  ASSERT_EQ(plain.exit_code, 0);
  EXPECT_THAT(plain.out, Not(HasSubstr("human")));
  EXPECT_THAT(plain.out, Not(HasSubstr("vs the reference")));
  CommandResult plain_json = Run("commonroad " + (dir_ / "scenarios").string() + " --json --no-timing");
  EXPECT_FALSE(json::parse(plain_json.out).at("summary").contains("comparison"));
}

TEST_F(CommonRoadCompareTest, CompareTakesDirectoriesAndFilesOfSolutions) {
  const std::string scenarios = (dir_ / "scenarios").string();
  const std::string humans = (dir_ / "humans").string();
  CommandResult dir = Run("commonroad " + scenarios + " --compare " + humans + " --json --no-timing");
  ASSERT_EQ(dir.exit_code, 0) << dir.out << err_;
  const json a = json::parse(dir.out);
  const json* reach = FindScenario(a, "ZAM_Reach-1_1_T-1");
  ASSERT_NE(reach, nullptr);
  EXPECT_EQ(reach->at("problems")[0].at("reference").at("file"), (dir_ / "humans" / "reach.xml").string());
  EXPECT_EQ(a.at("summary").at("comparison").at("solution_files"), 1);  // README.xml skipped
  EXPECT_TRUE(err_.empty()) << err_;

  // A list, and the same file twice (by directory and by name): one reference.
  CommandResult list = Run("commonroad " + scenarios + " --compare " + humans + "," + humans +
                           "/reach.xml --json --no-timing");
  ASSERT_EQ(list.exit_code, 0) << err_;
  EXPECT_EQ(json::parse(list.out).at("summary").at("comparison"), a.at("summary").at("comparison"));
  CommandResult repeated = Run("commonroad --compare " + humans + " " + scenarios +
                               " --compare " + (dir_ / "set").string() + " --json --no-timing");
  ASSERT_EQ(repeated.exit_code, 0) << err_;
  const json doc = json::parse(repeated.out);
  const json& c = doc.at("summary").at("comparison");
  EXPECT_EQ(c.at("solution_files"), 2);  // reach.xml first; b_far.solution.xml a second, ignored
  EXPECT_EQ(c.at("unpaired_solution_files").size(), 1u);
  EXPECT_THAT(err_, HasSubstr((dir_ / "set" / "b_far.solution.xml").string() + ": ignored, " +
                              humans + "/reach.xml is already the solution for ZAM_Reach-1_1_T-1"));
}

TEST_F(CommonRoadCompareTest, BadSolutionFilesAndPathsFailClearly) {
  // A solution file that does not read is an unreadable file like a scenario (exit 1); a file
  // with any other root stays an unreadable scenario.
  const fs::path bad = dir_ / "bad";
  fs::create_directories(bad);
  std::ofstream(bad / "a_reach.xml") << ReachXml();
  std::string broken = cr::WriteSolution(Human("ZAM_Reach-1_1_T-1"));
  broken.replace(broken.find("KS1:TR2"), 7, "KS1:XY9");
  std::ofstream(bad / "b_broken.solution.xml") << broken;
  std::ofstream(bad / "c_other.xml") << "<?xml version=\"1.0\"?>\n<html><body/></html>\n";
  CommandResult r = Run("commonroad " + bad.string() + " --json --no-timing");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const json doc = json::parse(r.out);
  EXPECT_EQ(doc.at("summary").at("unreadable_files"), 2);
  std::vector<std::string> errors;
  for (const json& s : doc.at("scenarios")) {
    if (s.contains("error")) errors.push_back(s.at("error"));
  }
  ASSERT_EQ(errors.size(), 2u) << r.out;
  EXPECT_THAT(errors[0], HasSubstr("b_broken.solution.xml:2: "));  // in the paths' order
  EXPECT_THAT(errors[0], HasSubstr("'XY9' unknown"));
  EXPECT_THAT(errors[1], HasSubstr("c_other.xml"));
  EXPECT_THAT(errors[1], HasSubstr("commonRoad"));

  struct Case {
    std::string args, line;  // the whole output
  };
  const std::string scenarios = (dir_ / "scenarios").string();
  const Case cases[] = {
      {"commonroad " + (dir_ / "set" / "c_nowhere.solution.xml").string(),
       "no scenario files among the paths (1 solution file(s))"},
      {"commonroad " + scenarios + " --compare /nonexistent/humans",
       "--compare: /nonexistent/humans: no such file or directory"},
      {"commonroad " + scenarios + " --compare " + scenarios,
       "--compare " + scenarios + ": no CommonRoad solution files (*.xml)"},
  };
  for (const Case& c : cases) {
    CommandResult e = RunFrenetic(c.args + " 2>&1");
    EXPECT_EQ(e.exit_code, 1) << c.args << ": " << e.out;
    EXPECT_EQ(e.out, "frenetic commonroad: " + c.line + "\n") << c.args;
  }
}

// The highD set as it is: each scenario with its human driver's file beside it.
TEST_F(CommonRoadCompareTest, SharedHighDHumansAsRecorded) {
  const fs::path dir = fs::path(FRENETIC_SHARED_DIR) / "commonroad" / "highD";
  const std::string id = "DEU_LocationALower26-1_261504_T-1579";
  if (!fs::exists(dir / (id + ".cr.xml"))) GTEST_SKIP() << dir << " is absent";
  CommandResult r = Run("commonroad " + (dir / (id + ".cr.xml")).string() + " " +
                        (dir / (id + ".solution.xml")).string() + " --json --no-timing");
  ASSERT_EQ(r.exit_code, 0) << r.out << err_;
  const json doc = json::parse(r.out);
  ASSERT_EQ(doc.at("scenarios").size(), 1u);
  const json& ref = doc.at("scenarios")[0].at("problems")[0].at("reference");
  EXPECT_EQ(ref.at("vehicle"), "KS1");
  EXPECT_EQ(ref.at("cost_function"), "TR2");
  // The recording's frame: the human starts at step 40 where the problem starts at 0, and its
  // positions move about twice what its velocities say.
  EXPECT_EQ(ref.at("first_step"), 40);
  EXPECT_THAT(ref.at("human_verdict").get<std::string>(), HasSubstr("start"));
  EXPECT_THAT(ref.at("human_verdict").get<std::string>(), HasSubstr("dynamics"));
  EXPECT_NEAR(ref.at("distance_ratio").get<double>(), 2.0, 0.1);
  ASSERT_TRUE(ref.at("goal_step").is_number_integer()) << ref.dump();
  EXPECT_EQ(ref.at("time_to_goal_steps").get<int>(),
            ref.at("goal_step").get<int>() - ref.at("first_step").get<int>());
  EXPECT_GT(ref.at("costs").at("WX1").get<double>(), 0);
  EXPECT_TRUE(err_.empty()) << err_;
}

}  // namespace
}  // namespace frenetic::testing

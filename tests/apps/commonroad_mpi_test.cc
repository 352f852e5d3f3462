// `frenetic commonroad` under mpirun: the reports' exact text form, and the executable under
// `mpirun -n 2` printing byte for byte what one process prints (skipped when frenetic was built
// without MPI or mpirun is not installed).
#include "apps/commonroad_mpi.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "apps/commonroad_summary.h"
#include "apps_test_util.h"
#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/solution.h"

namespace frenetic::apps::commonroad_cli {
namespace {

namespace fs = std::filesystem;
namespace crt = commonroad::testing;
using ::testing::HasSubstr;

// Every field set, with numbers that need all their digits or are not finite.
FileReport Awkward() {
  FileReport f;
  f.path = "dir/a \"quoted\" name.xml";
  f.benchmark_id = "DEU_LocationALower26-1_261504_T-1579";
  f.origin = {613000.0, -0.0};
  f.dt = 0.1;
  f.solution_file = "solution_KS2:WX1:x:2020a.xml";
  f.solution_error = "";
  f.record_error = "out/x.jsonl.gz: No space left on device";
  ProblemReport p;
  p.problem_id = 100800;
  p.road_error = "";
  p.verdict.problem_id = 100800;
  p.verdict.goal_step = 53;
  cr::Failure collision;
  collision.kind = cr::FailureKind::kCollision;
  collision.step = 1;
  collision.detail = "the ego overlaps obstacle 10782 (car) at (4.58, -22.48)";
  collision.obstacle_id = 10782;
  collision.entered_s = 0.30000000000000004;
  cr::Failure dynamics;
  dynamics.kind = cr::FailureKind::kDynamics;
  dynamics.step = 7;
  p.verdict.failures = {collision, dynamics};
  p.verdict.infeasible_at_start = collision;
  p.stop = "goal";
  p.initial_step = 0;
  p.lanes = 3;
  p.road_length_m = 1.0 / 3.0;
  p.route = {1, 2, 30622};
  p.plan_ms = {0.1 + 0.2, 4.9406564584124654e-324, std::numeric_limits<double>::max(), -0.0,
               1e-310, 0.0};
  p.candidates = 1407.0 * 79;
  p.not_ok_cycles = 2;
  p.rescued_cycles = 5;
  p.tracking_error_max_m = std::nan("");
  p.computation_s = std::numeric_limits<double>::infinity();
  p.costs = {{"WX1", 438.53210987654321}, {"JB1", 7.9}};
  ReferenceReport r;
  r.file = "highD/x.solution.xml";
  r.vehicle_type = 1;
  r.cost_function = "TR2";
  r.first_step = 40;
  r.last_step = 75;
  r.states = 36;
  r.costs = {{"WX1", 336.0948600549656}, {"JB1", 3.5}};
  r.goal_step = 75;
  r.distance_ratio = 1.9535585655180756;
  r.verdict = "failed: start, dynamics";
  p.reference = r;
  p.way_through = commonroad::WayThrough{false, 75, 7, true, 12506, 64, 80};
  f.problems.push_back(p);
  ProblemReport plain;  // defaults: no goal, no reference
  plain.problem_id = 2;
  plain.road_error = "no lanelet under the ego";
  f.problems.push_back(plain);
  return f;
}

bool SameBits(double a, double b) {
  return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}

TEST(CommonRoadMpiTest, ReportsReadBackExactly) {
  FileReport unreadable;
  unreadable.path = "broken.xml";
  unreadable.error = "broken.xml:3: bad";
  const std::vector<FileReport> reports = {unreadable, FileReport{}, Awkward()};
  const std::string text = Serialise(reports, {0, 2});

  std::vector<FileReport> back(3);
  back[1].path = "left alone";
  ASSERT_TRUE(Deserialise(text, &back).ok());
  EXPECT_EQ(back[1].path, "left alone");  // not among the indices sent
  EXPECT_EQ(back[0].error, unreadable.error);
  const FileReport& a = reports[2];
  const FileReport& b = back[2];
  ASSERT_EQ(b.problems.size(), 2u);
  const ProblemReport &p = a.problems[0], &q = b.problems[0];
  ASSERT_EQ(q.plan_ms.size(), p.plan_ms.size());
  for (size_t i = 0; i < p.plan_ms.size(); ++i) EXPECT_TRUE(SameBits(q.plan_ms[i], p.plan_ms[i])) << i;
  EXPECT_TRUE(std::isnan(q.tracking_error_max_m));
  EXPECT_EQ(q.rescued_cycles, 5);
  EXPECT_EQ(q.computation_s, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(SameBits(b.origin.y, -0.0));
  EXPECT_TRUE(SameBits(q.road_length_m, 1.0 / 3.0));
  EXPECT_EQ(q.costs, p.costs);
  EXPECT_EQ(q.verdict.Summary(), p.verdict.Summary());
  ASSERT_EQ(q.verdict.failures.size(), 2u);
  EXPECT_EQ(q.verdict.failures[0].obstacle_id, 10782);
  EXPECT_FALSE(q.verdict.failures[1].obstacle_id.has_value());
  ASSERT_TRUE(q.verdict.failures[0].entered_s.has_value());
  EXPECT_TRUE(SameBits(*q.verdict.failures[0].entered_s, 0.30000000000000004));
  EXPECT_FALSE(q.verdict.failures[1].entered_s.has_value());
  ASSERT_TRUE(q.reference.has_value());
  EXPECT_EQ(q.reference->costs, p.reference->costs);
  EXPECT_EQ(q.reference->goal_step, 75);
  EXPECT_FALSE(b.problems[1].reference.has_value());
  ASSERT_TRUE(q.way_through.has_value());
  EXPECT_EQ(q.way_through->survived_to, 7);
  EXPECT_EQ(q.way_through->checked, 12506);
  EXPECT_TRUE(q.way_through->exhaustive);
  EXPECT_EQ(q.way_through->goal_step, 64);
  EXPECT_EQ(q.way_through->goal_searched_to, 80);
  EXPECT_FALSE(b.problems[1].way_through.has_value());
  EXPECT_FALSE(b.problems[1].verdict.goal_step.has_value());
  // What the output is made of reads the same.
  EXPECT_EQ(FileJson(b).dump(), FileJson(a).dump());
  EXPECT_EQ(FileText(b), FileText(a));
  const SummarySettings settings{"recorded", 2};
  EXPECT_EQ(SummaryJson(Summarise(back), settings).dump(),
            SummaryJson(Summarise({unreadable, FileReport{}, Awkward()}), settings).dump());
  // Sent again, the same text.
  EXPECT_EQ(Serialise(back, {0, 2}), text);
}

TEST(CommonRoadMpiTest, BrokenTextIsAnErrorNotACrash) {
  std::vector<FileReport> reports(2);
  EXPECT_FALSE(Deserialise("[{\"index\": 1}]", &reports).ok());
  EXPECT_FALSE(Deserialise("not json", &reports).ok());
  const Status out_of_range = Deserialise(Serialise(std::vector<FileReport>(5), {4}), &reports);
  EXPECT_FALSE(out_of_range.ok());
  EXPECT_THAT(out_of_range.message(), HasSubstr("file 4 of 2"));
}

TEST(CommonRoadMpiTest, OneProcessRunsEveryFile) {
  const tune::Cluster& local = tune::Cluster::Local();
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(RunsHere(i, local));
  std::vector<FileReport> reports(2);
  reports[0].path = "a";
  EXPECT_TRUE(GatherReports(local, &reports).ok());
  EXPECT_EQ(reports[0].path, "a");
}

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Five files on two ranks (rank 0 gets three): solved, unsolved, infeasible at start,
// unreadable, and a reference beside them.
TEST(CommonRoadMpiTest, MpirunPrintsWhatOneProcessPrints) {
#ifndef FRENETIC_HAVE_MPI
  GTEST_SKIP() << "frenetic was built without MPI (FRENETIC_HAVE_MPI unset)";
#else
  if (!fs::exists(FRENETIC_BINARY)) GTEST_SKIP() << "no executable at " << FRENETIC_BINARY;
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const fs::path dir = fs::temp_directory_path() / ("frenetic_cr_mpi_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string goal = crt::GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90);
  {
    crt::ScenarioXml reach("ZAM_Reach-1_1_T-1");
    crt::AddStraightRoad(reach, 400).Problem(1, {10, -1.75}, 0, 20, {goal});
    std::ofstream(dir / "a_reach.xml") << reach.Str();
    crt::ScenarioXml far("ZAM_Far-1_1_T-1");
    crt::AddStraightRoad(far, 800).Problem(
        1, {10, -1.75}, 0, 20, {crt::GoalRectangleXml({600, -1.75}, 10, 3, 0, 0, 30)});
    std::ofstream(dir / "b_far.xml") << far.Str();
    crt::ScenarioXml blocked("ZAM_Blocked-2_1_T-1");
    crt::AddStraightRoad(blocked, 400).StaticObstacle(9, 4.5, 2, {12, -1.75}, 0).Problem(
        1, {10, -1.75}, 0, 20, {goal});
    std::ofstream(dir / "c_blocked.xml") << blocked.Str();
    std::ofstream(dir / "d_broken.xml") << "<commonRoad benchmarkID=\"x\">\n<lanelet id=\"1\">\n";
    commonroad::Solution human;
    human.scenario_id = "ZAM_Reach-1_1_T-1";
    commonroad::SolutionTrajectory t;
    t.problem_id = 1;
    for (int k = 3; k <= 80; ++k) {
      commonroad::KsState s;
      s.time_step = k;
      s.x = 10 + 2.0 * k;
      s.y = -1.75;
      s.velocity = 20;
      t.states.push_back(s);
    }
    human.trajectories.push_back(t);
    std::ofstream(dir / "e_reach.solution.xml") << commonroad::WriteSolution(human);
    std::ofstream(dir / "f_reach_again.xml") << reach.Str();
  }
  const std::string args = " commonroad " + dir.string() + " --no-timing";
  auto run = [&](const std::string& prefix, const std::string& options, const std::string& name) {
    return testing::RunFrenetic(prefix + args + options + " 2>" + (dir / name).string());
  };
  const std::string mpirun = "mpirun --allow-run-as-root --oversubscribe -n 2 ";
  // RunFrenetic puts the executable first: mpirun goes in front by hand.
  auto run_mpi = [&](const std::string& options, const std::string& name) {
    testing::CommandResult r;
    const std::string cmd = mpirun + FRENETIC_BINARY + args + options + " 2>" + (dir / name).string();
    FILE* pipe = popen(cmd.c_str(), "r");
    std::array<char, 4096> buf;
    for (size_t n; pipe && (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) r.out.append(buf.data(), n);
    const int status = pipe ? pclose(pipe) : -1;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
  };
  const testing::CommandResult one = run("", " --json --jobs 1", "one.err");
  const testing::CommandResult two = run_mpi(" --json --jobs 2", "mpi.err");
  EXPECT_EQ(one.exit_code, 1) << ReadFile(dir / "one.err");  // d_broken.xml
  EXPECT_NE(two.exit_code, 0) << ReadFile(dir / "mpi.err");
  ASSERT_FALSE(one.out.empty());
  EXPECT_EQ(two.out, one.out);  // byte for byte
  const nlohmann::json doc = nlohmann::json::parse(one.out);
  EXPECT_EQ(doc.at("scenarios").size(), 5u);
  EXPECT_EQ(doc.at("summary").at("infeasible_at_start"), 1);
  EXPECT_EQ(doc.at("summary").at("unreadable_files"), 1);
  EXPECT_EQ(doc.at("summary").at("comparison").at("with_reference"), 2);

  const testing::CommandResult text_one = run("", " --jobs 2", "one_text.err");
  const testing::CommandResult text_two = run_mpi(" --jobs 1", "mpi_text.err");
  EXPECT_EQ(text_two.out, text_one.out);
  EXPECT_THAT(text_one.out, HasSubstr("human (KS2, steps 3-80)"));
  fs::remove_all(dir);
#endif
}

}  // namespace
}  // namespace frenetic::apps::commonroad_cli

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/solution.h"

namespace frenetic::commonroad {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using testing::LineOf;

Solution Sample() {
  Solution s;
  s.scenario_id = "DEU_A9-2_1_T-1";
  s.date = "2024-05-01T12:30:00";
  s.computation_time = 0.8125;
  s.processor_name = "Test CPU <2 GHz> & co";
  SolutionTrajectory t;
  t.problem_id = 10;
  for (int k = 0; k < 30; ++k) {
    KsState st;
    st.time_step = k;
    st.x = 0.1 * k + 1.0 / 3.0;  // values that need all 17 digits
    st.y = std::sin(0.01 * k) * 1e-7;
    st.steering_angle = -0.0123456789012345 * k;
    st.velocity = 33 - 0.07 * k;
    st.orientation = 0.001 * k * k;
    t.states.push_back(st);
  }
  s.trajectories.push_back(t);
  return s;
}

TEST(SolutionTest, BenchmarkIdAndFileNameAsCommonRoadNamesThem) {
  Solution s = Sample();
  EXPECT_EQ(s.BenchmarkId(), "KS2:WX1:DEU_A9-2_1_T-1:2020a");
  EXPECT_EQ(s.FileName(), "solution_KS2:WX1:DEU_A9-2_1_T-1:2020a.xml");
  s.trajectories.push_back(s.trajectories[0]);
  s.trajectories[1].problem_id = 11;
  s.trajectories[1].vehicle_type = 3;
  s.trajectories[1].cost_function = "JB1";
  EXPECT_EQ(s.BenchmarkId(), "[KS2,KS3]:[WX1,JB1]:DEU_A9-2_1_T-1:2020a");
}

TEST(SolutionTest, WrittenInCommonRoadsElementNames) {
  const std::string xml = WriteSolution(Sample());
  EXPECT_THAT(xml, StartsWith("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<CommonRoadSolution "));
  EXPECT_THAT(xml, HasSubstr("benchmark_id=\"KS2:WX1:DEU_A9-2_1_T-1:2020a\""));
  EXPECT_THAT(xml, HasSubstr("computation_time=\"0.8125\""));
  EXPECT_THAT(xml, HasSubstr("date=\"2024-05-01T12:30:00\""));
  EXPECT_THAT(xml, HasSubstr("processor_name=\"Test CPU &lt;2 GHz> &amp; co\""));
  EXPECT_THAT(xml, HasSubstr("<ksTrajectory planningProblem=\"10\">"));
  // commonroad-io's field order.
  const size_t state = xml.find("<ksState>");
  ASSERT_NE(state, std::string::npos);
  size_t last = state;
  for (const char* field : {"<x>", "<y>", "<steeringAngle>", "<velocity>", "<orientation>",
                            "<time>0</time>"}) {
    const size_t at = xml.find(field, state);
    ASSERT_NE(at, std::string::npos) << field;
    EXPECT_GT(at, last) << field;
    last = at;
  }
}

TEST(SolutionTest, WriteReadRoundTripIsExact) {
  const Solution s = Sample();
  const StatusOr<Solution> r = ParseSolution(WriteSolution(s), "round.xml");
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r->scenario_id, s.scenario_id);
  EXPECT_EQ(r->version, "2020a");
  EXPECT_EQ(r->date, s.date);
  EXPECT_EQ(r->computation_time, s.computation_time);
  EXPECT_EQ(r->processor_name, s.processor_name);
  EXPECT_EQ(r->BenchmarkId(), s.BenchmarkId());
  ASSERT_EQ(r->trajectories.size(), 1u);
  const SolutionTrajectory& a = s.trajectories[0];
  const SolutionTrajectory& b = r->trajectories[0];
  EXPECT_EQ(b.problem_id, 10);
  EXPECT_EQ(b.vehicle_type, 2);
  EXPECT_EQ(b.cost_function, "WX1");
  ASSERT_EQ(a.states.size(), b.states.size());
  for (size_t i = 0; i < a.states.size(); ++i) {
    EXPECT_EQ(a.states[i].time_step, b.states[i].time_step);
    EXPECT_EQ(a.states[i].x, b.states[i].x);  // bit for bit
    EXPECT_EQ(a.states[i].y, b.states[i].y);
    EXPECT_EQ(a.states[i].steering_angle, b.states[i].steering_angle);
    EXPECT_EQ(a.states[i].velocity, b.states[i].velocity);
    EXPECT_EQ(a.states[i].orientation, b.states[i].orientation);
  }
}

TEST(SolutionTest, SavedUnderItsOwnNameAndLoadedBack) {
  // A fresh directory: a file left by an earlier run must not stand in for this one's.
  const std::filesystem::path base =
      std::filesystem::path(::testing::TempDir()) / "frenetic_solution_test";
  std::filesystem::remove_all(base);
  std::filesystem::create_directories(base);
  const std::string dir = base.string();
  Solution s = Sample();
  s.trajectories.push_back(s.trajectories[0]);
  s.trajectories[1].problem_id = 11;
  ASSERT_TRUE(SaveSolution(s, dir).ok());
  const std::string path = dir + "/solution_[KS2,KS2]:[WX1,WX1]:DEU_A9-2_1_T-1:2020a.xml";
  ASSERT_TRUE(std::filesystem::exists(path));
  const StatusOr<Solution> r = LoadSolution(path);
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_EQ(r->trajectories.size(), 2u);
  EXPECT_EQ(r->trajectories[1].problem_id, 11);
  EXPECT_FALSE(SaveSolution(s, "/nonexistent/dir").ok());
  EXPECT_FALSE(LoadSolution(dir + "/missing.xml").ok());
}

// As commonroad-io's CommonRoadSolutionWriter writes it (minidom's pretty print), states out of
// order.
constexpr const char* kCommonRoadIoFile = R"(<?xml version="1.0" ?>
<CommonRoadSolution benchmark_id="KS2:JB1:USA_US101-10_1_T-1:2020a" computation_time="42.5" date="2020-12-01T10:00:00" processor_name="Intel Core i7-8700K CPU @ 3.70GHz">
	<ksTrajectory planningProblem="543">
		<ksState>
			<x>0.93</x>
			<y>-1.0</y>
			<steeringAngle>0.0</steeringAngle>
			<velocity>9.4</velocity>
			<orientation>-0.8362</orientation>
			<time>1</time>
		</ksState>
		<ksState>
			<x>0.0</x>
			<y>0.0</y>
			<steeringAngle>0.0</steeringAngle>
			<velocity>9.336</velocity>
			<orientation>-0.8362</orientation>
			<time>0</time>
		</ksState>
	</ksTrajectory>
</CommonRoadSolution>
)";

TEST(SolutionTest, ReadsCommonRoadIoOutput) {
  const StatusOr<Solution> r = ParseSolution(kCommonRoadIoFile, "io.xml");
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r->scenario_id, "USA_US101-10_1_T-1");
  EXPECT_EQ(r->computation_time, 42.5);
  ASSERT_EQ(r->trajectories.size(), 1u);
  const SolutionTrajectory& t = r->trajectories[0];
  EXPECT_EQ(t.problem_id, 543);
  EXPECT_EQ(t.cost_function, "JB1");
  ASSERT_EQ(t.states.size(), 2u);
  EXPECT_EQ(t.states[0].time_step, 0);  // sorted
  EXPECT_DOUBLE_EQ(t.states[0].velocity, 9.336);
  EXPECT_DOUBLE_EQ(t.states[1].x, 0.93);
}

// The drivability checker's traffic-rule set names its cost function TR2 ("KS1:TR2:...").
TEST(SolutionTest, ReadsTheTrafficRuleCostIdAndVehicleOne) {
  std::string xml = kCommonRoadIoFile;
  xml.replace(xml.find("KS2:JB1"), 7, "KS1:TR2");
  const StatusOr<Solution> r = ParseSolution(xml, "tr2.xml");
  ASSERT_TRUE(r.ok()) << r.message();
  ASSERT_EQ(r->trajectories.size(), 1u);
  EXPECT_EQ(r->trajectories[0].cost_function, "TR2");
  EXPECT_EQ(r->trajectories[0].vehicle_type, 1);
  EXPECT_EQ(r->BenchmarkId(), "KS1:TR2:USA_US101-10_1_T-1:2020a");
}

// Every solution file of ../shared/commonroad/highD (the recorded human drivers) reads: KS1, TR2,
// one trajectory for the scenario beside it (named like the file, which the CLI does not rely on).
TEST(SolutionTest, ReadsTheSharedHighDSolutionFiles) {
  const std::filesystem::path dir = std::string(FRENETIC_SHARED_DIR "/commonroad/highD");
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > 13 && name.substr(name.size() - 13) == ".solution.xml") files.push_back(e.path());
  }
  if (files.empty()) GTEST_SKIP() << dir << " holds no solution files";
  EXPECT_EQ(files.size(), 30u);
  for (const std::filesystem::path& f : files) {
    SCOPED_TRACE(f.string());
    const StatusOr<Solution> r = LoadSolution(f.string());
    ASSERT_TRUE(r.ok()) << r.message();
    const std::string name = f.filename().string();
    EXPECT_EQ(r->scenario_id, name.substr(0, name.size() - 13));
    EXPECT_EQ(r->version, "2020a");
    ASSERT_EQ(r->trajectories.size(), 1u);
    EXPECT_EQ(r->trajectories[0].vehicle_type, 1);
    EXPECT_EQ(r->trajectories[0].cost_function, "TR2");
    EXPECT_GE(r->trajectories[0].states.size(), 2u);  // some are short: 2, 3, 7 states
  }
}

struct BadSolution {
  const char* name;
  std::string from, to;  // every `from` in kCommonRoadIoFile replaced
  std::string at;        // text on the line the error names
  std::string message;
};
void PrintTo(const BadSolution& c, std::ostream* os) { *os << c.name; }

class BadSolutionTest : public ::testing::TestWithParam<BadSolution> {};

TEST_P(BadSolutionTest, OneLineNamingTheLine) {
  const BadSolution& c = GetParam();
  std::string xml = kCommonRoadIoFile;
  ASSERT_NE(xml.find(c.from), std::string::npos);
  for (size_t at; (at = xml.find(c.from)) != std::string::npos;) xml.replace(at, c.from.size(), c.to);
  const StatusOr<Solution> r = ParseSolution(xml, "bad.xml");
  ASSERT_FALSE(r.ok()) << c.name;
  EXPECT_EQ(r.message().find('\n'), std::string::npos);
  EXPECT_THAT(r.message(), StartsWith("bad.xml:" + std::to_string(LineOf(xml, c.at)) + ": "))
      << r.message();
  EXPECT_THAT(r.message(), HasSubstr(c.message)) << r.message();
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadSolutionTest,
    ::testing::Values(
        BadSolution{"Root", "CommonRoadSolution", "Solution", "<Solution ",
                    "the root element must be <CommonRoadSolution>"},
        BadSolution{"ThreeFields", "KS2:JB1:USA", "KS2:USA", "<CommonRoadSolution ",
                    "is not <vehicle>:<cost>:<scenario>:<version>"},
        BadSolution{"PointMass", "KS2:JB1", "PM2:JB1", "<CommonRoadSolution ", "'PM2'"},
        BadSolution{"UnknownCost", "KS2:JB1", "KS2:XY9", "<CommonRoadSolution ", "'XY9' unknown"},
        BadSolution{"TwoVehiclesOneTrajectory", "KS2:JB1", "[KS2,KS2]:[JB1,JB1]",
                    "<CommonRoadSolution ", "lists 2 vehicle(s)"},
        BadSolution{"PmTrajectory", "ksTrajectory", "pmTrajectory", "<pmTrajectory",
                    "<pmTrajectory> is not supported (ksTrajectory only)"},
        BadSolution{"MissingX", "<x>0.0</x>", "", "<ksState>\n\t\t\t\n", "missing <x>"},
        BadSolution{"NaN", "<velocity>9.4</velocity>", "<velocity>nan</velocity>", "<velocity>nan",
                    "'nan' is not a finite number"},
        BadSolution{"RepeatedTime", "<time>1</time>", "<time>0</time>",
                    "<ksState>\n\t\t\t<x>0.0</x>", "time step 0 repeated"},
        BadSolution{"BadTime", "<time>1</time>", "<time>1.5</time>", "<time>1.5", "not an integer"},
        BadSolution{"MissingProblem", "planningProblem=\"543\"", "", "<ksTrajectory",
                    "missing attribute planningProblem"},
        BadSolution{"ComputationTime", "computation_time=\"42.5\"", "computation_time=\"soon\"",
                    "<CommonRoadSolution ", "computation_time 'soon'"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(SolutionTest, PeekRootElementNamesTheRootWithoutParsing) {
  EXPECT_EQ(PeekRootElementOf(kCommonRoadIoFile), "CommonRoadSolution");
  EXPECT_EQ(PeekRootElementOf(WriteSolution(Sample())), "CommonRoadSolution");
  EXPECT_EQ(PeekRootElementOf("<commonRoad timeStepSize=\"0.1\">"), "commonRoad");
  // What may come before the root.
  EXPECT_EQ(PeekRootElementOf("\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<!-- <commonRoad> -->\n"
                              "<!DOCTYPE s [<!ENTITY a \"<b>\">]>\n<?pi x?><CommonRoadSolution/>"),
            "CommonRoadSolution");
  EXPECT_EQ(PeekRootElementOf("<commonRoad>"), "commonRoad");
  // The rest of the document is not read: an unclosed root still has its name.
  EXPECT_EQ(PeekRootElementOf("<CommonRoadSolution benchmark_id=\"x"), "CommonRoadSolution");
  EXPECT_EQ(PeekRootElementOf(""), "");
  EXPECT_EQ(PeekRootElementOf("not xml at all"), "");
  EXPECT_EQ(PeekRootElementOf("<!-- never closed <commonRoad>"), "");
  EXPECT_EQ(PeekRootElementOf("<commonRoad"), "");  // cut before the name ends

  const std::string dir = ::testing::TempDir() + "/frenetic_peek_test";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(SaveSolution(Sample(), dir).ok());
  EXPECT_EQ(PeekRootElement(dir + "/" + Sample().FileName()), "CommonRoadSolution");
  EXPECT_EQ(PeekRootElement(dir + "/missing.xml"), "");
  EXPECT_EQ(PeekRootElement(dir), "");  // a directory
}

TEST(SolutionTest, ProcessorNameAndDateHelpers) {
  const std::string date = CurrentDate();
  ASSERT_EQ(date.size(), 19u);
  EXPECT_EQ(date[10], 'T');
  const std::string cpu = ProcessorName();  // may be empty on machines without /proc/cpuinfo
  EXPECT_EQ(cpu.find("(R)"), std::string::npos);
  EXPECT_EQ(cpu.find("(TM)"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::commonroad

// `frenetic commonroad --record DIR` as a user runs it, on a hand-made scenario written by the
// test: one record per planning problem that the report's reader reads back (the road's lane
// borders, the goal, the cars with their sizes, one exchange per step run), a page drawn from
// it, results that do not change with --record, and a one-line error for an unwritable DIR.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "apps_test_util.h"
#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/record.h"
#include "frenetic/record/reader.h"
#include "frenetic/report/page.h"

namespace frenetic::testing {
namespace {

namespace fs = std::filesystem;
namespace crt = commonroad::testing;
using nlohmann::json;
using ::testing::HasSubstr;

// Two lanes; the ego in the right one with a goal 140 m ahead within 5-9 s; a car of 4.8 x 2 m
// passing in the left lane and a parked one of 4 x 2 m in the right lane beyond the goal.
std::string TrafficXml() {
  crt::ScenarioXml xml("ZAM_RecordTest-1_1_T-1");
  crt::AddStraightRoad(xml, 400);
  std::vector<crt::StateXml> states;
  for (int k = 0; k <= 100; ++k) states.push_back({k, {40 + 22.0 * 0.1 * k, 1.75}, 0, 22});
  xml.DynamicObstacle(31, 4.8, 2.0, states);
  xml.StaticObstacle(30, 4.0, 2.0, {230, -1.75}, 0);
  xml.Problem(1, {10, -1.75}, 0, 20, {crt::GoalRectangleXml({150, -1.75}, 10, 3, 0, 50, 90)});
  return xml.Str();
}

class CommonRoadRecordTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("frenetic_cr_record_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(Scenario()) << TrafficXml();
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  void SetUp() override {
    if (!fs::exists(FRENETIC_BINARY)) GTEST_SKIP() << "no executable at " << FRENETIC_BINARY;
  }
  static std::string Scenario() { return (dir_ / "traffic.xml").string(); }
  static inline fs::path dir_;
};

TEST_F(CommonRoadRecordTest, RecordReadsBackWithLanesCarsAndOneExchangePerStep) {
  const fs::path records = dir_ / "records";  // created by the command
  CommandResult with =
      RunFrenetic("commonroad " + Scenario() + " --json --no-timing --record " + records.string());
  ASSERT_EQ(with.exit_code, 0) << with.out;
  CommandResult without = RunFrenetic("commonroad " + Scenario() + " --json --no-timing");
  ASSERT_EQ(without.exit_code, 0);
  EXPECT_EQ(with.out, without.out) << "--record changed the results";

  const json j = json::parse(with.out);
  const json& p = j["scenarios"][0]["problems"][0];
  const int steps = p["steps"].get<int>();
  ASSERT_GT(steps, 10);
  const fs::path file = records / commonroad::RecordFileName("ZAM_RecordTest-1_1_T-1", 1);
  EXPECT_EQ(file.filename().string(), "ZAM_RecordTest-1_1_T-1_1.jsonl.gz");
  ASSERT_TRUE(fs::exists(file)) << file;
  EXPECT_EQ(std::vector<fs::path>(fs::directory_iterator(records), {}).size(), 1u);

  auto run = record::ReadRecordFile(file.string());
  ASSERT_TRUE(run.ok()) << run.message();
  const record::RecordHeader& h = run->header;
  EXPECT_EQ(h.world, "commonroad");
  EXPECT_EQ(h.scenario, "ZAM_RecordTest-1_1_T-1");
  EXPECT_EQ(h.problem, 1);
  EXPECT_DOUBLE_EQ(h.dt, 0.1);
  EXPECT_EQ(h.lanes, p["lanes"].get<int>());
  EXPECT_NEAR(h.car_length, 4.508, 1e-9);  // the KS2 ego
  EXPECT_NEAR(h.car_width, 1.61, 1e-9);
  // The road's two lanes: borders along y = 3.5, 0 and -3.5 over the road's length.
  ASSERT_EQ(h.road_lanes.size(), 2u);
  const double border_y[2][2] = {{3.5, 0.0}, {0.0, -3.5}};
  for (int l = 0; l < 2; ++l) {
    const record::RecordHeader::Lane& lane = h.road_lanes[l];
    ASSERT_GT(lane.left.x.size(), 100u);
    ASSERT_EQ(lane.left.x.size(), lane.left.y.size());
    ASSERT_EQ(lane.right.x.size(), lane.right.y.size());
    EXPECT_GT(lane.left.x.back() - lane.left.x.front(), 350);
    for (size_t i = 0; i < lane.left.y.size(); ++i)
      EXPECT_NEAR(lane.left.y[i], border_y[l][0], 0.05);
    for (size_t i = 0; i < lane.right.y.size(); ++i)
      EXPECT_NEAR(lane.right.y[i], border_y[l][1], 0.05);
  }
  ASSERT_EQ(h.goals.size(), 1u);
  EXPECT_EQ(h.goals[0].outline.x.size(), 4u);
  EXPECT_EQ(h.goals[0].step_lo, 50);
  EXPECT_EQ(h.goals[0].step_hi, 90);

  // One exchange per step run, at t = step * dt from the initial step.
  ASSERT_EQ(run->size(), steps);
  EXPECT_DOUBLE_EQ(run->t.front(), 0.0);
  EXPECT_NEAR(run->t.back(), (steps - 1) * 0.1, 1e-9);
  EXPECT_NEAR(run->x.front(), 10, 1e-6);
  EXPECT_NEAR(run->y.front(), -1.75, 1e-6);
  EXPECT_GT(run->path_offset[1], run->path_offset[0]);                  // the plan's path
  EXPECT_EQ(run->candidate_cycles.size(), static_cast<size_t>(steps));  // replica never diverged
  // Both cars at the first step with their sizes; the parked one at its own heading.
  ASSERT_EQ(run->traffic_offset.size(), static_cast<size_t>(steps) + 1);
  std::vector<int> ids(run->traffic_id.begin() + run->traffic_offset[0],
                       run->traffic_id.begin() + run->traffic_offset[1]);
  EXPECT_THAT(ids, ::testing::UnorderedElementsAre(30, 31));
  for (int i = run->traffic_offset[0]; i < run->traffic_offset[1]; ++i) {
    const bool moving = run->traffic_id[i] == 31;
    EXPECT_NEAR(run->traffic_length[i], moving ? 4.8 : 4.0, 1e-6);
    EXPECT_NEAR(run->traffic_width[i], 2.0, 1e-6);
    EXPECT_NEAR(run->traffic_heading_deg[i], 0.0, 1e-6);
    if (moving) {
      EXPECT_NEAR(run->traffic_x[i], 40, 1e-6);
    }
  }
  // The footer holds the verdict.
  ASSERT_TRUE(run->has_footer);
  const json footer = json::parse(run->footer_json);
  EXPECT_EQ(footer["solved"], p["solved"]);
  EXPECT_EQ(footer["steps"].get<int>(), steps);
  EXPECT_EQ(footer["stop_reason"], p["stop"]);

  // The page: CommonRoad's script, the lane geometry and the cars' sizes in its data.
  const std::string page = report::RenderPage(*run, file.string());
  EXPECT_THAT(page, HasSubstr("\"world\":\"commonroad\""));
  EXPECT_THAT(page, HasSubstr("\"road\":[{\"lx\":["));
  EXPECT_THAT(page, HasSubstr("\"goals\":[{\"x\":["));
  EXPECT_THAT(page, HasSubstr("\"l\":[4,4.8,"));
  EXPECT_THAT(page, HasSubstr("D.traffic.l[j]"));  // the script draws each car's size

  // And as the user makes it.
  const fs::path html = dir_ / "page.html";
  CommandResult rep = RunFrenetic("report " + file.string() + " -o " + html.string());
  ASSERT_EQ(rep.exit_code, 0) << rep.out;
  EXPECT_THAT(rep.out, HasSubstr(std::to_string(steps) + " exchanges"));
  EXPECT_THAT(rep.out,
              HasSubstr(p["solved"].get<bool>() ? "; solved, goal at step " : "; NOT solved:"));
  EXPECT_GT(fs::file_size(html), 40000u);
}

// A car comes into the scene at step 5 in the ego's lane, 7 m behind it (2.5 m between the
// bumpers) and 40 m/s faster: it hits at once, whatever the ego does.
std::string EnteringXml() {
  crt::ScenarioXml xml("ZAM_Entering-1_1_T-1");
  crt::AddStraightRoad(xml, 400);
  std::vector<crt::StateXml> car;
  for (int k = 5; k <= 40; ++k)
    car.push_back({k, {10 + 20 * 0.5 - 7 + 60.0 * 0.1 * (k - 5), -1.75}, 0, 60});
  xml.DynamicObstacle(9, 4.5, 1.8, car);
  xml.Problem(1, {10, -1.75}, 0, 20, {crt::GoalTimeOnlyXml(30, 40)});
  return xml.Str();
}

TEST_F(CommonRoadRecordTest, ACarThatCameIntoTheSceneIsNamedInTheJsonTheRecordAndTheSummary) {
  const fs::path scenario = dir_ / "entering.xml";
  std::ofstream(scenario) << EnteringXml();
  const fs::path records = dir_ / "entering_records";
  CommandResult r = RunFrenetic("commonroad " + scenario.string() +
                                " --json --no-timing --no-rescue --record " + records.string());
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const json j = json::parse(r.out);
  const json& p = j["scenarios"][0]["problems"][0];
  ASSERT_FALSE(p["solved"].get<bool>());
  json hit;
  for (const json& f : p["failures"]) {
    if (f["kind"] == "collision") hit = f;
  }
  ASSERT_FALSE(hit.is_null()) << p.dump();
  EXPECT_EQ(hit["obstacle"], 9);
  // It came in at step 5 and hit within 0.3 s: the seconds between, the step in the detail.
  const double entered = hit["obstacle_entered_s"].get<double>();
  EXPECT_NEAR(entered, 0.1 * (hit["step"].get<int>() - 5), 1e-9);
  EXPECT_LE(entered, 0.3);
  EXPECT_THAT(hit["detail"].get<std::string>(), HasSubstr("in the scene from step 5, "));
  EXPECT_EQ(j["summary"]["collisions_entering"], 1);
  EXPECT_EQ(j["summary"]["families"]["ZAM_Entering"]["collisions_entering"], 1);
  // The record's footer carries the same.
  auto run = record::ReadRecordFile(
      (records / commonroad::RecordFileName("ZAM_Entering-1_1_T-1", 1)).string());
  ASSERT_TRUE(run.ok()) << run.message();
  ASSERT_TRUE(run->has_footer);
  const json footer = json::parse(run->footer_json);
  bool found = false;
  for (const json& f : footer["failures"]) {
    if (f["kind"] != "collision") continue;
    found = true;
    EXPECT_EQ(f["obstacle_entered_s"], hit["obstacle_entered_s"]);
  }
  EXPECT_TRUE(found) << footer.dump();
}

TEST_F(CommonRoadRecordTest, UnwritableDirIsAOneLineError) {
  const fs::path file = dir_ / "a_file";
  std::ofstream(file) << "x";
  for (const fs::path& bad : {file, file / "below"}) {
    CommandResult r =
        RunFrenetic("commonroad " + Scenario() + " --no-timing --record " + bad.string() + " 2>&1");
    EXPECT_EQ(r.exit_code, 1) << bad;
    EXPECT_THAT(r.out, HasSubstr("frenetic commonroad: --record " + bad.string()));
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  }
}

TEST_F(CommonRoadRecordTest, HelpTellsWhatRecordWrites) {
  CommandResult r = RunFrenetic("commonroad --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.out, HasSubstr("--record"));
  EXPECT_THAT(r.out, HasSubstr("jsonl.gz"));
}

TEST(CommonRoadRecordName, UnsafeCharactersBecomeUnderscores) {
  EXPECT_EQ(commonroad::RecordFileName("DEU_A9-2_1_T-1", 3), "DEU_A9-2_1_T-1_3.jsonl.gz");
  EXPECT_EQ(commonroad::RecordFileName("a/b c", 1), "a_b_c_1.jsonl.gz");
  EXPECT_EQ(commonroad::RecordFileName("", 2), "scenario_2.jsonl.gz");
}

}  // namespace
}  // namespace frenetic::testing

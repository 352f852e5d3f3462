#include "frenetic/report/page.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "record/synthetic_record.h"

namespace frenetic::report {
namespace {

using record::ReadRecord;
using record::RecordHeader;
using record::RunData;
namespace testing = record::testing;

using ::testing::HasSubstr;
using ::testing::Not;
using json = nlohmann::json;

RunData ReadSynthetic(const testing::SyntheticOptions& options) {
  std::istringstream in(testing::SyntheticRecord(options));
  auto run = ReadRecord(in, "run.jsonl");
  EXPECT_TRUE(run.ok()) << run.message();
  return std::move(run).value();
}

// The page without its data block.
std::string WithoutData(std::string page) {
  const std::string open = "<script id=\"frenetic-data\" type=\"application/json\">";
  const size_t begin = page.find(open);
  EXPECT_NE(begin, std::string::npos);
  const size_t end = page.find("</script>", begin);
  return page.erase(begin + open.size(), end - begin - open.size());
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(PageDataTest, IsValidJsonWithColumnsOfOneLength) {
  testing::SyntheticOptions options;
  options.exchanges = 50;
  options.incident = true;
  options.incident_at = 20;
  const RunData run = ReadSynthetic(options);
  const json data = json::parse(PageDataJson(run, "run.jsonl"));
  EXPECT_EQ(data["format"], "frenetic-report");
  EXPECT_EQ(data["version"], 1);
  EXPECT_EQ(data["n"], 50);
  for (const auto& [name, column] : data["ex"].items()) {
    EXPECT_EQ(column.size(), 50u) << name;
  }
  EXPECT_EQ(data["path"]["off"].size(), 51u);
  EXPECT_EQ(data["path"]["x"].size(), data["path"]["off"].back().get<size_t>());
  EXPECT_EQ(data["traffic"]["id"].size(), data["traffic"]["off"].back().get<size_t>());
  // Constant weights collapse to one number; values stay per exchange.
  ASSERT_EQ(data["terms"].size(), 3u);
  EXPECT_TRUE(data["terms"][0]["weight"].is_number());
  EXPECT_EQ(data["terms"][0]["value"].size(), 50u);
  ASSERT_EQ(data["incidents"].size(), 1u);
  EXPECT_EQ(data["incidents"][0]["e"], 20);
  EXPECT_EQ(data["incidents"][0]["kind"], "collision");
  EXPECT_EQ(data["header"]["lanes"], 3);
  EXPECT_EQ(data["header"]["config"]["weights"]["comfort"], 1.0);
  EXPECT_EQ(data["footer"]["incidents"], 1);
  // Candidate rows: [lane, end_speed, duration, total, flags, reject, x, y, costs].
  const json& c0 = data["candidates"][0];
  EXPECT_EQ(c0["e"], 0);
  EXPECT_EQ(c0["c"][0].size(), 9u);
  EXPECT_TRUE(c0["c"][0][5].is_string());  // rejected best candidate of cycle 0
  EXPECT_EQ(c0["c"][1][4], 3);             // checked and winner
  EXPECT_EQ(c0["c"][1][8].size(), 9u);     // three terms as (index, weight, value)
}

// A drive's data stays as it was before CommonRoad records: none of their keys.
TEST(PageDataTest, ADrivesDataHasNoCommonRoadParts) {
  testing::SyntheticOptions options;
  options.exchanges = 20;
  const RunData run = ReadSynthetic(options);
  const json data = json::parse(PageDataJson(run, "run.jsonl"));
  for (const char* key : {"world", "problem", "dt", "prediction", "vehicle"}) {
    EXPECT_FALSE(data["header"].contains(key)) << key;
  }
  EXPECT_FALSE(data.contains("road"));
  EXPECT_FALSE(data.contains("goals"));
  EXPECT_FALSE(data["traffic"].contains("l"));
  EXPECT_FALSE(data["traffic"].contains("w"));
}

// A CommonRoad record's header (commonroad/record.h) and rows with sizes and headings.
TEST(PageDataTest, ACommonRoadRecordHasItsRoadGoalsAndCarSizes) {
  const std::string text =
      R"({"type":"header","version":1,"world":"commonroad","scenario":"ZAM_X-1_1_T-1",)"
      R"("problem":7,"dt":0.1,"prediction":"recorded","vehicle":"KS2","lanes":1,)"
      R"("lane_width":3.5,"car_length":4.508,"car_width":1.61,)"
      R"("road":{"lanes":[{"left":{"x":[0,100],"y":[0,0]},)"
      R"("right":{"x":[0,100],"y":[-3.5,-3.5]}}]},)"
      R"("goals":[{"x":[90,100,100,90],"y":[0,0,-3.5,-3.5],"steps":[10,20]}]})"
      "\n"
      R"({"type":"exchange","i":0,"t":0,"telemetry":{"x":10,"y":-1.75,"yaw":0,"speed":40,"s":10,)"
      R"("d":1.75,"sensor_fusion":[[3,30,-1.75,0,0,30,1.75,4.8,2.0,90],[4,40,-1.75,5,0,40,1.75]]}})"
      "\n";
  std::istringstream in(text);
  auto run = ReadRecord(in, "cr.jsonl");
  ASSERT_TRUE(run.ok()) << run.message();
  const RecordHeader& h = run->header;
  EXPECT_EQ(h.world, "commonroad");
  EXPECT_EQ(h.problem, 7);
  ASSERT_EQ(h.road_lanes.size(), 1u);
  EXPECT_EQ(h.road_lanes[0].right.y, (std::vector<double>{-3.5, -3.5}));
  ASSERT_EQ(h.goals.size(), 1u);
  EXPECT_EQ(h.goals[0].step_lo, 10);
  EXPECT_EQ(h.goals[0].step_hi, 20);
  ASSERT_EQ(run->traffic_length.size(), 2u);
  EXPECT_EQ(run->traffic_length[0], 4.8);
  EXPECT_EQ(run->traffic_heading_deg[0], 90);       // the row's own, though it stands
  EXPECT_TRUE(std::isnan(run->traffic_length[1]));  // a drive's row: the header's size
  const json data = json::parse(PageDataJson(*run, "cr.jsonl"));
  EXPECT_EQ(data["header"]["world"], "commonroad");
  EXPECT_EQ(data["road"][0]["ry"], json::array({-3.5, -3.5}));
  EXPECT_EQ(data["goals"][0]["steps"], json::array({10, 20}));
  EXPECT_EQ(data["traffic"]["l"], json::array({4.8, nullptr}));
  // One page for both kinds of run: its script switches on the header's world, and only the
  // data differs.
  const std::string page = RenderPage(*run, "cr.jsonl");
  EXPECT_THAT(page, HasSubstr("D.traffic.l[j]"));
  EXPECT_THAT(page, HasSubstr(R"(H.world === "commonroad")"));
  testing::SyntheticOptions drive;
  drive.exchanges = 20;
  EXPECT_EQ(WithoutData(page), WithoutData(RenderPage(ReadSynthetic(drive), "run.jsonl")));
}

TEST(PageDataTest, RoundsNumbersAndWritesNullForMissing) {
  testing::SyntheticOptions options;
  options.exchanges = 40;
  RunData run = ReadSynthetic(options);
  run.x[0] = 1234.56789;
  run.gap[0] = std::nan("");
  run.y[0] = -0.001;
  const json data = json::parse(PageDataJson(run, "run.jsonl"));
  EXPECT_DOUBLE_EQ(data["ex"]["x"][0].get<double>(), 1234.57);
  EXPECT_TRUE(data["ex"]["gap"][0].is_null());
  EXPECT_EQ(data["ex"]["y"][0].dump(), "0");
  const std::string text = PageDataJson(run, "run.jsonl");
  EXPECT_THAT(text, Not(HasSubstr("1234.56789")));
  EXPECT_THAT(text, Not(HasSubstr("NaN")));
}

TEST(RenderPageTest, InlinesEverythingAndEscapesTheData) {
  testing::SyntheticOptions options;
  options.exchanges = 30;
  RunData run = ReadSynthetic(options);
  run.header.config_json = R"({"note":"</script><script>alert(1)</script> <!--"})";
  const std::string page = RenderPage(run, "run.jsonl");
  EXPECT_THAT(page, Not(HasSubstr("@FRENETIC_DATA@")));
  EXPECT_THAT(page, Not(HasSubstr("@FRENETIC_STYLE@")));
  EXPECT_THAT(page, Not(HasSubstr("@FRENETIC_SCRIPT@")));
  EXPECT_THAT(page, Not(HasSubstr("alert(1)</script>")));
  EXPECT_EQ(Count(page, "</script>"), Count(std::string(PageTemplate()), "</script>"));
  // Self-contained: nothing is fetched when the page opens.
  EXPECT_THAT(page, Not(HasSubstr("src=\"http")));
  EXPECT_THAT(page, Not(HasSubstr("href=\"http")));
  EXPECT_THAT(page, Not(HasSubstr("@import")));
  // The data block is the JSON of PageDataJson with '<' escaped.
  const std::string open = "<script id=\"frenetic-data\" type=\"application/json\">";
  const size_t begin = page.find(open);
  ASSERT_NE(begin, std::string::npos);
  const size_t end = page.find("</script>", begin);
  const json data = json::parse(page.substr(begin + open.size(), end - begin - open.size()));
  EXPECT_EQ(data["header"]["config"]["note"], "</script><script>alert(1)</script> <!--");
  EXPECT_EQ(data["n"], 30);
}

TEST(WriteFileTest, WritesAndNamesAnUnwritablePath) {
  const std::string path = ::testing::TempDir() + "/frenetic_report_write_test.html";
  ASSERT_TRUE(WriteFile(path, "abc").ok());
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "abc");
  std::remove(path.c_str());
  const Status bad = WriteFile("/nonexistent/dir/out.html", "abc");
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.message(), HasSubstr("/nonexistent/dir/out.html"));
}

}  // namespace
}  // namespace frenetic::report

// The record writer: plain and gzip files of the same drive hold the same text, the candidates a
// replica traces on the writer's thread are the ones the driving planner would have traced, and
// write failures are reported. (The schema itself: episode_test.cc.)
#include "frenetic/drive/record.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "frenetic/drive/episode.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/sanitizers.h"
#include "frenetic/sim/scenario.h"
#include "sim/sim_test_util.h"

namespace frenetic::sim {
namespace {

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The text of a gzip file (empty when it is not one, or is cut short).
std::string Gunzip(const std::string& bytes) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 16) != Z_OK) return "";
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  zs.avail_in = static_cast<uInt>(bytes.size());
  std::string out;
  char buf[1 << 16];
  int rc = Z_OK;
  while (rc == Z_OK) {
    zs.next_out = reinterpret_cast<Bytef*>(buf);
    zs.avail_out = sizeof buf;
    rc = inflate(&zs, Z_NO_FLUSH);
    out.append(buf, sizeof buf - zs.avail_out);
  }
  inflateEnd(&zs);
  return rc == Z_STREAM_END ? out : "";
}

std::unique_ptr<plan::Planner> SearchPlanner(const std::shared_ptr<const World>& world) {
  auto config = plan::PlannerConfig::LoadDefault();
  EXPECT_TRUE(config.ok()) << config.message();
  config->PinDeadlines();
  auto planner = plan::MakePlanner("search", *config, world->line);
  EXPECT_TRUE(planner.ok()) << planner.message();
  return std::move(planner).value();
}

// A 12 s drive of the search planner with dense traffic (so cycles have rejected candidates),
// recorded to `path` with timing off; with a replica, the driving planner does not trace. Under
// the sanitizers, which run it ten times slower, 6 s.
std::string Record(const std::shared_ptr<const World>& world, const std::string& path,
                   std::unique_ptr<plan::Planner> replica = nullptr) {
  auto writer = RecordWriter::Open(path);
  EXPECT_TRUE(writer.ok()) << writer.message();
  auto planner = SearchPlanner(world);
  RunOptions options;
  options.record = writer->get();
  options.timing = false;
  if (replica) {
    (*writer)->TraceByReplay(std::move(replica), options.trace_candidates);
    options.trace_candidates = 0;
  }
  auto scenario = LoadScenario("dense");
  EXPECT_TRUE(scenario.ok()) << scenario.message();
  // Seed 5: dense traffic whose candidates run into cars in most exchanges (the rejection
  // traces below need some).
  const double seconds = kUnderSanitizer ? 6 : 12;
  auto report =
      RunEpisode(world, *scenario, 5, EpisodeLimits{0, 0, seconds, 60}, *planner, options);
  EXPECT_TRUE(report.ok()) << report.message();
  EXPECT_TRUE((*writer)->status().ok());
  writer->reset();
  return ReadBytes(path);
}

std::vector<nlohmann::json> Lines(const std::string& text) {
  std::vector<nlohmann::json> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) rows.push_back(nlohmann::json::parse(line));
  return rows;
}

TEST(Record, AGzipRecordIsThePlainRecordCompressedAndBothAreStable) {
  FRENETIC_REQUIRE_UDACITY(world);
  const std::string dir = ::testing::TempDir();
  const std::string plain = Record(world, dir + "/rec.jsonl");
  const std::string gz = Record(world, dir + "/rec.jsonl.gz");
  ASSERT_GT(plain.size(), 1000u);
  ASSERT_GE(gz.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(gz[0]), 0x1f);
  EXPECT_EQ(static_cast<unsigned char>(gz[1]), 0x8b);
  EXPECT_EQ(Gunzip(gz), plain);
  EXPECT_LT(gz.size() * 4, plain.size());
  EXPECT_EQ(Record(world, dir + "/again.jsonl.gz"), gz) << "same seed, same bytes";
}

TEST(Record, CandidatePathsAreWrittenAtTheReportsTenthOfAMetre) {
  FRENETIC_REQUIRE_UDACITY(world);
  const auto rows = Lines(Record(world, ::testing::TempDir() + "/cand.jsonl"));
  int candidates = 0;
  for (const auto& row : rows) {
    if (row["type"] != "exchange") continue;
    for (const auto& c : row["plan"]["candidates"]) {
      ++candidates;
      for (const char* axis : {"x", "y"}) {
        for (const auto& v : c[axis]) {
          // The value as the page prints it with one decimal.
          const double d = v.get<double>();
          EXPECT_EQ(d, std::round(d * 10) / 10) << d;
        }
      }
    }
    // The path sent keeps its 0.1 mm.
    bool finer = false;
    for (const auto& v : row["path"]["x"])
      finer = finer || v.get<double>() != std::round(v.get<double>() * 10) / 10;
    EXPECT_TRUE(finer || row["path"]["x"].empty());
  }
  EXPECT_GT(candidates, 100);
}

// The replica traces on the writer's thread what the driving planner would have traced itself:
// the two records are the same bytes.
TEST(Record, AReplicaTracesTheCandidatesThePlannerWouldHave) {
  FRENETIC_REQUIRE_UDACITY(world);
  const std::string dir = ::testing::TempDir();
  const std::string traced = Record(world, dir + "/traced.jsonl");
  const std::string replayed = Record(world, dir + "/replayed.jsonl", SearchPlanner(world));
  ASSERT_FALSE(traced.empty());
  EXPECT_EQ(replayed, traced);
  int with_candidates = 0, with_rejections = 0;
  for (const auto& row : Lines(replayed)) {
    if (row["type"] != "exchange") continue;
    with_candidates += !row["plan"]["candidates"].empty();
    with_rejections += row["plan"]["rejections"]["collision"].get<int>() > 0;
  }
  EXPECT_GT(with_candidates, 10);
  EXPECT_GT(with_rejections, 0);
}

// A replica that plans otherwise is dropped with a warning; the record stays whole, its
// candidates left out from the first exchange that differs.
TEST(Record, AReplicaThatPlansOtherwiseIsDroppedAndTheRecordStaysWhole) {
  FRENETIC_REQUIRE_UDACITY(world);
  const std::string dir = ::testing::TempDir();
  auto replica = SearchPlanner(world);
  // Its first path is not the planner's.
  class Lagging : public plan::Planner {
   public:
    explicit Lagging(std::unique_ptr<plan::Planner> p) : p_(std::move(p)) {}
    const plan::PlanResult& Plan(const plan::Telemetry& t) override {
      if (first_) {
        first_ = false;
        empty_.x = {1, 2};
        empty_.y = {1, 2};
        return empty_;
      }
      return p_->Plan(t);
    }
    void Reset() override { p_->Reset(); }
    std::string_view name() const override { return "lagging"; }
    void set_trace(plan::CycleTrace* trace, int n) override { p_->set_trace(trace, n); }

   private:
    std::unique_ptr<plan::Planner> p_;
    plan::PlanResult empty_;
    bool first_ = true;
  };
  const auto rows =
      Lines(Record(world, dir + "/lagging.jsonl", std::make_unique<Lagging>(std::move(replica))));
  ASSERT_GT(rows.size(), 10u);
  EXPECT_EQ(rows.back()["type"], "footer");
  for (std::size_t i = 1; i + 1 < rows.size(); ++i) {
    EXPECT_TRUE(rows[i]["plan"]["candidates"].empty()) << i;
    EXPECT_TRUE(rows[i]["plan"].contains("candidates_generated")) << i;
  }
}

TEST(Record, WriteFailuresNameTheFileAndWhy) {
  auto missing = RecordWriter::Open("/nonexistent-dir/run.jsonl.gz");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("/nonexistent-dir/run.jsonl.gz: cannot write record"),
            std::string::npos)
      << missing.message();
  FRENETIC_REQUIRE_UDACITY(world);
  {
    const std::string path = "/dev/full";  // every write fails: no space left
    auto writer = RecordWriter::Open(path);
    ASSERT_TRUE(writer.ok()) << writer.message();
    testing::KeepLanePlanner planner(world->line, 18);
    RunOptions options;
    options.record = writer->get();
    options.timing = false;
    auto report = RunEpisode(world, Scenario(), 1, EpisodeLimits{0, 0, 5, 60}, planner, options);
    ASSERT_FALSE(report.ok()) << "the record could not be written";
    EXPECT_NE(report.message().find(path + ": write failed: No space left on device"),
              std::string::npos)
        << report.message();
  }
}

}  // namespace
}  // namespace frenetic::sim

#include "frenetic/record/reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <set>
#include <sstream>
#include <string>

#include "record/synthetic_record.h"

namespace frenetic::record {
namespace {

using ::testing::HasSubstr;
using testing::SyntheticOptions;
using testing::SyntheticRecord;

StatusOr<RunData> Read(const std::string& text, const ReadOptions& options = {}) {
  std::istringstream in(text);
  return ReadRecord(in, "run.jsonl", options);
}

// Replaces line `n` (1-based) of `text` with `line`.
std::string ReplaceLine(const std::string& text, int n, const std::string& line) {
  std::istringstream in(text);
  std::string out, l;
  for (int i = 1; std::getline(in, l); ++i) out += (i == n ? line : l) + "\n";
  return out;
}

TEST(ReadRecordTest, ReadsEveryExchangeIntoColumns) {
  SyntheticOptions options;
  options.exchanges = 120;
  auto run = Read(SyntheticRecord(options));
  ASSERT_TRUE(run.ok()) << run.message();
  ASSERT_EQ(run->size(), 120);
  EXPECT_EQ(run->lines, 122);  // header + exchanges + footer
  EXPECT_EQ(run->skipped_lines, 0);
  EXPECT_EQ(run->header.lanes, 3);
  EXPECT_DOUBLE_EQ(run->header.lane_width, 4.0);
  EXPECT_EQ(run->header.scenario, "synthetic");
  EXPECT_NEAR(run->header.max_s, 2 * M_PI * testing::kSyntheticRadius, 1e-9);
  EXPECT_EQ(run->header.center_x.size(), run->header.center_y.size());
  EXPECT_GT(run->header.center_x.size(), 700u);  // a 1571 m loop every 2 m
  EXPECT_THAT(run->header.config_json, HasSubstr("\"lane_change\":3.0"));
  for (const auto* column : {&run->x, &run->y, &run->speed_mph, &run->acc, &run->ms_total}) {
    EXPECT_EQ(static_cast<int>(column->size()), run->size());
  }
  EXPECT_DOUBLE_EQ(run->t[10], 1.0);
  EXPECT_EQ(run->cycle[10], 10);
  // Lane from metrics: starts in lane 1, ends in lane 0 after the lane change.
  EXPECT_EQ(run->lane.front(), 1);
  EXPECT_EQ(run->lane.back(), 0);
  ASSERT_EQ(run->terms.size(), 3u);
  EXPECT_EQ(run->terms[2].name, "lane_change");
  EXPECT_DOUBLE_EQ(run->terms[2].weight[5], 3.0);
  ASSERT_EQ(run->rejections.size(), 6u);  // every reason, lane_line never
  int rejected = 0;
  for (const CountColumn& c : run->rejections) {
    ASSERT_EQ(static_cast<int>(c.count.size()), run->size());
    for (int n : c.count) rejected += n;
  }
  EXPECT_EQ(rejected, 30);  // the best candidate fails every 4th cycle
  ASSERT_EQ(run->status_names.size(), 1u);
  EXPECT_EQ(run->status_names[0], "ok");
  EXPECT_TRUE(run->has_footer);
  EXPECT_THAT(run->footer_json, HasSubstr("\"plan_ms\":{\"max\":2.5,\"p50\":2.2,\"p99\":2.5}"));
  EXPECT_TRUE(run->incidents.empty());
}

TEST(ReadRecordTest, DecimatesPathAndFiltersTrafficByRange) {
  SyntheticOptions options;
  options.exchanges = 20;
  ReadOptions read;
  read.path_stride = 5;
  read.traffic_range = 1000;  // the whole loop
  auto run = Read(SyntheticRecord(options), read);
  ASSERT_TRUE(run.ok()) << run.message();
  ASSERT_EQ(static_cast<int>(run->path_offset.size()), run->size() + 1);
  // 50 points: indices 0, 5, ..., 45 and the last one.
  EXPECT_EQ(run->path_offset[1] - run->path_offset[0], 11);
  EXPECT_EQ(run->traffic_offset.back(), static_cast<int>(run->traffic_id.size()));
  const int all_cars = run->traffic_offset[1] - run->traffic_offset[0];
  EXPECT_EQ(all_cars, 6);
  read.traffic_range = 100;
  auto near = Read(SyntheticRecord(options), read);
  ASSERT_TRUE(near.ok());
  const int near_cars = near->traffic_offset[1] - near->traffic_offset[0];
  EXPECT_GT(near_cars, 0);
  EXPECT_LT(near_cars, all_cars);
  for (int j = near->traffic_offset[0]; j < near->traffic_offset[1]; ++j) {
    EXPECT_LE(std::hypot(near->traffic_x[j] - near->x[0], near->traffic_y[j] - near->y[0]), 100);
    EXPECT_TRUE(std::isfinite(near->traffic_heading_deg[j]));
  }
}

TEST(ReadRecordTest, KeepsTheWinnerBeyondMaxCandidates) {
  SyntheticOptions options;
  options.exchanges = 8;
  ReadOptions read;
  read.max_candidates = 1;
  auto run = Read(SyntheticRecord(options), read);
  ASSERT_TRUE(run.ok()) << run.message();
  ASSERT_EQ(run->candidate_cycles.size(), 8u);
  // Cycle 0: the best candidate was rejected, the second won; both are kept.
  const CycleCandidates& c0 = run->candidate_cycles[0];
  EXPECT_EQ(c0.listed, 6);
  ASSERT_EQ(c0.candidates.size(), 2u);
  EXPECT_FALSE(c0.candidates[0].reject.empty());
  EXPECT_TRUE(c0.candidates[1].winner);
  // Cycle 1: the best one won; only it is kept.
  ASSERT_EQ(run->candidate_cycles[1].candidates.size(), 1u);
  EXPECT_TRUE(run->candidate_cycles[1].candidates[0].winner);
  EXPECT_TRUE(run->candidate_cycles[1].candidates[0].reject.empty());
  ASSERT_EQ(c0.candidates[1].costs.size(), 3u);
  EXPECT_EQ(run->terms[c0.candidates[1].costs[2].term].name, "lane_change");
  EXPECT_EQ(c0.candidates[1].x.size(), 13u);
}

TEST(ReadRecordTest, CandidateCyclesStayWithinBudgetAndEvenlySpread) {
  SyntheticOptions options;
  options.exchanges = 300;
  ReadOptions read;
  read.max_candidate_cycles = 10;
  auto run = Read(SyntheticRecord(options), read);
  ASSERT_TRUE(run.ok()) << run.message();
  // Evenly spread cycles (multiples of one power-of-two stride) plus lane decisions.
  std::set<int> lane_changes;
  for (int k = 1; k < run->size(); ++k) {
    if (run->winner_lane[k] != run->winner_lane[k - 1]) lane_changes.insert(k);
  }
  int regular = 0;
  int previous = -1;
  for (const CycleCandidates& c : run->candidate_cycles) {
    EXPECT_GT(c.exchange, previous);  // sorted, no duplicates
    previous = c.exchange;
    if (lane_changes.count(c.exchange) == 0) {
      ++regular;
      EXPECT_EQ(c.exchange % 32, 0) << c.exchange;
    }
  }
  EXPECT_LE(regular, 10);
  EXPECT_GE(regular, 5);
  EXPECT_LE(static_cast<int>(run->candidate_cycles.size()), 20);
}

TEST(ReadRecordTest, IncidentPinsItsCycleAndTheOnesBefore) {
  SyntheticOptions options;
  options.exchanges = 300;
  options.incident = true;
  options.incident_at = 151;
  ReadOptions read;
  read.max_candidate_cycles = 8;
  auto run = Read(SyntheticRecord(options), read);
  ASSERT_TRUE(run.ok()) << run.message();
  ASSERT_EQ(run->incidents.size(), 1u);
  EXPECT_EQ(run->incidents[0].exchange, 151);
  EXPECT_EQ(run->incidents[0].kind, "collision");
  EXPECT_NEAR(run->incidents[0].t, 15.1, 1e-9);
  std::set<int> kept;
  for (const CycleCandidates& c : run->candidate_cycles) kept.insert(c.exchange);
  for (int k = 146; k <= 151; ++k) EXPECT_TRUE(kept.count(k)) << k;
  // A tight budget keeps the incident's own cycle first.
  read.max_candidate_cycles = 2;
  auto tight = Read(SyntheticRecord(options), read);
  ASSERT_TRUE(tight.ok());
  kept.clear();
  for (const CycleCandidates& c : tight->candidate_cycles) kept.insert(c.exchange);
  EXPECT_TRUE(kept.count(151));
  EXPECT_TRUE(kept.count(150));
  EXPECT_FALSE(kept.count(147));
}

TEST(ReadRecordTest, SkipsMalformedLinesNamingThem) {
  SyntheticOptions options;
  options.exchanges = 30;
  std::string text = SyntheticRecord(options);
  text = ReplaceLine(text, 5, "{\"type\":\"exchange\",\"t\":0.3,\"telemetry\":{\"x\":1");
  text = ReplaceLine(text, 9, "{\"type\":\"exchange\",\"i\":7,\"t\":0.7}");
  text = ReplaceLine(text, 12, "[1,2,3]");
  auto run = Read(text);
  ASSERT_TRUE(run.ok()) << run.message();
  EXPECT_EQ(run->size(), 27);
  EXPECT_EQ(run->skipped_lines, 3);
  ASSERT_EQ(run->warnings.size(), 3u);
  EXPECT_THAT(run->warnings[0], HasSubstr("line 5"));
  EXPECT_THAT(run->warnings[1], HasSubstr("line 9"));
  EXPECT_THAT(run->warnings[1], HasSubstr("telemetry"));
  EXPECT_THAT(run->warnings[2], HasSubstr("line 12"));
  ReadOptions read;
  read.max_warnings = 1;
  auto few = Read(text, read);
  ASSERT_TRUE(few.ok());
  EXPECT_EQ(few->skipped_lines, 3);
  EXPECT_EQ(few->warnings.size(), 1u);
}

TEST(ReadRecordTest, WrongTypesFallBackInsteadOfFailing) {
  SyntheticOptions options;
  options.exchanges = 3;
  std::string text = SyntheticRecord(options);
  text = ReplaceLine(
      text, 3,
      R"({"type":"exchange","i":"one","t":0.1,"telemetry":{"x":1,"y":2,"yaw":"north",)"
      R"("sensor_fusion":[[1,"a"],"car",[2,1,2,0,0,0,6]]},"path":{"x":[1,2],"y":"no"},)"
      R"("plan":{"rejections":{"speed":"many"},"winner_costs":[{"name":7},{"weight":1}],)"
      R"("candidates":[1,{"lane":"x","x":[1],"y":[2]}]},"metrics":{"gap":null},"incidents":[3]})");
  auto run = Read(text);
  ASSERT_TRUE(run.ok()) << run.message();
  ASSERT_EQ(run->size(), 3);
  EXPECT_EQ(run->skipped_lines, 0);
  EXPECT_DOUBLE_EQ(run->x[1], 1);
  EXPECT_DOUBLE_EQ(run->yaw_deg[1], 0);
  EXPECT_TRUE(std::isnan(run->gap[1]));
  EXPECT_EQ(run->traffic_offset[2] - run->traffic_offset[1], 1);  // only the well-formed car
  EXPECT_EQ(run->path_offset[2] - run->path_offset[1], 0);
}

TEST(ReadRecordTest, ErrorsNameWhatIsWrong) {
  SyntheticOptions options;
  options.exchanges = 3;
  const std::string text = SyntheticRecord(options);
  const std::string no_header = text.substr(text.find('\n') + 1);
  auto a = Read(no_header);
  ASSERT_FALSE(a.ok());
  EXPECT_THAT(a.message(), HasSubstr("run.jsonl:1: record has no header"));

  auto b = Read("");
  ASSERT_FALSE(b.ok());
  EXPECT_THAT(b.message(), HasSubstr("no header"));

  auto c = Read(text.substr(0, text.find('\n') + 1));
  ASSERT_FALSE(c.ok());
  EXPECT_THAT(c.message(), HasSubstr("no usable exchange"));

  auto d = Read(ReplaceLine(text, 1, R"({"type":"header","lane_width":-4})"));
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.message(), HasSubstr("run.jsonl:1: header: lane_width"));

  // A malformed first line is skipped; the header on line 2 still counts.
  auto e = Read("not json\n" + text);
  ASSERT_TRUE(e.ok()) << e.message();
  EXPECT_EQ(e->skipped_lines, 1);
  EXPECT_THAT(e->warnings[0], HasSubstr("line 1"));

  auto f = ReadRecordFile("/nonexistent/run.jsonl");
  ASSERT_FALSE(f.ok());
  EXPECT_THAT(f.message(), HasSubstr("/nonexistent/run.jsonl: cannot open"));

  ReadOptions bad;
  bad.max_candidates = 0;
  auto g = Read(text, bad);
  ASSERT_FALSE(g.ok());
  EXPECT_THAT(g.message(), HasSubstr("max_candidates"));
}

TEST(ReadRecordTest, RecordWithoutFooterStillReads) {
  SyntheticOptions options;
  options.exchanges = 10;
  options.footer = false;
  auto run = Read(SyntheticRecord(options));
  ASSERT_TRUE(run.ok()) << run.message();
  EXPECT_FALSE(run->has_footer);
  EXPECT_EQ(run->footer_json, "null");
  EXPECT_EQ(run->size(), 10);
}

// `text` as a gzip stream (as `drive --record run.jsonl.gz` writes it), in `members` gzip
// members one after another.
std::string Gzip(const std::string& text, int members = 1) {
  std::string out;
  const std::size_t step = text.size() / members + 1;
  for (std::size_t at = 0; at < text.size(); at += step) {
    z_stream zs{};
    EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
    const std::string part = text.substr(at, step);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(part.data()));
    zs.avail_in = static_cast<uInt>(part.size());
    std::string buf(deflateBound(&zs, zs.avail_in), '\0');
    zs.next_out = reinterpret_cast<Bytef*>(buf.data());
    zs.avail_out = static_cast<uInt>(buf.size());
    EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
    out += buf.substr(0, buf.size() - zs.avail_out);
    deflateEnd(&zs);
  }
  return out;
}

// A compressed record reads as its text does: the same columns, whether in one gzip member or
// several.
TEST(ReadRecordTest, AGzipRecordReadsAsItsText) {
  SyntheticOptions options;
  options.exchanges = 400;
  options.incident = true;
  const std::string text = SyntheticRecord(options);
  auto plain = Read(text);
  ASSERT_TRUE(plain.ok()) << plain.message();
  for (int members : {1, 3}) {
    auto gz = Read(Gzip(text, members));
    ASSERT_TRUE(gz.ok()) << gz.message();
    EXPECT_EQ(gz->size(), 400);
    EXPECT_TRUE(gz->warnings.empty()) << gz->warnings.front();
    EXPECT_EQ(gz->t, plain->t) << members;
    EXPECT_EQ(gz->x, plain->x) << members;
    EXPECT_EQ(gz->speed_mph, plain->speed_mph) << members;
    EXPECT_EQ(gz->path_x, plain->path_x) << members;
    EXPECT_EQ(gz->traffic_id, plain->traffic_id) << members;
    EXPECT_EQ(gz->candidate_cycles.size(), plain->candidate_cycles.size()) << members;
    EXPECT_EQ(gz->incidents.size(), plain->incidents.size()) << members;
    EXPECT_EQ(gz->header.config_json, plain->header.config_json) << members;
    EXPECT_EQ(gz->footer_json, plain->footer_json) << members;
  }
}

// A drive that died leaves its compressed record cut short: what is there reads, with a warning
// saying where it ends; damage in the middle ends it there too. With nothing usable, an error.
TEST(ReadRecordTest, ACutOrDamagedGzipRecordReadsUpToTheDamage) {
  SyntheticOptions options;
  options.exchanges = 2000;
  const std::string gz = Gzip(SyntheticRecord(options));
  auto cut = Read(gz.substr(0, gz.size() / 2));
  ASSERT_TRUE(cut.ok()) << cut.message();
  EXPECT_GT(cut->size(), 100);
  EXPECT_LT(cut->size(), 2000);
  EXPECT_FALSE(cut->has_footer);
  ASSERT_FALSE(cut->warnings.empty());
  EXPECT_THAT(cut->warnings.back(), HasSubstr("the compressed data ends early"));

  std::string damaged = gz;
  for (std::size_t i = gz.size() / 2; i < gz.size() / 2 + 64; ++i) damaged[i] = '\x55';
  auto bad = Read(damaged);
  ASSERT_TRUE(bad.ok()) << bad.message();
  EXPECT_LT(bad->size(), 2000);
  ASSERT_FALSE(bad->warnings.empty());
  EXPECT_THAT(bad->warnings.back(), HasSubstr("corrupt compressed data"));

  auto header_only = Read(gz.substr(0, 30));
  ASSERT_FALSE(header_only.ok());
  EXPECT_THAT(header_only.message(), HasSubstr("run.jsonl: the compressed data ends early"));
  auto garbage = Read(std::string("\x1f\x8bnot gzip at all"));
  ASSERT_FALSE(garbage.ok());
  EXPECT_THAT(garbage.message(), HasSubstr("run.jsonl: corrupt compressed data"));
}

}  // namespace
}  // namespace frenetic::record

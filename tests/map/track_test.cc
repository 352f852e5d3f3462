#include "frenetic/map/track.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace frenetic::map {
namespace {

constexpr const char* kGood =
    "0 0 0 0 -1\n"
    "100 0 100 1 0\n"
    "100 100 200 0 1\n"
    "0 100 300 -1 0\n";

// Expects a parse failure whose message names the source, the line and `what`.
void ExpectError(const std::string& text, const std::string& where, const std::string& what) {
  auto t = ParseTrack(text, "bad.csv");
  ASSERT_FALSE(t.ok()) << "accepted:\n" << text;
  EXPECT_NE(t.message().find(where), std::string::npos) << t.message();
  EXPECT_NE(t.message().find(what), std::string::npos) << t.message();
  EXPECT_EQ(t.message().find('\n'), std::string::npos) << "not one line: " << t.message();
}

TEST(TrackTest, ParsesSpaceSeparatedAndComputesMaxS) {
  auto t = ParseTrack(kGood, "square");
  ASSERT_TRUE(t.ok()) << t.message();
  ASSERT_EQ(t->waypoints.size(), 4u);
  EXPECT_DOUBLE_EQ(t->waypoints[2].x, 100);
  EXPECT_DOUBLE_EQ(t->waypoints[2].dy, 1);
  EXPECT_DOUBLE_EQ(t->max_s, 400);  // 300 + closing segment of 100 m
  EXPECT_EQ(t->source, "square");
}

TEST(TrackTest, ParsesCommaSeparatedBlankLinesAndNoTrailingNewline) {
  auto t = ParseTrack("\n0,0,0,0,-1\n\n100, 0, 100, 1, 0\r\n100,100,200,0,1\n0,100,300,-1,0", "c");
  ASSERT_TRUE(t.ok()) << t.message();
  EXPECT_EQ(t->waypoints.size(), 4u);
  EXPECT_DOUBLE_EQ(t->max_s, 400);
}

TEST(TrackTest, MaxSOverride) {
  auto t = ParseTrack(kGood, "square", 410.0);
  ASSERT_TRUE(t.ok()) << t.message();
  EXPECT_DOUBLE_EQ(t->max_s, 410);
  auto bad = ParseTrack(kGood, "square", 250.0);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("max_s"), std::string::npos) << bad.message();
}

TEST(TrackTest, RejectsWrongFieldCount) {
  ExpectError("0 0 0 0 -1\n100 0 100 1\n100 100 200 0 1\n0 100 300 -1 0\n",
              "bad.csv:2:", "expected 5 fields");
}
TEST(TrackTest, RejectsNonNumber) {
  ExpectError("0 0 0 0 -1\n100 0 100 1 0\n100 abc 200 0 1\n0 100 300 -1 0\n",
              "bad.csv:3:", "field y is not a number");
}
TEST(TrackTest, RejectsEmptyCommaField) {
  ExpectError("0 0 0 0 -1\n100,0,,1,0\n100 100 200 0 1\n0 100 300 -1 0\n",
              "bad.csv:2:", "malformed row");
}
TEST(TrackTest, RejectsNaN) {
  ExpectError("0 0 0 0 -1\n100 0 100 1 0\n100 100 nan 0 1\n0 100 300 -1 0\n",
              "bad.csv:3:", "field s is not finite");
}
TEST(TrackTest, RejectsInfinity) {
  ExpectError("0 0 0 0 -1\n100 0 100 1 0\n100 100 200 0 1\ninf 100 300 -1 0\n",
              "bad.csv:4:", "field x is not finite");
}
TEST(TrackTest, RejectsNonIncreasingS) {
  ExpectError("0 0 0 0 -1\n100 0 100 1 0\n100 100 100 0 1\n0 100 300 -1 0\n",
              "bad.csv:3:", "does not increase");
}
TEST(TrackTest, RejectsTooFewRows) {
  auto t = ParseTrack("0 0 0 0 -1\n100 0 100 1 0\n100 100 200 0 1\n", "bad.csv");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("bad.csv"), std::string::npos) << t.message();
  EXPECT_NE(t.message().find("at least 4"), std::string::npos) << t.message();
}
TEST(TrackTest, RejectsNonUnitNormal) {
  ExpectError("0 0 0 0 -1\n100 0 100 1.01 0\n100 100 200 0 1\n0 100 300 -1 0\n",
              "bad.csv:2:", "normal");
  // Within the tolerance is fine.
  EXPECT_TRUE(
      ParseTrack("0 0 0 0 -1\n100 0 100 1.0009 0\n100 100 200 0 1\n0 100 300 -1 0\n", "ok").ok());
}
TEST(TrackTest, RejectsDuplicatePoint) {
  ExpectError("0 0 0 0 -1\n100 0 100 1 0\n100 100 200 0 1\n100 0 300 -1 0\n0 100 400 -1 0\n",
              "bad.csv:4:", "duplicate point (100, 0) of line 2");
}

// One coordinate off by orders of magnitude (a mangled row): refused at its line, not fitted
// (a fit through it ran for minutes).
TEST(TrackTest, RejectsAPointFarFromWhereItsSPutsIt) {
  ExpectError("0 0 0 0 -1\n100 0 100 1 0\n100 100000000 200 0 1\n0 100 300 -1 0\n",
              "bad.csv:3:", "lies 1e+08 m from the previous row's, but s advances 100 m");
  // A bend cuts its chord shorter than s: fine, and so is a chord a little longer than s.
  EXPECT_TRUE(ParseTrack("0 0 0 0 -1\n100 0 100 1 0\n100 100 220 0 1\n0 100 300 -1 0\n", "ok").ok());
  EXPECT_TRUE(ParseTrack("0 0 0 0 -1\n100 0 95 1 0\n100 100 200 0 1\n0 100 300 -1 0\n", "ok").ok());
}

TEST(TrackTest, LoadMissingFileNamesIt) {
  auto t = LoadTrack("/nonexistent/map.csv");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("/nonexistent/map.csv"), std::string::npos) << t.message();
}

TEST(TrackTest, FormatParsesBack) {
  auto t = ParseTrack(kGood, "square");
  ASSERT_TRUE(t.ok());
  auto back = ParseTrack(FormatTrack(*t), "again");
  ASSERT_TRUE(back.ok()) << back.message();
  ASSERT_EQ(back->waypoints.size(), t->waypoints.size());
  for (size_t i = 0; i < t->waypoints.size(); ++i) {
    EXPECT_EQ(back->waypoints[i].x, t->waypoints[i].x);
    EXPECT_EQ(back->waypoints[i].s, t->waypoints[i].s);
  }
}

TEST(TrackTest, UdacityMapFacts) {
  const std::string path = std::string(FRENETIC_SHARED_DIR "/data/highway_map.csv");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "Udacity map absent: " << path;
  auto t = LoadTrack(path);
  ASSERT_TRUE(t.ok()) << t.message();
  EXPECT_EQ(t->waypoints.size(), 181u);
  EXPECT_NEAR(t->max_s, 6945.554, 1e-3);
  EXPECT_NEAR(t->waypoints.back().s, 6914.149, 1e-3);
}

TEST(TrackTest, BundledTrackLoads) {
  auto t = LoadTrack(DefaultTrackPath());
  ASSERT_TRUE(t.ok()) << t.message();
  EXPECT_GT(t->waypoints.size(), 150u);
  EXPECT_NEAR(t->max_s, 7000, 100);
}

}  // namespace
}  // namespace frenetic::map

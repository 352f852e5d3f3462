#include "frenetic/map/track_generator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"

namespace frenetic::map {
namespace {

TEST(TrackGeneratorTest, DeterministicForASeedAndDifferentAcrossSeeds) {
  TrackGeneratorOptions o;
  o.seed = 7;
  auto a = GenerateTrack(o), b = GenerateTrack(o);
  ASSERT_TRUE(a.ok()) << a.message();
  ASSERT_TRUE(b.ok()) << b.message();
  EXPECT_EQ(FormatTrack(*a), FormatTrack(*b));
  o.seed = 8;
  auto c = GenerateTrack(o);
  ASSERT_TRUE(c.ok()) << c.message();
  EXPECT_NE(FormatTrack(*a), FormatTrack(*c));
}

TEST(TrackGeneratorTest, ClosedCounterClockwiseLoopWithSpacingAndNormals) {
  TrackGeneratorOptions o;
  auto t = GenerateTrack(o);
  ASSERT_TRUE(t.ok()) << t.message();
  const auto& w = t->waypoints;
  const size_t n = w.size();
  double area = 0;
  for (size_t i = 0; i < n; ++i) {
    const Waypoint& a = w[i];
    const Waypoint& b = w[(i + 1) % n];  // includes the closing segment
    const double gap = std::hypot(b.x - a.x, b.y - a.y);
    EXPECT_GE(gap, 30.0) << i;
    EXPECT_LE(gap, 40.0) << i;
    area += a.x * b.y - b.x * a.y;
    // The normal points to the right of the chord direction.
    EXPECT_LT((b.x - a.x) * a.dy - (b.y - a.y) * a.dx, 0) << i;
    EXPECT_NEAR(std::hypot(a.dx, a.dy), 1.0, 1e-12);
  }
  EXPECT_GT(area, 0);  // counter-clockwise
  EXPECT_NEAR(t->max_s, o.length, 0.01 * o.length);
  EXPECT_DOUBLE_EQ(w[0].s, 0);
}

TEST(TrackGeneratorTest, LoadsBackAndHonoursMinRadius) {
  for (uint64_t seed : {1u, 2u, 3u}) {
    TrackGeneratorOptions o;
    o.seed = seed;
    o.min_radius = 180;
    auto t = GenerateTrack(o);
    ASSERT_TRUE(t.ok()) << t.message();
    auto parsed = ParseTrack(FormatTrack(*t), "generated");
    ASSERT_TRUE(parsed.ok()) << parsed.message();
    EXPECT_NEAR(parsed->max_s, t->max_s, 1e-9);
    auto line = ReferenceLine::Fit(*parsed);
    ASSERT_TRUE(line.ok()) << line.message();
    double max_k = 0;
    for (const RefSample& r : (*line)->samples()) max_k = std::max(max_k, std::abs(r.kappa));
    // Tightest curve near the requested radius but not below it (1 % for the fit).
    EXPECT_GE(1.0 / max_k, 0.99 * o.min_radius) << "seed " << seed;
    EXPECT_LE(1.0 / max_k, 1.3 * o.min_radius) << "seed " << seed;
    // The sim's d sign point is inside the loop: waypoint normals point away from it.
    for (const Waypoint& w : parsed->waypoints) {
      EXPECT_GT((w.x - o.centre_x) * w.dx + (w.y - o.centre_y) * w.dy, 0);
    }
  }
}

TEST(TrackGeneratorTest, BundledTrackIsTheDefaultOutput) {
  auto bundled = LoadTrack(DefaultTrackPath());
  ASSERT_TRUE(bundled.ok()) << bundled.message();
  auto t = GenerateTrack(TrackGeneratorOptions());
  ASSERT_TRUE(t.ok()) << t.message();
  EXPECT_EQ(FormatTrack(*bundled), FormatTrack(*t))
      << "regenerate with: frenetic track generate -o config/tracks/frenetic_loop.csv";
}

TEST(TrackGeneratorTest, RejectsBadOptions) {
  TrackGeneratorOptions o;
  o.min_radius = 5000;
  auto t = GenerateTrack(o);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("min_radius"), std::string::npos) << t.message();
  o = TrackGeneratorOptions();
  o.spacing = 0;
  EXPECT_FALSE(GenerateTrack(o).ok());
  o = TrackGeneratorOptions();
  o.length = NAN;
  EXPECT_FALSE(GenerateTrack(o).ok());
}

}  // namespace
}  // namespace frenetic::map

#include "frenetic/map/chord_frenet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"

namespace frenetic::map {
namespace {

class ChordFrenetUdacity : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string path = std::string(FRENETIC_SHARED_DIR "/data/highway_map.csv");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "Udacity map absent: " << path;
    auto track = LoadTrack(path);
    ASSERT_TRUE(track.ok()) << track.message();
    track_ = *track;
  }
  Track track_;
};

struct Vector {
  double x, y, s, d;
};

// udacity-sim.md §10. Tolerance 1e-3 m, except the spawned car (1056.788, 1164.296): its logged
// position is rounded to 1 mm and the algorithm gives 275.7812 for it, like the spec's own
// independent implementation (275.781 vs logged 275.7777), so that vector is held to 4e-3 m.
TEST_F(ChordFrenetUdacity, ReproducesSpecValidationVectors) {
  const ChordFrenet frenet(track_);
  struct Case {
    Vector v;
    double tol;
  };
  const Case cases[] = {{{909.48, 1128.67, 124.8336, 6.1648}, 1e-3},
                        {{775.8, 1425.2, 6719.219, -280.149}, 1e-3},
                        {{1056.788, 1164.296, 275.778, 6.000}, 4e-3},
                        {{870.4026, 1132.156, 85.818, 2.667}, 1e-3},
                        {{1101.201, 1184.121, 324.833, 1.480}, 1e-3}};
  for (const Case& c : cases) {
    const FrenetPoint f = frenet.Convert(c.v.x, c.v.y);
    EXPECT_NEAR(f.s, c.v.s, c.tol) << "(" << c.v.x << ", " << c.v.y << ")";
    EXPECT_NEAR(f.d, c.v.d, c.tol) << "(" << c.v.x << ", " << c.v.y << ")";
  }
}

// The logged end_path of the first message: 0.1 m ahead of the ego, same owner.
TEST_F(ChordFrenetUdacity, LoggedEndPath) {
  const ChordFrenet frenet(track_);
  const FrenetPoint f = frenet.Convert(909.58, 1128.67, 909.48, 1128.67);
  EXPECT_NEAR(f.s, 124.9337, 1e-3);
  EXPECT_NEAR(f.d, 6.165697, 1e-3);
}

TEST_F(ChordFrenetUdacity, EndPathUsesOwnerNearestWaypoint) {
  const ChordFrenet frenet(track_);
  // The owner is the ego at the start; the end of its path is 150 m further on, in the middle
  // lane. The simulator picks the waypoint nearest to the OWNER and, since p is past it, the
  // chord from there to the next waypoint, extended far beyond its end.
  const double ox = 909.48, oy = 1128.67;
  const auto& w = track_.waypoints;
  size_t nearest = 0;
  for (size_t i = 1; i < w.size(); ++i) {
    if (std::hypot(w[i].x - ox, w[i].y - oy) < std::hypot(w[nearest].x - ox, w[nearest].y - oy)) {
      nearest = i;
    }
  }
  const Waypoint& ahead = w[nearest + 5];
  const double px = ahead.x + 6 * ahead.dx, py = ahead.y + 6 * ahead.dy;
  // Expected, in double: projection on the chord nearest -> nearest + 1.
  const Waypoint& a = w[nearest];
  const Waypoint& b = w[nearest + 1];
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  const double ux = (b.x - a.x) / len, uy = (b.y - a.y) / len;
  const double along = (px - a.x) * ux + (py - a.y) * uy;
  const double across = std::abs((px - a.x) * uy - (py - a.y) * ux);
  double chords = 0;
  for (size_t i = 0; i < nearest; ++i)
    chords += std::hypot(w[i + 1].x - w[i].x, w[i + 1].y - w[i].y);
  const FrenetPoint quirk = frenet.Convert(px, py, ox, oy);
  EXPECT_NEAR(quirk.s, chords + along, 2e-3);
  EXPECT_NEAR(std::abs(quirk.d), across, 2e-3);
  // Converted with its own position, the same point is 6 m right of the road.
  const FrenetPoint honest = frenet.Convert(px, py);
  EXPECT_NEAR(honest.d, 6.0, 0.05);
  EXPECT_GT(std::abs(quirk.d - honest.d), 0.5);
}

TEST_F(ChordFrenetUdacity, SignAndSeam) {
  const ChordFrenet frenet(track_);
  const Waypoint& w0 = track_.waypoints[0];
  // Right of the road (outward, away from (1000, 2000)) is positive.
  const FrenetPoint out = frenet.Convert(w0.x + 6 * w0.dx, w0.y + 6 * w0.dy);
  EXPECT_NEAR(out.d, 6.0, 0.05);
  const FrenetPoint in = frenet.Convert(w0.x - 3 * w0.dx, w0.y - 3 * w0.dy);
  EXPECT_NEAR(in.d, -3.0, 0.05);
  // Just before waypoint 0 the closing chord 180 -> 0 is used: s close to the loop length.
  const Waypoint& last = track_.waypoints.back();
  const double px = w0.x + 0.1 * (last.x - w0.x), py = w0.y + 0.1 * (last.y - w0.y);
  const FrenetPoint seam = frenet.Convert(px, py);
  EXPECT_NEAR(seam.s, 6945.554 - 0.1 * 31.405, 0.01);
  EXPECT_NEAR(seam.d, 0.0, 0.01);
}

// ReferenceLine::ChordOffset bounds what the simulator reads for points of the smooth line, and
// it is large where the spec says (§5.3: up to ~1.4 m mid-segment on the left bends, outward).
TEST_F(ChordFrenetUdacity, ReferenceLineChordOffsetBoundsTheSimulatorsReading) {
  auto line = ReferenceLine::Fit(track_);
  ASSERT_TRUE(line.ok()) << line.message();
  const ChordFrenet frenet(track_);
  double widest = 0, widest_s = 0;
  for (double s = 0.25; s < (*line)->length(); s += 3.1) {
    for (double d : {2.0, 6.0, 9.8}) {
      const CartesianPose p = (*line)->ToCartesian(s, d);
      const double reading = frenet.Convert(p.x, p.y).d - d;
      const ReferenceLine::OffsetRange r = (*line)->ChordOffset(s, s, d);
      ASSERT_LE(r.lo - 0.02, reading) << "s " << s << " d " << d;
      ASSERT_GE(r.hi + 0.02, reading) << "s " << s << " d " << d;
      if (r.hi > widest) {
        widest = r.hi;
        widest_s = s;
      }
    }
  }
  EXPECT_GT(widest, 1.1);  // a right-lane car at d = 9.8 reads > 10.9 there
  EXPECT_NEAR(widest_s, 5100, 120);  // segment 144 -> 145, s 5072-5135
  // A window covers its points.
  const auto window = (*line)->ChordOffset(4900, 5200, 9.8);
  EXPECT_GE(window.hi, widest - 1e-9);
}

TEST(ChordFrenetTest, SquareLoopByHand) {
  // A 100 m square around (1000, 2000), counter-clockwise, normals outward.
  Track t;
  t.waypoints = {{950, 1950, 0, 0, -1},
                 {1050, 1950, 100, 1, 0},
                 {1050, 2050, 200, 0, 1},
                 {950, 2050, 300, -1, 0}};
  t.max_s = 400;
  const ChordFrenet frenet(t);
  const FrenetPoint a = frenet.Convert(1000, 1945);  // 5 m outside the bottom side, halfway
  EXPECT_FLOAT_EQ(a.s, 50);
  EXPECT_FLOAT_EQ(a.d, 5);
  const FrenetPoint b = frenet.Convert(1055, 2010);  // right side, 60 m up, 5 m outside
  EXPECT_FLOAT_EQ(b.s, 160);
  EXPECT_FLOAT_EQ(b.d, 5);
  const FrenetPoint c = frenet.Convert(940, 1970);  // closing side, 10 m outside
  EXPECT_FLOAT_EQ(c.s, 380);
  EXPECT_FLOAT_EQ(c.d, 10);
  const FrenetPoint e = frenet.Convert(1000, 1960);  // 10 m inside
  EXPECT_FLOAT_EQ(e.d, -10);
}

}  // namespace
}  // namespace frenetic::map

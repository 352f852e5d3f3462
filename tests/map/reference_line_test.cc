#include "frenetic/map/reference_line.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <string>

#include "frenetic/map/track.h"

namespace frenetic::map {
namespace {

constexpr double kPi = std::numbers::pi;
const double kOffsets[] = {-2, 0, 2, 6, 10, 14};

std::string UdacityMapPath() { return std::string(FRENETIC_SHARED_DIR "/data/highway_map.csv"); }

// Fits once per map for the whole test binary: fitting is the expensive part.
std::shared_ptr<const ReferenceLine> FitOrDie(const std::string& path) {
  auto track = LoadTrack(path);
  EXPECT_TRUE(track.ok()) << track.message();
  if (!track.ok()) return nullptr;
  auto line = ReferenceLine::Fit(*track);
  EXPECT_TRUE(line.ok()) << line.message();
  return line.ok() ? *line : nullptr;
}

class ReferenceLineOnMap : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    path_ = GetParam() == "udacity" ? UdacityMapPath() : DefaultTrackPath();
    if (!std::filesystem::exists(path_)) GTEST_SKIP() << "map file absent: " << path_;
    static std::map<std::string, std::shared_ptr<const ReferenceLine>> cache;
    auto& slot = cache[path_];
    if (!slot) slot = FitOrDie(path_);
    line_ = slot;
    ASSERT_NE(line_, nullptr);
    auto track = LoadTrack(path_);
    ASSERT_TRUE(track.ok()) << track.message();
    track_ = *track;
  }
  std::string path_;
  Track track_;
  std::shared_ptr<const ReferenceLine> line_;
};

TEST_P(ReferenceLineOnMap, LengthCloseToMaxS) {
  EXPECT_NEAR(line_->length(), track_.max_s, 0.002 * track_.max_s);
  EXPECT_LE(line_->samples().size() * 0.5, line_->length() + 0.5);
  EXPECT_GE(line_->samples().size() * 0.5, line_->length() - 0.5);
}

TEST_P(ReferenceLineOnMap, RoundTripWithinOneCentimetre) {
  double max_ds = 0, max_dd = 0;
  const double len = line_->length();
  for (double d : kOffsets) {
    for (double s = 0; s < len; s += 0.5) {
      const CartesianPose p = line_->ToCartesian(s, d);
      const FrenetPoint f = line_->ToFrenet(p.x, p.y);
      max_ds = std::max(max_ds, std::abs(line_->DiffS(f.s, s)));
      max_dd = std::max(max_dd, std::abs(f.d - d));
    }
  }
  EXPECT_LE(max_ds, 0.01);
  EXPECT_LE(max_dd, 0.01);
  RecordProperty("max_ds", std::to_string(max_ds));
  RecordProperty("max_dd", std::to_string(max_dd));
}

TEST_P(ReferenceLineOnMap, RoundTripWithHintAcrossSeam) {
  const double len = line_->length();
  for (double d : kOffsets) {
    for (double s = len - 5; s < len + 5; s += 0.05) {
      const CartesianPose p = line_->ToCartesian(s, d);
      const FrenetPoint f = line_->ToFrenet(p.x, p.y, s - 3.0);
      ASSERT_LE(std::abs(line_->DiffS(f.s, s)), 0.01) << "s " << s << " d " << d;
      ASSERT_LE(std::abs(f.d - d), 0.01) << "s " << s << " d " << d;
      ASSERT_GE(f.s, 0.0);
      ASSERT_LT(f.s, len);
    }
  }
}

TEST_P(ReferenceLineOnMap, HintedProjectionReadsOnlyTheHintSample) {
  // Hints anywhere within one dense sample's stretch (and one loop on) give the same projection,
  // bit for bit: what a caller keeping projections by HintSample relies on.
  const double len = line_->length();
  const double step = len / line_->samples().size();
  EXPECT_EQ(line_->HintSample(NAN), -1);
  EXPECT_EQ(line_->HintSample(INFINITY), -1);
  for (double s = 1.0; s < len; s += 97.3) {
    const CartesianPose p = line_->ToCartesian(s + 4.0, 6.0);
    const double lo = std::floor(s / step) * step;  // the stretch of the sample s is in
    const int sample = line_->HintSample(s);
    ASSERT_GE(sample, 0);
    const FrenetPoint f = line_->ToFrenet(p.x, p.y, s);
    for (const double hint : {lo + 0.01 * step, lo + 0.5 * step, lo + 0.99 * step, s + len}) {
      if (line_->HintSample(hint) != sample) continue;  // rounding at a stretch's ends
      const FrenetPoint g = line_->ToFrenet(p.x, p.y, hint);
      ASSERT_EQ(f.s, g.s) << "s " << s << " hint " << hint;
      ASSERT_EQ(f.d, g.d) << "s " << s << " hint " << hint;
    }
  }
}

TEST_P(ReferenceLineOnMap, SmoothAllTheWayRoundIncludingSeam) {
  const auto& samples = line_->samples();
  const size_t n = samples.size();
  double max_dth = 0, max_dk = 0;
  for (size_t i = 0; i < n; ++i) {
    const RefSample& a = samples[i];
    const RefSample& b = samples[(i + 1) % n];
    max_dth = std::max(max_dth, std::abs(std::remainder(b.heading - a.heading, 2 * kPi)));
    max_dk = std::max(max_dk, std::abs(b.kappa - a.kappa));
  }
  EXPECT_LE(max_dth, 0.01);
  EXPECT_LE(max_dk, 1e-4);
  // Across the seam in particular, via the interpolating accessors.
  const double len = line_->length();
  const CartesianPose before = line_->ToCartesian(len - 0.25, 0);
  const CartesianPose after = line_->ToCartesian(0.25, 0);
  EXPECT_NEAR(std::hypot(after.x - before.x, after.y - before.y), 0.5, 1e-3);
  EXPECT_LE(std::abs(std::remainder(after.heading - before.heading, 2 * kPi)), 0.01);
  EXPECT_LE(std::abs(after.kappa - before.kappa), 1e-4);
}

TEST_P(ReferenceLineOnMap, PassesNearEveryWaypoint) {
  double worst = 0;
  for (const Waypoint& w : track_.waypoints) {
    const FrenetPoint f = line_->ToFrenet(w.x, w.y);
    worst = std::max(worst, std::abs(f.d));
  }
  EXPECT_LE(worst, 0.3);
  EXPECT_NEAR(line_->max_waypoint_distance(), worst, 1e-9);
  EXPECT_GE(line_->max_map_s_difference(), 0.0);
  EXPECT_LE(line_->max_map_s_difference(), 5.0);
}

TEST_P(ReferenceLineOnMap, CounterClockwiseLoopSigns) {
  // The loop turns +2 pi in total: left curves dominate, so the mean curvature is positive, and
  // d > 0 (right) is outward, i.e. the offset curve there is longer.
  double turn = 0, outer = 0, inner = 0;
  const double len = line_->length();
  CartesianPose po = line_->ToCartesian(0, 10), pi = line_->ToCartesian(0, -10);
  for (double s = 1; s <= len; s += 1) {
    turn += line_->At(s - 0.5).kappa;
    const CartesianPose qo = line_->ToCartesian(s, 10), qi = line_->ToCartesian(s, -10);
    outer += std::hypot(qo.x - po.x, qo.y - po.y);
    inner += std::hypot(qi.x - pi.x, qi.y - pi.y);
    po = qo;
    pi = qi;
  }
  EXPECT_NEAR(turn, 2 * kPi, 0.05);
  EXPECT_NEAR(outer - inner, 2 * 10 * 2 * kPi, 1.0);
}

TEST_P(ReferenceLineOnMap, OffsetCurvatureMatchesNumericalHeadingRate) {
  // kappa of the pose at (s, d) must equal d(heading)/d(arc length of the offset curve).
  const double len = line_->length();
  for (double d : kOffsets) {
    for (double s = 3.3; s < len; s += 97.0) {
      const double h = 0.25;
      const CartesianPose a = line_->ToCartesian(s - h, d), b = line_->ToCartesian(s + h, d);
      const double arc = std::hypot(b.x - a.x, b.y - a.y);
      const double numeric = std::remainder(b.heading - a.heading, 2 * kPi) / arc;
      const CartesianPose c = line_->ToCartesian(s, d);
      EXPECT_NEAR(c.kappa, numeric, 2e-5) << "s " << s << " d " << d;
    }
  }
}

TEST_P(ReferenceLineOnMap, FarFromRoadIsFiniteAndNearest) {
  const double len = line_->length();
  for (double s = 0; s < len; s += 250) {
    for (double d : {-280.0, -150.0, 120.0, 280.0, 5000.0}) {
      const CartesianPose p = line_->ToCartesian(s, d);
      for (bool hint : {false, true}) {
        const FrenetPoint f = hint ? line_->ToFrenet(p.x, p.y, s + 100) : line_->ToFrenet(p.x, p.y);
        ASSERT_TRUE(std::isfinite(f.s) && std::isfinite(f.d));
        ASSERT_GE(f.s, 0);
        ASSERT_LT(f.s, len);
        // The answer is a nearest point: no line sample is closer than |d| (up to sampling).
        const CartesianPose foot = line_->ToCartesian(f.s, 0);
        const double dist = std::hypot(p.x - foot.x, p.y - foot.y);
        EXPECT_NEAR(dist, std::abs(f.d), 1e-6);
        double best = 1e18;
        for (const RefSample& r : line_->samples())
          best = std::min(best, std::hypot(p.x - r.x, p.y - r.y));
        EXPECT_LE(dist, best + 1e-3);
      }
    }
  }
  const FrenetPoint nan_in = line_->ToFrenet(NAN, 3.0);
  EXPECT_TRUE(std::isfinite(nan_in.s) && std::isfinite(nan_in.d));
}

TEST_P(ReferenceLineOnMap, WrapAndDiffAcrossSeam) {
  const double len = line_->length();
  EXPECT_NEAR(line_->WrapS(len + 3), 3, 1e-9);
  EXPECT_NEAR(line_->WrapS(-3), len - 3, 1e-9);
  EXPECT_NEAR(line_->WrapS(-len * 5 - 1), len - 1, 1e-6);
  EXPECT_GE(line_->WrapS(-1e-17), 0.0);
  EXPECT_LT(line_->WrapS(-1e-17), len);
  EXPECT_NEAR(line_->DiffS(2, len - 3), 5, 1e-9);
  EXPECT_NEAR(line_->DiffS(len - 3, 2), -5, 1e-9);
  EXPECT_NEAR(line_->DiffS(100, 50), 50, 1e-9);
  // ToCartesian agrees across a wrap of s.
  const CartesianPose a = line_->ToCartesian(-1.0, 6), b = line_->ToCartesian(len - 1.0, 6);
  EXPECT_NEAR(a.x, b.x, 1e-6);
  EXPECT_NEAR(a.y, b.y, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Maps, ReferenceLineOnMap, ::testing::Values("udacity", "bundled"));

Track Circle(double radius, int n) {
  Track t;
  t.source = "circle";
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n;
    Waypoint w;
    w.x = radius * std::cos(a);
    w.y = radius * std::sin(a);
    w.dx = std::cos(a);  // counter-clockwise: right is outward
    w.dy = std::sin(a);
    w.s = i == 0 ? 0 : t.waypoints.back().s + 2 * radius * std::sin(kPi / n);
    t.waypoints.push_back(w);
  }
  t.max_s = n * 2 * radius * std::sin(kPi / n);
  return t;
}

TEST(ReferenceLineTest, CircleHasConstantCurvatureAndRadius) {
  auto line = ReferenceLine::Fit(Circle(300, 60));
  ASSERT_TRUE(line.ok()) << line.message();
  EXPECT_NEAR((*line)->length(), 2 * kPi * 300, 1.0);
  for (const RefSample& r : (*line)->samples()) {
    ASSERT_NEAR(r.kappa, 1.0 / 300, 2e-5);
    ASSERT_NEAR(std::hypot(r.x, r.y), 300, 0.3);
  }
  const CartesianPose p = (*line)->ToCartesian(100, 10);
  EXPECT_NEAR(p.kappa, 1.0 / 310, 2e-5);  // d > 0 is outward on a left-turning loop
}

TEST(ReferenceLineTest, RejectsBadOptions) {
  ReferenceLine::Options o;
  o.sample_step = 2.0;
  auto line = ReferenceLine::Fit(Circle(300, 60), o);
  ASSERT_FALSE(line.ok());
  EXPECT_NE(line.message().find("sample_step"), std::string::npos) << line.message();
  o = ReferenceLine::Options();
  o.smoothness_weight = -1;
  EXPECT_FALSE(o.Validate().ok());
  o = ReferenceLine::Options();
  o.control_spacing = 0;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_TRUE(ReferenceLine::Options().Validate().ok());
}

TEST(ReferenceLineTest, RejectsTooFewWaypoints) {
  Track t = Circle(300, 60);
  t.waypoints.resize(3);
  auto line = ReferenceLine::Fit(t);
  ASSERT_FALSE(line.ok());
  EXPECT_NE(line.message().find("circle"), std::string::npos) << line.message();
}

}  // namespace
}  // namespace frenetic::map

namespace frenetic::map {
namespace {

TEST(ReferenceLineTest, TinySquareFitsAndQueriesStayFinite) {
  Track t;
  t.source = "square";
  t.waypoints = {
      {0, 0, 0, 0, -1}, {100, 0, 100, 1, 0}, {100, 100, 200, 0, 1}, {0, 100, 300, -1, 0}};
  t.max_s = 400;
  auto line = ReferenceLine::Fit(t);
  ASSERT_TRUE(line.ok()) << line.message();
  EXPECT_GT((*line)->length(), 250);
  EXPECT_LT((*line)->length(), 450);
  for (double x : {50.0, -1e6, 1e6}) {
    for (double y : {50.0, -3.0, 1e6}) {
      const FrenetPoint f = (*line)->ToFrenet(x, y);
      const FrenetPoint g = (*line)->ToFrenet(x, y, 123.0);
      EXPECT_TRUE(std::isfinite(f.s) && std::isfinite(f.d) && std::isfinite(g.s) &&
                  std::isfinite(g.d));
    }
  }
  const CartesianPose p = (*line)->ToCartesian(1e9, 1e6);
  EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.kappa));
  const CartesianPose q = (*line)->ToCartesian(NAN, 2);
  EXPECT_TRUE(std::isfinite(q.x) && std::isfinite(q.y));
}

}  // namespace
}  // namespace frenetic::map

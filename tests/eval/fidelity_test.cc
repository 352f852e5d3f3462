// Tests of `frenetic fidelity`'s checks: on real recordings when the shared data is present
// (skipped otherwise), and that a wrong trimming rule, a wrong Frenet or a bad planner reply
// make the checks fail.
#include "frenetic/eval/fidelity.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "common/real_recordings.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/sim/ego.h"
#include "frenetic/sim/world.h"

namespace frenetic::sim {
namespace {

using testing::kMap;
using testing::kRecordings;
using testing::kShared;

const CheckRow* Row(const CheckReport& report, const std::string& prefix) {
  for (const CheckRow& r : report.rows) {
    if (r.check.rfind(prefix, 0) == 0) return &r;
  }
  return nullptr;
}

// The real recordings and the Udacity world, loaded once for all tests.
class RealData : public testing::RealRecordingsTest {
 protected:
  // The first `n` messages (and replies) of every recording.
  static std::vector<Recording> Head(std::size_t n) {
    std::vector<Recording> out = *recordings_;
    for (Recording& r : out) {
      r.messages.resize(std::min(n, r.messages.size()));
      r.replies.resize(r.messages.size());
    }
    return out;
  }
};

// --- Printing equality -----------------------------------------------------------------------

TEST(EqualAsPrinted, FloatThenSevenDigits) {
  EXPECT_TRUE(EqualAsPrinted(909.841861, 909.8419));    // float32 909.84186 prints 909.8419
  EXPECT_FALSE(EqualAsPrinted(909.841861, 909.8418));
  EXPECT_TRUE(EqualAsPrinted(0.225277423, 0.2252774));
  EXPECT_TRUE(EqualAsPrinted(914.53125, 914.5313));     // an exact tie: .NET rounds away
  EXPECT_TRUE(EqualAsPrinted(914.53125, 914.5312));     // and printf to even
  EXPECT_FALSE(EqualAsPrinted(914.53125, 914.5314));
  EXPECT_TRUE(EqualAsPrinted(0.0, 0.0));
  EXPECT_FALSE(EqualAsPrinted(0.0, 1e-3));
  EXPECT_FALSE(EqualAsPrinted(std::nan(""), 1.0));
  EXPECT_NEAR(DigitsOff(1000.5, 1000.501), 1.0, 1e-6);  // 1000.5 is exact in float32
}

// --- Parsing -----------------------------------------------------------------------------------

constexpr const char* kMessage =
    R"({"d":6.164833,"end_path_d":0,"end_path_s":0,"previous_path_x":[],"previous_path_y":[],)"
    R"("s":124.8336,"sensor_fusion":[[0,1056.788,1164.296,37.39919,15.43803,275.7777,5.999895]],)"
    R"("speed":0,"x":909.48,"y":1128.67,"yaw":0})";
constexpr const char* kReply = R"(42["control",{"next_x":[1,2],"next_y":[3,4]}])";

TEST(ParseRecording, ReadsMessagesAndReplies) {
  auto rec = ParseRecording("r", std::string(kMessage) + "\n" + kMessage + "\n",
                            std::string(kReply) + "\n\n" + kReply);
  ASSERT_TRUE(rec.ok()) << rec.message();
  ASSERT_EQ(rec->messages.size(), 2u);
  EXPECT_EQ(rec->replies.size(), 2u);
  EXPECT_DOUBLE_EQ(rec->messages[0].s, 124.8336);
  ASSERT_EQ(rec->messages[0].sensor_fusion.size(), 1u);
  EXPECT_DOUBLE_EQ(rec->messages[0].sensor_fusion[0][6], 5.999895);
}

TEST(ParseRecording, ErrorsNameTheProblem) {
  auto unequal = ParseRecording("r", std::string(kMessage) + "\n" + kMessage, kReply);
  ASSERT_FALSE(unequal.ok());
  EXPECT_THAT(unequal.message(), ::testing::HasSubstr("2 telemetry lines but 1 replies"));

  std::string no_speed = kMessage;
  no_speed.replace(no_speed.find("\"speed\":0"), 9, "\"speed\":\"x\"");
  auto bad_field = ParseRecording("r", std::string(kMessage) + "\n" + no_speed,
                                  std::string(kReply) + "\n" + kReply);
  ASSERT_FALSE(bad_field.ok());
  EXPECT_THAT(bad_field.message(), ::testing::HasSubstr("input line 2"));
  EXPECT_THAT(bad_field.message(), ::testing::HasSubstr("'speed'"));

  auto bad_json = ParseRecording("r", "{not json", kReply);
  ASSERT_FALSE(bad_json.ok());
  EXPECT_THAT(bad_json.message(), ::testing::HasSubstr("input line 1"));
}

TEST(LoadRecordings, MissingDirectoryIsAnError) {
  auto recs = LoadRecordings("/nonexistent/fidelity/dir");
  ASSERT_FALSE(recs.ok());
  EXPECT_THAT(recs.message(), ::testing::HasSubstr("/nonexistent/fidelity/dir"));
}

// --- Traffic statistics on synthetic samples --------------------------------------------------

TEST(TrafficStatsBuilder, CountsCrossingsRespawnsAndBraking) {
  // One car driving +x at 20 m/s, 0.1 s per message; it crosses d = 4 once, brakes at
  // -10 m/s^2 once, then teleports 100 m ahead. A second car stays parked off the road.
  std::vector<TrafficSample> run;
  double x = 0, v = 20;
  const double ds[] = {3.5, 3.8, 4.2, 4.5, 4.5, 4.5};
  for (int k = 0; k < 6; ++k) {
    TrafficSample m;
    m.ego_s = 100;
    m.dt = k == 0 ? 0 : 0.1;
    m.consumed = k == 0 ? 0 : 5;
    if (k == 3) v = 19;  // -10 m/s^2 over 0.1 s
    if (k > 0) x += v * 0.1;
    if (k == 5) x += 100;  // re-spawn
    m.cars.push_back({0, x, 0, v, 0, 150 + x, ds[k]});
    m.cars.push_back({1, 770, 1420, 0, 0, 6700, -280});
    run.push_back(m);
  }
  TrafficStatsBuilder b(6945.554);
  b.AddRun(run);
  const TrafficFigures& f = b.figures();
  EXPECT_EQ(f.messages, 6);
  EXPECT_EQ(f.car_samples, 6);  // the parked car is off the road
  EXPECT_EQ(f.lane_crossings, 1);
  ASSERT_EQ(f.dvdt.size(), 4u);  // 5 pairs, one across the re-spawn
  EXPECT_EQ(std::count_if(f.dvdt.begin(), f.dvdt.end(), [](double a) { return a < -7; }), 1);
  EXPECT_EQ(f.spawn_ahead.size(), 2u);  // first appearance and the re-spawn
  EXPECT_NEAR(f.spawn_ahead[0], 50, 1e-9);
  EXPECT_EQ(f.consumed.size(), 5u);
  EXPECT_NEAR(f.car_minutes, 0.5 / 60, 1e-12);
}

TEST(CompareTraffic, RatiosAndBands) {
  TrafficFigures real, sim;
  for (int i = 0; i < 100; ++i) {
    real.speeds.push_back(10 + 0.1 * i);
    sim.speeds.push_back(2 * (10 + 0.1 * i));  // twice as fast: fails every speed row
  }
  real.car_minutes = sim.car_minutes = 10;
  real.lane_crossings = 2;
  sim.lane_crossings = 3;  // ratio 1.5: inside the lane-change band 0.5-2
  const auto rows = CompareTraffic(real, sim);
  ASSERT_FALSE(rows.empty());
  EXPECT_NEAR(rows[1].ratio, 2.0, 1e-9);
  EXPECT_FALSE(rows[1].ok());
  const auto lane = std::find_if(rows.begin(), rows.end(), [](const StatRow& r) {
    return r.name.find("lane-line") != std::string::npos;
  });
  ASSERT_NE(lane, rows.end());
  EXPECT_NEAR(lane->ratio, 1.5, 1e-9);
  EXPECT_TRUE(lane->ok());
  // No samples at all is a failure, never a pass.
  const auto spawn = std::find_if(rows.begin(), rows.end(), [](const StatRow& r) {
    return r.name.find("spawn offset ahead") != std::string::npos;
  });
  ASSERT_NE(spawn, rows.end());
  EXPECT_FALSE(spawn->ok());
  EXPECT_FALSE(TrafficReport(rows).ok());
}

// --- Real recordings: Frenet ------------------------------------------------------------------

TEST_F(RealData, LoadsBothFullRecordings) {
  ASSERT_EQ(recordings_->size(), 2u);
  long total = 0;
  for (const Recording& r : *recordings_) {
    EXPECT_EQ(r.messages.size(), r.replies.size());
    total += static_cast<long>(r.messages.size());
  }
  EXPECT_EQ(total, 1823);
}

TEST_F(RealData, ChordFrenetReproducesEveryRecordedSD) {
  const CheckReport report = CheckFrenet(*recordings_, ChordFrenetFn(*world_));
  for (const CheckRow& r : report.rows) {
    EXPECT_TRUE(r.ok()) << r.check << ": " << r.passed << "/" << r.cases << " "
                        << (r.failures.empty() ? "" : r.failures.front());
    EXPECT_LE(r.worst, kFrenetTolerance) << r.check;
  }
  EXPECT_EQ(Row(report, "frenet: sensor_fusion")->cases, 1823 * 12);
}

TEST_F(RealData, SmoothFrenetInsteadOfChordsIsCaught) {
  const auto line = (*world_)->line;
  const FrenetFn smooth = [line](double px, double py, double, double) {
    return line->ToFrenet(px, py);
  };
  const CheckReport report = CheckFrenet(Head(50), smooth);
  EXPECT_FALSE(report.ok());
  EXPECT_FALSE(Row(report, "frenet: sensor_fusion")->ok());
  EXPECT_GT(Row(report, "frenet: sensor_fusion")->worst, 0.05);
}

TEST_F(RealData, FrenetOnAMapShiftedByFiveCentimetresIsCaught) {
  map::Track shifted = (*world_)->track;
  for (auto& wp : shifted.waypoints) wp.x += 0.05;
  auto chord = std::make_shared<map::ChordFrenet>(shifted);
  const FrenetFn wrong = [chord](double px, double py, double ox, double oy) {
    return chord->Convert(px, py, ox, oy);
  };
  const CheckReport report = CheckFrenet(Head(50), wrong);
  EXPECT_FALSE(Row(report, "frenet: ego")->ok());
  EXPECT_FALSE(Row(report, "frenet: sensor_fusion")->ok());
}

TEST_F(RealData, EndPathWithoutTheEgoOwnerQuirkIsCaughtWhereItMatters) {
  const auto world = *world_;
  const FrenetFn no_quirk = [world](double px, double py, double, double) {
    return world->chord->Convert(px, py);  // the point as its own owner
  };
  const CheckReport right = CheckFrenet(*recordings_, ChordFrenetFn(world));
  const CheckReport wrong = CheckFrenet(*recordings_, no_quirk);
  long quirk_cases = -1;
  for (const QuirkCount& q : right.quirks) {
    if (q.name.find("ego-owner") != std::string::npos) quirk_cases = q.count;
  }
  ASSERT_GE(quirk_cases, 0);
  const CheckRow* end = Row(wrong, "frenet: end_path");
  ASSERT_NE(end, nullptr);
  // Exactly the messages where the quirk moves end_path fail without it.
  EXPECT_EQ(end->cases - end->passed, quirk_cases);
}

// --- Real recordings: ego motion -------------------------------------------------------------

TEST_F(RealData, SimulatorEgoReproducesNextMessages) {
  const CheckReport report = CheckEgoMotion(*recordings_, SimulatorEgoModel());
  for (const CheckRow& r : report.rows) {
    EXPECT_TRUE(r.ok()) << r.check << ": " << r.passed << "/" << r.cases << " "
                        << (r.failures.empty() ? "" : r.failures.front());
  }
  EXPECT_EQ(Row(report, "ego: previous_path")->cases, 1821);
}

// An ego like sim::EgoCar with a deliberately altered trimming rule.
class WrongTrimEgo final : public EgoModel {
 public:
  enum class Rule { kKeepClosest, kAlwaysDropClosest, kNoTrim };
  WrongTrimEgo(float x, float y, double yaw, Rule rule) : x_(x), y_(y), yaw_(yaw), rule_(rule) {}
  void ApplyPath(std::span<const double> x, std::span<const double> y) override {
    std::vector<float> fx(x.begin(), x.end()), fy(y.begin(), y.end());
    int start = TrimStart(fx, fy, x_, y_);
    switch (rule_) {
      case Rule::kKeepClosest: start = start > 1 ? start - 1 : start; break;
      case Rule::kAlwaysDropClosest: start = std::max(start, fx.empty() ? 0 : 1); break;
      case Rule::kNoTrim: start = 0; break;
    }
    px_.assign(fx.begin() + start, fx.end());
    py_.assign(fy.begin() + start, fy.end());
  }
  void Tick() override {
    if (px_.size() >= 2) {
      const float nx = px_[0], ny = py_[0];
      speed_ = std::hypot((nx - x_) / 0.02f, (ny - y_) / 0.02f);
      yaw_ = std::atan2(static_cast<double>(py_[1] - y_), px_[1] - x_);
      x_ = nx;
      y_ = ny;
      px_.erase(px_.begin());
      py_.erase(py_.begin());
    } else {
      speed_ = 0;
      px_.clear();
      py_.clear();
    }
  }
  float x() const override { return x_; }
  float y() const override { return y_; }
  double yaw() const override { return yaw_; }
  float speed() const override { return speed_; }
  std::span<const float> path_x() const override { return px_; }
  std::span<const float> path_y() const override { return py_; }

 private:
  float x_, y_;
  double yaw_;
  float speed_ = 0;
  Rule rule_;
  std::vector<float> px_, py_;
};

class WrongTrimming : public RealData,
                      public ::testing::WithParamInterface<WrongTrimEgo::Rule> {};

TEST_P(WrongTrimming, IsCaught) {
  const auto rule = GetParam();
  const EgoModelFactory factory = [rule](float x, float y, double yaw) {
    return std::make_unique<WrongTrimEgo>(x, y, yaw, rule);
  };
  const CheckReport report = CheckEgoMotion(Head(40), factory);
  const CheckRow* path = Row(report, "ego: previous_path");
  ASSERT_NE(path, nullptr);
  EXPECT_FALSE(path->ok());
  EXPECT_FALSE(report.ok());
}

INSTANTIATE_TEST_SUITE_P(Rules, WrongTrimming,
                         ::testing::Values(WrongTrimEgo::Rule::kKeepClosest,
                                           WrongTrimEgo::Rule::kAlwaysDropClosest,
                                           WrongTrimEgo::Rule::kNoTrim));

// The simulator's own ego on the same messages passes: the failures above come from the
// rule alone.
TEST_F(RealData, StandInEgoWithTheRightRulePasses) {
  const EgoModelFactory factory = SimulatorEgoModel();
  EXPECT_TRUE(CheckEgoMotion(Head(40), factory).ok());
}

// --- Real recordings: protocol ----------------------------------------------------------------

TEST_F(RealData, SearchPlannerAnswersRealMessages) {
  auto config = plan::PlannerConfig::LoadDefault();
  ASSERT_TRUE(config.ok()) << config.message();
  auto planner = plan::MakePlanner("search", *config, (*world_)->line);
  ASSERT_TRUE(planner.ok()) << planner.message();
  const CheckReport report = CheckProtocol(Head(40), **planner);
  for (const CheckRow& r : report.rows) {
    EXPECT_TRUE(r.ok()) << r.check << ": " << (r.failures.empty() ? "" : r.failures.front());
    EXPECT_EQ(r.cases, 80);
  }
}

// A planner whose replies the simulator would choke on.
class BadPlanner final : public plan::Planner {
 public:
  explicit BadPlanner(int points, bool nan) : points_(points), nan_(nan) {}
  const plan::PlanResult& Plan(const plan::Telemetry& t) override {
    result_.x.assign(points_, t.x);
    result_.y.assign(points_, t.y);
    if (nan_ && points_ > 3) result_.x[3] = std::numeric_limits<double>::quiet_NaN();
    return result_;
  }
  void Reset() override {}
  std::string_view name() const override { return "bad"; }

 private:
  int points_;
  bool nan_;
  plan::PlanResult result_;
};

TEST_F(RealData, ShortOrNonFiniteRepliesFailTheProtocolCheck) {
  for (const auto& [points, nan] : {std::pair{10, false}, std::pair{60, true}}) {
    BadPlanner bad(points, nan);
    const CheckReport report = CheckProtocol(Head(5), bad);
    const CheckRow* answered = Row(report, "protocol: valid control reply");
    ASSERT_NE(answered, nullptr);
    EXPECT_EQ(answered->passed, 0) << points;
    EXPECT_TRUE(Row(report, "protocol: telemetry frame parsed")->ok());
  }
}

// --- Real recordings: traffic -------------------------------------------------------------------

TEST_F(RealData, RealTrafficFiguresAgreeWithStatsMd) {
  // STATS.md (computed independently, in Python) pools the two full recordings: 20771 on-road
  // speed samples, median 16.38 m/s, 4 lane-line crossings in 24.4 car-minutes.
  TrafficStatsBuilder b((*world_)->track.max_s);
  for (const Recording& r : *recordings_) b.AddRun(RecordingTrafficSamples(r));
  const TrafficFigures& f = b.figures();
  EXPECT_EQ(f.speeds.size(), 20771u);
  EXPECT_EQ(f.lane_crossings, 4);
  EXPECT_NEAR(f.car_minutes, 24.4, 0.05);
  EXPECT_EQ(f.consumed.size(), 1821u);
  const auto rows = CompareTraffic(f, f);
  EXPECT_NEAR(rows[1].real, 16.38, 0.01);  // median speed
  for (const StatRow& r : rows) EXPECT_TRUE(r.ok()) << r.name;  // itself: every ratio 1
}

TEST(EgoProfile, Interpolates) {
  EgoProfile p;
  p.name = "p";
  p.t = {0, 1, 2};
  p.speed = {0, 10, 20};
  p.d = {6, 6, 2};
  EXPECT_DOUBLE_EQ(p.SpeedAt(0.5), 5.0);
  EXPECT_DOUBLE_EQ(p.SpeedAt(-1), 0.0);
  EXPECT_DOUBLE_EQ(p.SpeedAt(9), 20.0);
  EXPECT_DOUBLE_EQ(p.DAt(1.5), 4.0);
}

}  // namespace
}  // namespace frenetic::sim

// The traffic runs of `frenetic fidelity` (drive/traffic_runs.h): deterministic whatever the
// threads, and a replayed ego that drives like the recorded one (real recordings when the shared
// data is present, skipped otherwise).
#include "frenetic/drive/traffic_runs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/real_recordings.h"
#include "frenetic/eval/fidelity.h"
#include "frenetic/sim/world.h"

namespace frenetic::sim {
namespace {

// The real recordings and the Udacity world, loaded once for all tests.
using TrafficRuns = testing::RealRecordingsTest;

TEST_F(TrafficRuns, SimulatedTrafficIsDeterministicAcrossThreads) {
  TrafficRunOptions options;
  options.planner = "baseline";
  options.minutes = 0.5;
  options.episode_seconds = 15;
  options.jobs = 1;
  auto one = SimulateTraffic(*world_, options, "");
  ASSERT_TRUE(one.ok()) << one.message();
  options.jobs = 2;
  auto two = SimulateTraffic(*world_, options, "");
  ASSERT_TRUE(two.ok()) << two.message();
  EXPECT_GT(one->car_samples, 0);
  EXPECT_EQ(one->messages, two->messages);
  EXPECT_EQ(one->speeds, two->speeds);
  EXPECT_EQ(one->rel_s, two->rel_s);
  EXPECT_EQ(one->consumed, two->consumed);
  // Latency mode: every message consumed l_old + l_new >= 1 points.
  EXPECT_GE(*std::min_element(one->consumed.begin(), one->consumed.end()), 1.0);
}

TEST_F(TrafficRuns, ReplayedEgoDrivesLikeTheRecordedEgoAndIsDeterministic) {
  TrafficRunOptions options;
  for (const Recording& r : *recordings_) options.ego_profiles.push_back(RecordingEgoProfile(r));
  ASSERT_EQ(options.ego_profiles.size(), 2u);
  // STATS.md: advanced run ~108 s, keep-lane run ~20.8 s of simulated time.
  EXPECT_NEAR(options.ego_profiles[0].duration(), 108.0, 0.5);
  EXPECT_NEAR(options.ego_profiles[1].duration(), 20.8, 0.5);
  options.minutes =
      (options.ego_profiles[0].duration() + options.ego_profiles[1].duration()) / 60.0;
  options.jobs = 1;
  EXPECT_EQ(TrafficEpisodes(options), 2);
  auto one = SimulateTraffic(*world_, options, "");
  ASSERT_TRUE(one.ok()) << one.message();
  options.jobs = 2;
  auto two = SimulateTraffic(*world_, options, "");
  ASSERT_TRUE(two.ok()) << two.message();
  EXPECT_EQ(one->speeds, two->speeds);
  EXPECT_EQ(one->ego_speeds, two->ego_speeds);
  // The scripted ego follows the recorded speed profile (a cap it may only undershoot behind a
  // slower car): its median and p95 speed are those of the recordings.
  TrafficStatsBuilder b((*world_)->track.max_s);
  for (const Recording& r : *recordings_) b.AddRun(RecordingTrafficSamples(r));
  const auto rows = CompareTraffic(b.figures(), *one);
  for (const StatRow& r : rows) {
    if (r.name.rfind("ego speed", 0) == 0) {
      EXPECT_NEAR(r.ratio, 1.0, 0.1) << r.name;
    }
  }
}

TEST(SimulateTraffic, RejectsBadProfiles) {
  EgoProfile p;
  p.name = "p";
  p.t = {0, 1, 2};
  p.speed = {0, 10, 20};
  p.d = {6, 6, 2};
  TrafficRunOptions options;
  options.ego_profiles = {p};
  options.ego_profiles[0].t = {0, 2, 1};  // not increasing
  auto world = LoadWorld(std::string(FRENETIC_SHARED_DIR "/data/highway_map.csv"));
  if (!world.ok()) GTEST_SKIP() << "Udacity map absent: " << world.message();
  auto r = SimulateTraffic(*world, options, "");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("ego profile 'p'"), std::string::npos) << r.message();
}

}  // namespace
}  // namespace frenetic::sim

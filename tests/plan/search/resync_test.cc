// A cycle that starts from the measured pose (the first message, or a previous path the planner
// did not send): the measured speed is the XY one, and the start is planned at the speed along
// the line that gives it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::plan {
namespace {

TEST(SearchResyncTest, AStartOnABendsOuterLaneKeepsTheMeasuredSpeed) {
  if (!std::filesystem::exists(map::DefaultTrackPath())) GTEST_SKIP() << "no bundled track";
  auto track = map::LoadTrack(map::DefaultTrackPath());
  ASSERT_TRUE(track.ok()) << track.message();
  auto line = map::ReferenceLine::Fit(*track);
  ASSERT_TRUE(line.ok()) << line.message();
  auto config = PlannerConfig::LoadDefault();
  ASSERT_TRUE(config.ok()) << config.message();
  config->PinDeadlines();
  // The sharpest left bend (the lanes lie right of the line, d > 0); its right lane is on the
  // outside, where the lane's XY speed is s' (1 + kappa d), above the speed along the line.
  double s = 0, kappa = 0;
  for (double x = 0; x < (*line)->length(); x += 5) {
    const double k = (*line)->At(x).kappa;
    if (k > kappa) {
      kappa = k;
      s = x;
    }
  }
  const double d = 10.0;  // the right lane's centre in the Udacity layout
  const double stretch = 1 + kappa * d;
  ASSERT_GT(stretch, 1.02) << "the bundled track's sharpest bend is too gentle for this test";
  const double cap = config->value("limits.max_speed_mph") * 0.44704;
  const double v = 0.985 * cap;  // the measured (XY) speed, just under the cap
  auto planner = MakePlanner("search", *config, *line);
  ASSERT_TRUE(planner.ok()) << planner.message();
  const map::CartesianPose p = (*line)->ToCartesian(s, d);
  Telemetry t;
  t.x = p.x;
  t.y = p.y;
  t.yaw = p.heading;
  t.speed = v;
  const map::FrenetPoint f = (*line)->ToFrenet(p.x, p.y);
  t.s = f.s;
  t.d = f.d;
  const PlanResult& r = (*planner)->Plan(t);
  // Planned from s' = v / (1 + kappa d): the path's first steps move at the measured speed, so
  // a candidate keeping its speed is within the limits (taken as s' = v, every one started
  // above the cap and none passed).
  EXPECT_EQ(r.status, PlanStatus::kOk) << ToString(r.status);
  ASSERT_GE(r.x.size(), 11u);
  for (int i = 0; i < 10; ++i) {
    const double step = std::hypot(r.x[i + 1] - r.x[i], r.y[i + 1] - r.y[i]) / kTickSeconds;
    EXPECT_LE(step, cap) << "tick " << i;
    EXPECT_NEAR(step, v, 0.02 * v) << "tick " << i;
  }
}

}  // namespace
}  // namespace frenetic::plan

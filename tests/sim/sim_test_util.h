// Shared helpers of the sim tests: the Udacity world (fitted once per binary) and a small
// keep-lane planner that re-sends its previous path and extends it at constant d.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/plan/planner.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/sim/world.h"

namespace frenetic::sim::testing {

inline std::string UdacityMapPath() {
  return std::string(FRENETIC_SHARED_DIR "/data/highway_map.csv");
}

// The Udacity world, or nullptr when the map is absent (callers GTEST_SKIP).
inline std::shared_ptr<const World> UdacityWorld() {
  static std::shared_ptr<const World> world = [] {
    std::shared_ptr<const World> w;
    if (!std::filesystem::exists(UdacityMapPath())) return w;
    auto loaded = LoadWorld(UdacityMapPath());
    EXPECT_TRUE(loaded.ok()) << loaded.message();
    if (loaded.ok()) w = *loaded;
    return w;
  }();
  return world;
}

#define FRENETIC_REQUIRE_UDACITY(world)                                              \
  auto world = ::frenetic::sim::testing::UdacityWorld();                             \
  if (!world) GTEST_SKIP() << "Udacity map absent: " << ::frenetic::sim::testing::UdacityMapPath()

// Sets a path along the lane at d = 6 m from where the ego is: `seconds` s at `v` m/s.
inline void DriveAlong(Simulator& sim, double v, double seconds) {
  const map::ReferenceLine& line = *sim.world().line;
  const plan::Telemetry t = sim.Telemetry();
  const double s0 = line.ToFrenet(t.x, t.y).s;
  std::vector<double> x, y;
  for (int i = 1; i <= static_cast<int>(seconds / kTick); ++i) {
    const map::CartesianPose p = line.ToCartesian(s0 + v * kTick * i, 6.0);
    x.push_back(p.x);
    y.push_back(p.y);
  }
  ASSERT_TRUE(sim.ApplyPath(x, y).ok());
}

// Keeps the lane it starts in (its measured d on the smooth line), accelerates at `accel` up to
// `speed`, always sends `points` points: the unvisited previous path plus new ones.
class KeepLanePlanner : public plan::Planner {
 public:
  KeepLanePlanner(std::shared_ptr<const map::ReferenceLine> line, double speed,
                  double accel = 3.0, int points = 50)
      : line_(std::move(line)), speed_(speed), accel_(accel), points_(points) {}

  const plan::PlanResult& Plan(const plan::Telemetry& t) override {
    result_.x.assign(t.previous_path_x.begin(), t.previous_path_x.end());
    result_.y.assign(t.previous_path_y.begin(), t.previous_path_y.end());
    if (result_.x.empty() || !started_) {
      result_.x.clear();
      result_.y.clear();
      const map::FrenetPoint f = line_->ToFrenet(t.x, t.y);
      s_ = f.s;
      if (!started_) d_ = f.d;
      v_ = t.speed;
      started_ = true;
    }
    while (static_cast<int>(result_.x.size()) < points_) {
      v_ = std::min(speed_, v_ + accel_ * plan::kTickSeconds);
      s_ += v_ * plan::kTickSeconds;
      const map::CartesianPose p = line_->ToCartesian(s_, d_);
      result_.x.push_back(p.x);
      result_.y.push_back(p.y);
    }
    return result_;
  }
  void Reset() override { started_ = false; }
  std::string_view name() const override { return "keep-lane-test"; }

 private:
  std::shared_ptr<const map::ReferenceLine> line_;
  double speed_, accel_;
  int points_;
  bool started_ = false;
  double s_ = 0, d_ = 0, v_ = 0;
  plan::PlanResult result_;
};

}  // namespace frenetic::sim::testing

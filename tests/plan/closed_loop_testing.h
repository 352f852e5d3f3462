// A small closed loop for the planner tests on the Udacity map: the simulator's path-trimming
// rule, 1-3 points consumed per cycle, traffic at constant velocity (planner_test.cc,
// planner_fuzz_test.cc).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/plan/feasibility.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "plan/search/stages_testing.h"

namespace frenetic::plan::closed_loop {

inline std::shared_ptr<const map::ReferenceLine> UdacityLine() {
  return search::testing::UdacityLine();
}

#define REQUIRE_MAP(line)                                                                    \
  auto line = ::frenetic::plan::closed_loop::UdacityLine();                                  \
  if (line == nullptr) {                                                                     \
    GTEST_SKIP() << "Udacity map not found at " FRENETIC_SHARED_DIR "/data/highway_map.csv"; \
  }

inline PlannerConfig Config() {
  auto c = PlannerConfig::LoadDefault();
  EXPECT_TRUE(c.ok()) << c.message();
  return c.ok() ? *c : PlannerConfig::Defaults();
}

struct Car {
  int id;
  double s, d, v;
};

// A minimal closed loop: the simulator's control handling (§4.2) and one point per tick.
class Loop {
 public:
  Loop(std::shared_ptr<const map::ReferenceLine> line, Planner* planner, double s0, double d0,
       double v0, std::uint32_t seed)
      : line_(std::move(line)), planner_(planner), rng_(seed) {
    const map::CartesianPose p = line_->ToCartesian(s0, d0);
    x_ = p.x;
    y_ = p.y;
    yaw_ = p.heading;
    speed_ = v0;
    driven_x_.push_back(x_);
    driven_y_.push_back(y_);
  }

  std::vector<Car> cars;
  std::vector<double> driven_x_, driven_y_;
  double min_same_lane_gap = 1e9;  // centre to centre along s, cars ahead in the ego's lane
  bool collided = false;
  int fallbacks = 0;
  PlanStatus last_status = PlanStatus::kOk;

  Telemetry Make() const {
    Telemetry t;
    t.x = x_;
    t.y = y_;
    t.yaw = yaw_;
    t.speed = speed_;
    const map::FrenetPoint f = line_->ToFrenet(x_, y_);
    t.s = f.s;
    t.d = f.d;
    for (size_t i = 0; i < path_x_.size(); ++i) {
      t.previous_path_x.push_back(static_cast<float>(path_x_[i]));
      t.previous_path_y.push_back(static_cast<float>(path_y_[i]));
    }
    for (const Car& c : cars) {
      const map::CartesianPose p = line_->ToCartesian(c.s, c.d);
      t.sensor_fusion.push_back({c.id, p.x, p.y, c.v * std::cos(p.heading),
                                 c.v * std::sin(p.heading), line_->WrapS(c.s), c.d});
    }
    return t;
  }

  // One exchange: plan, apply with the trimming rule, then advance 1-3 ticks.
  void Cycle() {
    const Telemetry t = Make();
    const PlanResult& r = planner_->Plan(t);
    last_status = r.status;
    if (r.status == PlanStatus::kFallbackUsed) ++fallbacks;
    ASSERT_GE(r.x.size(), static_cast<size_t>(kMinPathPoints));
    int k = 0;
    double best = 10000;
    for (size_t i = 0; i < r.x.size(); ++i) {
      const double dd = std::hypot(r.x[i] - x_, r.y[i] - y_);
      if (dd < best) {
        best = dd;
        k = static_cast<int>(i);
      }
    }
    const int drop = k > 0 ? k + 1 : (best == 0 ? 1 : 0);
    path_x_.assign(r.x.begin() + drop, r.x.end());
    path_y_.assign(r.y.begin() + drop, r.y.end());
    const int ticks = 1 + static_cast<int>(rng_() % 3);
    for (int i = 0; i < ticks; ++i) Tick();
  }

  void Tick() {
    for (Car& c : cars) c.s += c.v * kTickSeconds;
    if (path_x_.size() >= 2) {
      const double nx = path_x_[0], ny = path_y_[0];
      speed_ = std::hypot(nx - x_, ny - y_) / kTickSeconds;
      x_ = nx;
      y_ = ny;
      yaw_ = std::atan2(path_y_[1] - ny, path_x_[1] - nx);
    } else {
      speed_ = 0;
    }
    if (!path_x_.empty()) {
      path_x_.erase(path_x_.begin());
      path_y_.erase(path_y_.begin());
    }
    driven_x_.push_back(x_);
    driven_y_.push_back(y_);
    const map::FrenetPoint e = line_->ToFrenet(x_, y_, ego_s_hint_);
    ego_s_hint_ = e.s;
    ego_d_.push_back(e.d);
    for (const Car& c : cars) {
      const double ds = line_->DiffS(line_->WrapS(c.s), e.s);
      if (std::abs(c.d - e.d) < 2.0 && ds > 0) min_same_lane_gap = std::min(min_same_lane_gap, ds);
      if (std::abs(ds) < 4.5 && std::abs(c.d - e.d) < 2.2) collided = true;
    }
  }

  double speed() const { return speed_; }
  double s() const { return ego_s_hint_; }
  double d() const { return ego_d_.empty() ? 0 : ego_d_.back(); }
  const std::vector<double>& ego_d() const { return ego_d_; }

 private:
  std::shared_ptr<const map::ReferenceLine> line_;
  Planner* planner_;
  std::mt19937 rng_;
  double x_, y_, yaw_, speed_;
  double ego_s_hint_ = 0;
  std::vector<double> path_x_, path_y_, ego_d_;
};

// Closed-loop tests count ticks, not wall time: the wall-clock deadlines are switched off, so
// a loaded machine cannot cut a cycle and change the drive.
inline std::unique_ptr<Planner> Make(const std::string& name,
                                     std::shared_ptr<const map::ReferenceLine> line) {
  PlannerConfig config = Config();
  config.PinDeadlines();
  auto p = MakePlanner(name, config, std::move(line));
  EXPECT_TRUE(p.ok()) << p.message();
  return p.ok() ? std::move(p.value()) : nullptr;
}

// Runs the loop for `seconds` of simulated time (cycles are 1-3 ticks).
inline void RunFor(Loop& loop, double seconds) {
  const size_t target = loop.driven_x_.size() + static_cast<size_t>(seconds / kTickSeconds);
  while (loop.driven_x_.size() < target) {
    loop.Cycle();
    if (::testing::Test::HasFatalFailure()) return;
  }
}

inline XyMeasure WorstSlidingMeasure(const Loop& loop, int from) {
  XyChecker checker(static_cast<int>(loop.driven_x_.size()) + 8);
  return checker.Measure(loop.driven_x_.data(), loop.driven_y_.data(),
                         static_cast<int>(loop.driven_x_.size()), from);
}

}  // namespace frenetic::plan::closed_loop

// The search planner's stages wired as the planner wires them, on the Udacity map, with a
// fake clock (a cycle never runs out of time unless a test moves `now_ms`) and a
// constant-velocity predictor: for the per-stage tests (search/*_test.cc).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "frenetic/cost/cost_set.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "plan/predictor.h"
#include "plan/search/collisions.h"
#include "plan/search/context.h"
#include "plan/search/continuity.h"
#include "plan/search/lattice.h"
#include "plan/search/least_harm.h"
#include "plan/search/limits.h"
#include "plan/search/refiner.h"
#include "plan/search/scoring.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search::testing {

// m: the ego's s on the Udacity track in the stage tests.
inline constexpr double kS = 800;

inline std::shared_ptr<const map::ReferenceLine> UdacityLine() {
  static std::shared_ptr<const map::ReferenceLine> line = [] {
    std::shared_ptr<const map::ReferenceLine> l;
    auto track = map::LoadTrack(FRENETIC_SHARED_DIR "/data/highway_map.csv");
    if (!track.ok()) return l;
    auto fit = map::ReferenceLine::Fit(*track);
    if (fit.ok()) l = *fit;
    return l;
  }();
  return line;
}

#define REQUIRE_UDACITY_MAP()                                                                \
  if (::frenetic::plan::search::testing::UdacityLine() == nullptr) {                         \
    GTEST_SKIP() << "Udacity map not found at " FRENETIC_SHARED_DIR "/data/highway_map.csv"; \
  }

inline PlannerConfig DefaultConfig() {
  auto c = PlannerConfig::LoadDefault();
  EXPECT_TRUE(c.ok()) << c.message();
  return c.ok() ? *c : PlannerConfig::Defaults();
}

// A car of a test scene: s, d on the line (m) and speed along the lane (m/s).
struct SceneCar {
  double s, d, v;
};

struct Stages {
  explicit Stages(const PlannerConfig& c = DefaultConfig())
      : config(c),
        line(UdacityLine()),
        road(ConfiguredRoad(c, line)),
        costs(*cost::CostSet::Build(config.cost_terms())),
        cfg(config),
        predictor(MakeConstantVelocityPredictor(line, PredictorOptions{})),
        ws(cfg),
        clock([this] { return now_ms; }),
        lattice(cfg, *predictor, ws),
        scorer(cfg, *costs, ws, clock),
        limits(cfg, *line, ws),
        collisions(cfg, ws),
        least_harm(cfg, ws, scorer, limits, collisions, clock),
        refiner(cfg, config.refine_algorithm(), ws, lattice, scorer, limits, collisions, clock),
        continuity(cfg, *line, ws, clock) {}

  // The sensor_fusion row of a scene car.
  SensorCar Row(int id, const SceneCar& c) const {
    const map::CartesianPose p = line->ToCartesian(c.s, c.d);
    return {id, p.x, p.y, c.v * std::cos(p.heading), c.v * std::sin(p.heading), line->WrapS(c.s),
            c.d};
  }

  // A cycle's start without kept points: observes `cars`, builds the context and gives the
  // limit checks the start point as the XY prefix.
  void Prepare(const traj::FrenetState& start, const std::vector<SceneCar>& cars = {}) {
    ws.start = start;
    ws.kept = 0;
    ws.t_keep = 0;
    ws.straddle_at_start = 0;
    rows.clear();
    for (size_t i = 0; i < cars.size(); ++i) rows.push_back(Row(static_cast<int>(i), cars[i]));
    predictor->Observe(rows, start.s, NAN);
    clock.Start();
    BuildContext(cfg, *road, *predictor, ws);
    const map::CartesianPose p = line->ToCartesian(start.s, start.d);
    prefix_x = p.x;
    prefix_y = p.y;
    limits.SetXyPrefix(&prefix_x, &prefix_y, 1, nullptr, nullptr, 0);
  }

  // Writes ws.tk_* from an acceleration profile a(t) (m/s^2 along s) at constant d, from
  // (s0, v0), integrated tick by tick.
  template <typename Accel>
  void WriteTicks(double s0, double v0, double d, Accel accel) {
    double s = s0, v = v0;
    for (int i = 1; i <= ws.n_ticks; ++i) {
      const double a = accel(i * kTickSeconds);
      v += a * kTickSeconds;
      s += v * kTickSeconds;
      ws.tk_s[i] = s;
      ws.tk_sd[i] = v;
      ws.tk_sdd[i] = a;
      ws.tk_d[i] = d;
      ws.tk_dd[i] = 0;
      ws.tk_ddd[i] = 0;
    }
  }

  PlannerConfig config;
  std::shared_ptr<const map::ReferenceLine> line;
  std::shared_ptr<const map::Road> road;
  std::shared_ptr<const cost::CostSet> costs;
  Settings cfg;
  std::unique_ptr<Predictor> predictor;
  Workspace ws;
  double now_ms = 0;
  CycleClock clock;
  Lattice lattice;
  Scorer scorer;
  LimitChecker limits;
  CollisionChecker collisions;
  LeastHarm least_harm;
  Refiner refiner;
  Continuity continuity;
  std::vector<SensorCar> rows;
  double prefix_x = 0, prefix_y = 0;
};

}  // namespace frenetic::plan::search::testing

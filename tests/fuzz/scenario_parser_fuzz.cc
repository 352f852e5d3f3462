// libFuzzer target for the CommonRoad readers (scenario.h: "nothing in the input makes the reader
// crash"): ParseScenario and ParseSolution on arbitrary bytes, and what must hold for whatever
// they accept, as the runner and the verdict rely on it:
//   - a scenario's step is finite and positive; every lanelet bound has two points or more, and
//     every number read (points, states, shapes, goal intervals) is finite;
//   - an obstacle's trajectory runs at consecutive steps after its initial state's; an occupancy's
//     steps lie after the initial step; StateAt and OccupancyAt answer at its first, second and
//     last steps without failing, and a state they give is finite;
//   - a lanelet's bounds run side by side (ends at most 100 m apart, at most 100 km long), and
//     its centre line and polygon are built from them;
//   - a solution that parses writes back (WriteSolution) to text that parses to the same states.
// Build: scripts/fuzz.sh (clang, -DFRENETIC_BUILD_FUZZERS=ON).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/solution.h"

namespace {

namespace cr = frenetic::commonroad;

void Check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "property violated: %s\n", what);
    std::abort();
  }
}

bool Finite(cr::Vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }

void CheckState(const cr::State& s, const char* what) {
  Check(Finite(s.position), what);
  for (const std::optional<double>& v : {s.orientation, s.velocity, s.acceleration, s.yaw_rate,
                                         s.slip_angle, s.steering_angle}) {
    Check(!v || std::isfinite(*v), what);
  }
}

void CheckShapes(const cr::ShapeGroup& g, const char* what) {
  for (const cr::Shape& sh : g.shapes) {
    Check(Finite(sh.center), what);
    for (const cr::Vec2& v : sh.Vertices()) Check(Finite(v), what);
  }
}

void CheckObstacle(const cr::Obstacle& o) {
  CheckState(o.initial, "an obstacle's initial state is finite");
  CheckShapes(o.shape, "an obstacle's shape is finite");
  int step = o.initial.time_step;
  for (const cr::State& s : o.trajectory) {
    CheckState(s, "a trajectory state is finite");
    Check(s.time_step == ++step, "trajectory steps follow the initial one");
  }
  for (const auto& occ : o.occupancies) {
    Check(occ.time.start > o.initial.time_step && occ.time.start <= occ.time.end,
          "an occupancy lies after the initial step");
    CheckShapes(occ.shape, "an occupancy's shape is finite");
  }
  // What the runner and the verdict ask of every obstacle.
  const int last = o.LastStep();
  for (const int k : {o.initial.time_step, o.initial.time_step + 1,
                      o.role == cr::ObstacleRole::kStatic ? o.initial.time_step + 2 : last}) {
    const std::optional<cr::State> st = o.StateAt(k);
    if (st) CheckState(*st, "StateAt gives a finite state");
    (void)o.OccupancyAt(k);
  }
}

void CheckScenario(const cr::Scenario& sc) {
  Check(std::isfinite(sc.dt) && sc.dt > 0, "the step is finite and positive");
  Check(Finite(sc.origin), "the origin is finite");
  for (const auto& l : sc.lanelets) {
    Check(l.left.size() >= 2 && l.right.size() >= 2, "a bound has two points");
    for (const cr::Vec2& p : l.left) Check(Finite(p), "a left bound is finite");
    for (const cr::Vec2& p : l.right) Check(Finite(p), "a right bound is finite");
    // Side by side (a point far off its line is refused): the road's 2 m samples stay bounded.
    Check(cr::PolylineLength(l.left) <= 100e3 && cr::PolylineLength(l.right) <= 100e3,
          "a bound is at most 100 km long");
    Check(cr::Distance(l.left.front(), l.right.front()) <= 100 &&
              cr::Distance(l.left.back(), l.right.back()) <= 100,
          "a lanelet's bounds end side by side");
    (void)l.CenterLine();
    (void)l.Polygon();
  }
  for (const cr::Obstacle& o : sc.obstacles) CheckObstacle(o);
  for (const auto& p : sc.problems) {
    CheckState(p.initial, "a problem's initial state is finite");
    for (const auto& g : p.goals) {
      for (const cr::Shape& sh : g.shapes) Check(Finite(sh.center), "a goal shape is finite");
      if (g.velocity) {
        Check(std::isfinite(g.velocity->start) && std::isfinite(g.velocity->end),
              "a goal's velocity interval is finite");
      }
      if (g.orientation) {
        Check(std::isfinite(g.orientation->start) && std::isfinite(g.orientation->end),
              "a goal's orientation interval is finite");
      }
    }
  }
}

void CheckSolution(const cr::Solution& s) {
  const auto again = cr::ParseSolution(cr::WriteSolution(s), "rewritten");
  Check(again.ok(), "a solution written back parses");
  Check(again->trajectories.size() == s.trajectories.size(), "the same trajectories");
  for (std::size_t i = 0; i < s.trajectories.size(); ++i) {
    const auto& a = s.trajectories[i].states;
    const auto& b = again->trajectories[i].states;
    Check(a.size() == b.size(), "the same number of states");
    for (std::size_t k = 0; k < a.size(); ++k) {
      Check(a[k].time_step == b[k].time_step && a[k].x == b[k].x && a[k].y == b[k].y &&
                a[k].velocity == b[k].velocity && a[k].orientation == b[k].orientation &&
                a[k].steering_angle == b[k].steering_angle,
            "a state reads back exactly");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (auto sc = cr::ParseScenario(text, "fuzz"); sc.ok()) CheckScenario(*sc);
  if (auto sol = cr::ParseSolution(text, "fuzz"); sol.ok()) CheckSolution(*sol);
  return 0;
}

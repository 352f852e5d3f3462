// What the planner is told about a CommonRoad scenario's obstacles at one step of a closed-loop
// run (RunScenario), as a simulator's sensor fusion would report them: a row per obstacle present
// then (plan::SensorCar: centre, velocity, Frenet s/d, footprint) and, with --prediction
// recorded, each one's known future (plan::CarFuture). Positions in the scenario's frame (m),
// angles counter-clockwise from +x (rad), speeds m/s; s/d on the planner's reference line.
//
// A set-based obstacle (Obstacle::occupancies) after its initial step is reported by what it may
// occupy: its footprint is the bounding box of the step's occupancy (Obstacle::StateAt), which
// grows with the prediction's uncertainty, and its speed the motion of that box's centre since
// the previous step (known at the step); its recorded future, the boxes' centres ahead.
#pragma once

#include <optional>

#include "frenetic/commonroad/obstacle.h"
#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/plan/telemetry.h"

namespace frenetic::commonroad {

// Samples of a recorded future (the one at the present included: kFutureSteps + 1 at most):
// enough for the planner's horizons (6 s and a little at 0.1 s).
inline constexpr int kFutureSteps = 80;

// An obstacle's footprint at a step: centre, heading (rad), length and width (m). For a state of
// the obstacle: the bounding box of its shape in its own frame, placed at the state (the box
// centre, the state's orientation); a shape without extent gives the state's position and size 0.
struct Footprint {
  Vec2 centre;
  double heading = 0, length = 0, width = 0;
};
Footprint FootprintOf(const Obstacle& o, const State& st);
// The footprint at `step`: FootprintOf its state there; for a set-based obstacle after its
// initial step, the bounding box of its occupancy (the centre and heading of its StateAt).
// Absent when the obstacle is not there.
std::optional<Footprint> FootprintAt(const Obstacle& o, int step);

// An obstacle's speed at `step` (m/s): its state's velocity, else from its positions a step
// apart (the next one, else the previous one; a static obstacle 0); 0 when it is not there.
double SpeedAt(const Obstacle& o, int step, double dt);

// Fills out->sensor_fusion with a row for each obstacle present at `step`, in the scenario's
// order, and, in recorded mode, out->futures with each one's future from `step` on (centre,
// speed and heading every dt, up to kFutureSteps ahead, to the last step it exists); constant
// velocity: futures empty. Both are cleared first, their storage reused. A row's s/d is its
// centre projected on `line`, the search started at `ego_s` (the ego's s). Never fails.
void Observe(const Scenario& sc, int step, const map::ReferenceLine& line, double ego_s,
             PredictionMode mode, plan::Telemetry* out);

}  // namespace frenetic::commonroad

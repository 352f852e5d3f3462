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
// Steps ahead within which an obstacle not there yet is told as a car to come (recorded mode):
// the planner's check horizon and a little.
inline constexpr int kComingSteps = 60;

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

// The velocity a sensor measures of an obstacle at `step`, from what is known then: a speed (m/s)
// along a direction (rad).
//
// Some files state velocities their positions do not follow: in the highD set the positions
// advance ~2.0x their stated velocity per step (recorded every 0.2 s, labelled 0.1 s), so a
// predictor that trusts the stated speed carries every car on at half its pace. The speed is
// therefore the distance from the obstacle's position at step - 1 to the one at `step`, over dt,
// when that differs from the stated speed (SpeedAt) by more than max(kSpeedSlack, kSpeedShare x
// |stated|); else the stated speed. It is the stated speed, too, when the obstacle was not there
// at step - 1 (its first step) or moved less than kStillDistance since. The direction is the
// obstacle's orientation, unless it moved at kSpeedSlack or more in a direction more than
// kTurnSlack off it (sideways, backwards): then that direction, with the speed's magnitude.
//
// The thresholds leave consistent files as they were: in the 13 top-level shared files, zip/ and
// us101/ (14083 steps of positions), the speed from positions differs from the stated one by at
// most 0.81 of the slack (NGSIM US-101 cars by up to 24% of their stated speed) and the motion's
// direction from the orientation by at most 0.42 rad; in highD/ all but the 153 steps from the
// initial state (which move ~1x) switch. A set-based obstacle's StateAt speed is already its
// centre's motion. A static obstacle never moves: its stated speed (0 when none).
struct MeasuredVelocity {
  double speed = 0;    // m/s (negative: a stated reversing speed, along `heading`)
  double heading = 0;  // rad
};
inline constexpr double kSpeedSlack = 1.0;                // m/s
inline constexpr double kSpeedShare = 0.3;                // of the stated speed
inline constexpr double kStillDistance = 0.01;            // m per step
inline constexpr double kTurnSlack = 0.7853981633974483;  // rad (pi / 4)
MeasuredVelocity MeasureVelocity(const Obstacle& o, int step, double dt);

// Fills out->sensor_fusion with a row for each obstacle present at `step`, in the scenario's
// order (its footprint, FootprintAt, and the velocity a sensor measures, MeasureVelocity), and, in
// recorded mode, out->futures with each one's future from `step` on (footprint centre and
// MeasureVelocity's speed and direction every dt, up to kFutureSteps ahead, to the last step it
// exists), then one for each dynamic obstacle that comes within kComingSteps (a car entering
// the map later: CarFuture::start its first step's time from now, its footprint there, its
// samples from then on, to kFutureSteps after `step`); constant velocity: futures empty. Both are cleared first, their storage reused. A row's
// s/d is its centre projected on `line`, the search started at `ego_s` (the ego's s). Never fails.
void Observe(const Scenario& sc, int step, const map::ReferenceLine& line, double ego_s,
             PredictionMode mode, plan::Telemetry* out);

}  // namespace frenetic::commonroad

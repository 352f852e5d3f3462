// Incidents judged: could any trajectory within the simulator's limits have avoided an incident,
// starting from the ego's state at some moment of the 3 s before it, against the traffic as it
// actually moved (replayed tick by tick, not reacting)? An incident that no trajectory avoids is
// the traffic's.
//
// What "avoids" means is the simulator's own judgement, not a second implementation: every
// candidate is driven tick by tick through a copy of the drive's IncidentMonitor taken at the
// start (speed per tick, total acceleration on its 0.2 s blocks, jerk on its 1 s blocks, the
// lane-line timer, the road edges), the ego's position per tick in float32 with the EgoCar's
// speed and heading arithmetic, its d from the simulator's chord Frenet (map::ChordFrenet), and
// its box (BoxesOverlap) against the recorded boxes of the cars at that tick (the chord
// conversion is skipped only where the reference line's bounds of it decide the lane and edge
// flags with 0.3 m to spare; a test checks them over the whole track). A candidate fails
// at the first tick on which any flag of the monitor is up; it succeeds when it reaches the
// horizon (the incident's time plus a margin, 2 s: a trajectory that only postpones the incident
// does not count) with none.
//
// The search (a depth-first search over 0.2 s blocks with a transposition table):
// - Starts: every 0.2 s block boundary of the drive (the monitor's own blocks) from 3 s before
//   the incident to the last one before it, latest first. A start with a flag already up (an
//   earlier incident still on) is skipped. Once a start is avoidable, every earlier start whose
//   drive up to it had no flag up is avoidable too: drive as the ego did, then take that escape
//   (exact, no search needed). The latest start found avoidable is the "last chance".
// - From a start, the ego's state (s, d on the smooth reference line, their rates from a fit over
//   the last 0.2 s) and the monitor copy; each block of 10 ticks applies one action:
//   longitudinally a constant acceleration of its speed along the lane, one of
//   -9.6, -8, -6, -4, -2, 0, +2, +4 m/s^2, capped at 49.9 mph (less the lateral speed) and at
//   standstill; laterally either the current lateral move continued, or a new quintic move (from
//   the current d, its rate and acceleration) to every lane centre (2, 6, 10 m) or 1.2 m either
//   side of the nearest one, over 4 durations (a peak lateral acceleration of 9, 6, 3.5 or
//   1.5 m/s^2: 1.6, 2.0, 2.6 and 3.9 s for a whole lane), begun at any block. So the longitudinal
//   profiles are every piecewise-constant acceleration on the 0.2 s grid (up to 25 pieces over
//   5 s: brake hard now, brake later, brake then accelerate...), and the lateral ones every chain
//   of moves to any lane or in-lane offset, begun at any block, aborted or re-targeted at any
//   block, combined with any of them. The planner's lattice (3 lane timings, quartic/quintic
//   families, at most 8 m/s^2 of braking) is a small subset; the simulator's limits, not
//   comfort, bound what is tried.
// - Two passes: first the trajectories with at most one lateral move and three acceleration
//   pieces (most escapes are among them; found sooner, and they read well), then all of them.
//   Children are ordered by a look-ahead over the recorded traffic (how long the box stays clear
//   of every car if the block's action is continued, or if it brakes), so escapes come early.
// - Cells: a child whose end state falls in a cell already tried in the pass is skipped (s 1 m,
//   speed 0.5 m/s, d 0.4 m, lateral rate 0.8 m/s, the block's acceleration, the lane-line timer
//   in 25 ticks), so the second pass is exhaustive over that cell graph: "unavoidable" means no
//   trajectory of the family avoids it, up to the cells' resolution. A search that simulates
//   `budget_blocks` blocks without an answer gives up: the start is "undecided", never
//   "unavoidable".
// - Not covered: reversing, speeds that change inside a block (the simulator only sees block
//   means, so a sawtooth could in principle do better), leaving the carriageway, and the planner's
//   latency (the escape takes effect on the next tick).
// Judging is deterministic (no wall-clock budget) and has no effect on the drive.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "frenetic/sim/incident_monitor.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"
#include "frenetic/status.h"

namespace frenetic::sim {

struct JudgeOptions {
  double window_seconds = 3.0;  // starts from this long before the incident (0.2 s blocks)
  double margin_seconds = 2.0;  // a trajectory must stay incident-free this long after it
  int budget_blocks = 60000;    // simulated 0.2 s blocks per start before the search gives up
  Status Validate() const;      // a message naming the bad option
};

// One car as recorded on a tick: its box and its place on the smooth reference line.
struct RecordedCar {
  int id = 0;
  double x = 0, y = 0, heading = 0;  // m, rad (the box's centre and heading)
  double s = 0, d = 0;               // smooth-line Frenet, m
};

// The ego as recorded on a tick (after it): what the simulator measured.
struct RecordedEgo {
  float x = 0, y = 0;    // m, float32 as the simulator holds them
  double yaw = 0;        // rad
  float speed = 0;       // m/s
  double s = 0, d = 0;   // smooth-line Frenet, m
  bool flagged = false;  // some incident flag was up after this tick
};

// The drive around one incident, tick by tick: the judge's input. Tick k is the k-th physics
// tick of the drive (time k * 0.02 s after it).
struct IncidentCase {
  Incident incident;
  std::int64_t incident_tick = 0;  // the tick after which the incident's flag rose
  std::int64_t first_tick = 0;     // the tick of ego[0]
  std::vector<RecordedEgo> ego;    // one per tick from first_tick
  std::vector<int> car_begin{0};   // tick i's cars are cars[car_begin[i], car_begin[i + 1])
  std::vector<RecordedCar> cars;
  // The drive's monitor after block ticks (multiples of 10) of the case, log cleared.
  std::vector<std::int64_t> monitor_ticks;
  std::vector<IncidentMonitor> monitors;
  double car_length = 4.6, car_width = 2.4;  // m, every car's box (the scenario's)

  std::int64_t last_tick() const { return first_tick + static_cast<std::int64_t>(ego.size()) - 1; }
  void AddTick(const RecordedEgo& e, std::span<const RecordedCar> tick_cars);
  void AddMonitor(std::int64_t tick, const IncidentMonitor& monitor);
  std::span<const RecordedCar> CarsAt(std::int64_t tick) const;  // empty outside the case
};

enum class StartResult : std::uint8_t {
  kAvoidable,    // a trajectory from this start stays incident-free through the horizon
  kUnavoidable,  // the search tried its whole space: none does
  kUndecided,    // the search ran out of budget
  kInIncident,   // a flag was already up at this start: not judged
};
const char* ToString(StartResult result);

struct StartJudgement {
  double t = 0;  // s, the start (a block boundary)
  StartResult result = StartResult::kUndecided;
  bool as_driven_first = false;  // avoidable by driving as the ego did until a later start
  std::int64_t blocks = 0;       // blocks simulated by its search (0 when not searched)
};

enum class Verdict : std::uint8_t {
  kAvoidable,    // from some start
  kUnavoidable,  // from every start, each search exhaustive: the traffic's incident
  kUndecided,    // none found, but some search ran out of budget
  kNotJudged,    // no start to judge from (too early in the drive, or judging off)
};
const char* ToString(Verdict verdict);

struct IncidentJudgement {
  Verdict verdict = Verdict::kNotJudged;
  double incident_t = 0;      // s
  double avoidable_from = 0;  // s, the earliest start found avoidable (when avoidable)
  double last_chance = 0;     // s, the latest start found avoidable (when avoidable)
  double until = 0;  // s, the horizon: incident time + margin, or the drive's end if sooner
  // How the escape from the last chance drives, e.g. "accel -9.6 m/s^2 0.6 s, 0 1.4 s;
  // lateral to d 10.0 m at +0.2 s over 1.60 s".
  std::string escape;
  std::vector<StartJudgement> starts;  // in time order
  std::int64_t blocks = 0;             // 0.2 s blocks simulated, all starts
  double ms = 0;                       // wall time of the judging (0 when timing is off)
};

// Judges one incident. Never fails: a case without history is kNotJudged. `world` must be the
// world of the drive (its reference line and chord Frenet).
IncidentJudgement JudgeIncident(const World& world, const IncidentCase& c,
                                const JudgeOptions& options);

// One sentence: "avoidable from t = 140.40 s, last chance 142.80 s (0.60 s before)",
// "unavoidable (every start from 140.40 s)", "undecided (...)", "not judged".
std::string Describe(const IncidentJudgement& judgement);

}  // namespace frenetic::sim

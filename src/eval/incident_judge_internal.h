// Internals of the incident judge (incident_judge.h), shared with its tests: the simulator's
// measure of one ego tick, and the search from one start.
#pragma once

#include <cstdint>
#include <string>

#include "frenetic/eval/incident_judge.h"

namespace frenetic::sim::judge {

// The ego between ticks, as the EgoCar (position, heading) and the lane-line timer hold it.
struct EgoTick {
  float x = 0, y = 0;  // m, float32
  double yaw = 0;      // rad
  int band = 0;        // ticks on a lane line
};

bool AnyFlag(const IncidentMonitor& monitor);

// A d with the simulator's lane and road-edge flags (IncidentMonitor::Update) for the point at
// smooth-line (s, d), when the reference line's bounds of the chord reading
// (ReferenceLine::ChordOffset, widened by 0.3 m) clear every threshold; NaN when only
// ChordFrenet can tell.
double ChordDFromBounds(const map::ReferenceLine& line, double s, double d);

// One physics tick of the ego as the simulator measures it. EgoCar::Tick: to (x, y), the speed
// from the displacement over the tick (float32), the nose toward (next_x, next_y) from the
// pre-tick position; then Simulator::Tick: its box against the case's cars of `tick`, the chord
// d (ChordDFromBounds, else ChordFrenet; s, d are the point's smooth-line Frenet) and
// `monitor`. Updates `ego`; false when some flag of the monitor is up after the tick.
bool MeasureTick(const World& world, const IncidentCase& c, std::int64_t tick, float x, float y,
                 float next_x, float next_y, double s, double d, EgoTick* ego,
                 IncidentMonitor* monitor);

// The search from one start for a trajectory incident-free through tick `until`. `start` is a
// block tick of the case with a monitor and 0.2 s of recorded history before it; otherwise, or
// with a flag up at the start, the result is kInIncident with no block searched. *escape (when
// not null and the start is avoidable): how the escape drives.
StartJudgement SearchFrom(const World& world, const IncidentCase& c, std::int64_t start,
                          std::int64_t until, int budget_blocks, std::string* escape);

}  // namespace frenetic::sim::judge

// Perfect predictions for a diagnostic drive (`frenetic drive --perfect-predictions S`): the
// traffic's future as it will be, read from a copy of the simulator run ahead.
#pragma once

#include <vector>

#include "frenetic/plan/telemetry.h"
#include "frenetic/sim/simulator.h"

namespace frenetic::sim {

// The traffic's next `seconds` s, were the ego to drive the rest of its path and then on along
// the road at the path's last speed and offset: a copy of `sim` advanced that long, each car
// now on the road sampled every 0.1 s from now (sample 0), as plan::CarFuture (start 0), cut
// before a sample where it respawns or leaves the road. Cars with fewer than two samples are
// left out. `out` is cleared first. A planner handed these predicts every car exactly as long as
// the ego keeps to that path (the traffic reacts to the ego).
void Foresee(const Simulator& sim, double seconds, std::vector<plan::CarFuture>* out);

}  // namespace frenetic::sim

// The search planner's view of one cycle, built once before generation: this cycle's lane
// centres and speed limits, the previous winner at the scoring samples, and the relevant traffic
// sampled from the predictor at the scoring samples and at the collision-check steps — the
// cost::CostContext every term reads and the arrays the lattice and the checks read.
#pragma once

#include "frenetic/map/road.h"
#include "frenetic/plan/predictor.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// The lane whose centre (this cycle's, ws.lane_center) is nearest d among the lanes there;
// ties to the lower index.
int LaneOf(const Settings& cfg, const Workspace& ws, double d);

// Fills the lanes (ws.lane_center, lane_exists, road edges), ws.ctx, ws.prev_s / prev_d and the
// traffic arrays (ws.car_*, ws.step_*) from ws.start, ws.t_keep, the decision memory in ws, the
// road and the predictor's last observation. At most kMaxCars cars; a car right behind in the
// ego's lane is left to its own driver.
void BuildContext(const Settings& cfg, const map::Road& road, const Predictor& predictor,
                  Workspace& ws);

}  // namespace frenetic::plan::search

// The search planner's view of one cycle, built once before generation: this cycle's lane
// centres and speed limits, the previous winner at the scoring samples, and the relevant traffic
// sampled from the predictor at the scoring samples and at the collision-check steps — the
// cost::CostContext every term reads and the arrays the lattice and the checks read.
#pragma once

#include <span>
#include <vector>

#include "frenetic/map/road.h"
#include "frenetic/plan/planner.h"
#include "plan/predictor.h"
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

// The sensor rows plus, for every lane that ends ahead before the road does (a lane drop, an
// on-ramp's end) or at a wall (the map's closed end), a car at rest in its last metre: the
// lattice follows and stops for it, the costs and checks see the lane as blocked there, as a
// driver sees a lane drop. The car of lane l has the id kLaneEndId - l and is kLaneEndLength m
// long; ends up to kLaneEndRange m ahead are shown, and a lane's end within kLaneEndSlack m of
// the road's own end is the road's end, not a lane's.
inline constexpr int kLaneEndId = -1000;
inline constexpr double kLaneEndLength = 1.0;
inline constexpr double kLaneEndRange = 250.0;
inline constexpr double kLaneEndSlack = 1.0;
class LaneEnds {
 public:
  explicit LaneEnds(const map::Road& road);  // `road` must outlive this
  // `rows` plus the lane ends seen from start_s (m along the road): rows as they are on a road
  // whose lanes never end (map::Road::uniform). Valid until the next call.
  std::span<const SensorCar> With(const std::vector<SensorCar>& rows, double start_s);

 private:
  const map::Road& road_;
  // The road's end: the farthest lane end.
  double road_end_;
  std::vector<SensorCar> rows_;
};

}  // namespace frenetic::plan::search

// What the search planner sends when the search found nothing: last cycle's winner if it is
// still clear of traffic (after a search cut short by the deadline), else keep-lane braking.
#pragma once

#include "plan/search/collisions.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// Samples last cycle's winner (ws.prev_traj) from the current start on into ws.tk_*; false
// when there is none or it now collides. The XY limits were checked on it when it won. On
// success the next cycle's elapsed time on it counts from this start (ws.prev_base).
bool ContinuePrevious(Workspace& ws, const CollisionChecker& collisions);

// Keep-lane braking into ws.tk_*, at a jerk-limited constant deceleration integrated tick by
// tick back to the current lane's centre; it never exceeds the limits. The first of three
// braking levels that clears the traffic wins, else the hardest.
void BuildFallback(const Settings& cfg, Workspace& ws, const CollisionChecker& collisions);

}  // namespace frenetic::plan::search

#include "plan/search/fallback.h"

#include <algorithm>
#include <cmath>

#include "frenetic/plan/planner.h"
#include "plan/search/context.h"

namespace frenetic::plan::search {

bool ContinuePrevious(Workspace& ws, const CollisionChecker& collisions) {
  if (!ws.have_prev_traj) return false;
  ws.FillTicks(ws.prev_traj, ws.prev_elapsed);
  if (collisions.Collides()) return false;
  ws.prev_base = ws.prev_elapsed;  // the next cycle's elapsed time counts from this start
  return true;
}

void BuildFallback(const Settings& cfg, Workspace& ws, const CollisionChecker& collisions) {
  const traj::FrenetState& start = ws.start;
  const double levels[3] = {cfg.fallback.decel,
                            std::min(2 * cfg.fallback.decel, 0.75 * cfg.limits.max_accel),
                            0.9 * cfg.limits.max_accel};
  const int lane = LaneOf(cfg, ws, start.d);
  traj::Trajectory1d lat;
  lat.poly = traj::SolveQuintic(start.d, start.d_d, start.d_dd, ws.lane_center[lane], 0, 0,
                                cfg.fallback.lat_duration);
  lat.duration = cfg.fallback.lat_duration;
  for (int level = 0; level < 3; ++level) {
    const double decel = levels[level];
    const double jerk = std::min(cfg.fallback.jerk, 0.8 * cfg.limits.max_jerk);
    double s = start.s, v = std::max(start.s_d, 0.0), a = start.s_dd;
    for (int i = 1; i <= ws.n_ticks; ++i) {
      // Aim at -decel, but ease off near standstill so a reaches 0 when v does.
      const double target = v > 0 ? -std::min(decel, std::sqrt(2.0 * jerk * v)) : 0.0;
      const double da = std::clamp(target - a, -jerk * kTickSeconds, jerk * kTickSeconds);
      a += da;
      v += a * kTickSeconds;
      if (v <= 0) {
        v = 0;
        a = 0;
      }
      s += v * kTickSeconds;
      const traj::State1d d = lat.At(i * kTickSeconds);
      ws.tk_s[i] = s;
      ws.tk_sd[i] = v;
      ws.tk_sdd[i] = a;
      ws.tk_d[i] = d.p;
      ws.tk_dd[i] = d.v;
      ws.tk_ddd[i] = d.a;
    }
    if (!collisions.Collides()) break;
  }
}

}  // namespace frenetic::plan::search

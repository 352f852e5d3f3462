#include "plan/search/workspace.h"

#include <algorithm>
#include <cmath>

#include "frenetic/plan/planner.h"

namespace frenetic::plan::search {

Workspace::Workspace(const Settings& cfg) {
  side_clear = cfg.check.side_clear;
  // The uniform road's lanes (another road's are read each cycle, BuildContext).
  for (int l = 0; l < cfg.road.num_lanes; ++l) {
    lane_nominal[l] = lane_center[l] = (l + 0.5) * cfg.road.lane_width;
    lane_exists[l] = true;
  }
  road_right = cfg.road.num_lanes * cfg.road.lane_width;
  if (cfg.road.num_lanes > 1) {
    lane_nominal[cfg.road.num_lanes - 1] -= cfg.road.outer_inset;
    lane_center[cfg.road.num_lanes - 1] -= cfg.road.outer_inset;
  }

  n_samples = static_cast<int>(std::floor(cfg.score.horizon / cfg.score.dt + 1e-9)) + 1;
  n_ticks = static_cast<int>(std::ceil(cfg.check.horizon / kTickSeconds));
  n_ticks = std::max(n_ticks, cfg.continuity.output_points);
  // The lattice's largest bundles (Lattice::Generate), with a little slack.
  const int max_lon =
      (cfg.grid.speeds + cfg.road.num_lanes) * cfg.grid.durations + cfg.grid.durations +
      2 * cfg.road.num_lanes * cfg.grid.follow_gaps * cfg.grid.durations +
      cfg.road.num_lanes * cfg.grid.gap_targets * cfg.grid.durations +
      cfg.brake.decels * cfg.brake.targets + cost::kMaxGoalRegions * cfg.grid.durations +
      cfg.grid.accels * (cfg.road.num_lanes + 1) + 9;
  const int escape_moves = cfg.lat.escape_duration > 0 ? 1 : 0;
  const int max_lat = cfg.road.num_lanes * (cfg.lat.durations + 1 + escape_moves + cfg.lat.delays) *
                          std::max(cfg.lat.offsets, cfg.lat.escape_offsets) +
                      kMaxSwerves + kMaxPasses + 9;
  lon.reserve(max_lon);
  lat.reserve(max_lat);
  for (auto* v : {&lon_s, &lon_sd, &lon_sdd}) v->assign(max_lon * n_samples, 0.0);
  for (auto* v : {&lat_d, &lat_dd, &lat_ddd}) v->assign(max_lat * n_samples, 0.0);
  cand_lon.reserve(max_lon * max_lat);
  cand_lat.reserve(max_lon * max_lat);
  cand_cost.reserve(max_lon * max_lat);
  order.reserve(max_lon * max_lat);
  for (auto* v : {&car_s, &car_d, &car_v}) v->assign(kMaxCars * n_samples, 0.0);
  car_index.assign(kMaxCars, 0);
  for (auto* v : {&car_hl, &car_hw, &car_sep_s, &car_sep_d, &car_reach_s, &car_reach_d}) {
    v->assign(kMaxCars, 0.0);
  }
  const int edge_bins = static_cast<int>(std::ceil(
                            (cfg.limits.max_speed * std::max(cfg.check.horizon, cfg.score.horizon) +
                             kEdgeBehind + kEdgeAhead) /
                            kEdgeBin)) +
                        2;
  edge_lo.assign(edge_bins, 0.0);
  edge_hi.assign(edge_bins, 0.0);
  abs_kappa.assign(edge_bins, 0.0);
  kappa_lo.assign(edge_bins, 0.0);
  kappa_hi.assign(edge_bins, 0.0);
  car_s0.assign(kMaxCars, 0.0);
  car_d0.assign(kMaxCars, 0.0);
  collision_step = TicksIn(cfg.check.collision_dt);
  n_steps = n_ticks / collision_step;
  for (auto* v : {&step_s, &step_d, &step_v, &step_vd, &step_dir_s, &step_dir_d})
    v->assign(kMaxCars * (n_steps + 1), 0.0);
  lat_near.assign(2 * max_lat * n_samples, 0);
  lon_near.assign(2 * max_lon * n_samples, 0);
  lon_near_have.assign(max_lon, 0);
  prev_s.assign(n_samples, 0.0);
  prev_d.assign(n_samples, 0.0);
  for (auto* v : {&tk_s, &tk_sd, &tk_sdd, &tk_d, &tk_dd, &tk_ddd}) v->assign(n_ticks + 1, 0.0);
}

int Workspace::CheckTicks(int c) const {
  const int j = cand_lat[c];
  if (!lat[j].swerve() || lat[j].goal >= num_goals) return n_ticks;
  const int ticks = static_cast<int>(std::floor(lat[j].traj.end_time() / kTickSeconds + 1e-6));
  return ticks < 1 || ticks >= n_ticks ? n_ticks : ticks;
}

bool Workspace::SwerveEndsInside(int i, int j) const {
  const LatTraj& l = lat[j];
  if (!l.swerve() || l.goal >= num_goals) return false;
  const double T = l.traj.end_time();
  const cost::GoalRegion& r = goals[l.goal];
  const traj::State1d lo = lon[i].traj.At(T);
  const traj::State1d la = l.traj.At(T);
  const double across = la.p - r.d_slope * (lo.p - r.s_ref);
  const double h = la.v / std::max(lo.v, 0.1);
  return T >= r.t_lo && T <= r.t_hi && lo.p >= r.s_lo && lo.p <= r.s_hi && across >= r.d_lo &&
         across <= r.d_hi && lo.v >= r.v_lo && lo.v <= r.v_hi && h >= r.h_lo && h <= r.h_hi;
}

void Workspace::FillTicks(const traj::FrenetTrajectory& tr, double t0) {
  for (int i = 1; i <= n_ticks; ++i) {
    const traj::FrenetState st = tr.At(t0 + i * kTickSeconds);
    tk_s[i] = st.s;
    tk_sd[i] = st.s_d;
    tk_sdd[i] = st.s_dd;
    tk_d[i] = st.d;
    tk_dd[i] = st.d_d;
    tk_ddd[i] = st.d_dd;
  }
}

void Workspace::FillTicksForLimits(const traj::FrenetTrajectory& tr) {
  const auto time = [](int t) { return 0.0 + t * kTickSeconds; };  // FillTicks' time
  tr.lon.Sample(1, n_ticks + 1, time, tk_s.data(), tk_sd.data(), nullptr);
  tr.lat.Sample(1, n_ticks + 1, time, tk_d.data(), tk_dd.data(), nullptr);
}

}  // namespace frenetic::plan::search

#include "plan/search/context.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "frenetic/plan/planner.h"

namespace frenetic::plan::search {
namespace {

// s of driving, then at most kMaxLaneLookahead m: where a road's lane centres are read.
constexpr double kLaneLookahead = 2.0;
constexpr double kMaxLaneLookahead = 60.0;
// m: FirstCollision's broad reaches for cars no larger than the Udacity footprint (4.8 x 2.4 m,
// whose half diagonal this is).
constexpr double kReachS = 8.0, kReachD = 5.0;
constexpr double kUdacityHalfDiagonal = 2.6832815729997477;

// The lanes' centres for this cycle: the nominal ones, moved just enough that the simulator,
// which measures d from the chords between waypoints (up to ~1.3 m outward mid-segment on
// left bends, udacity-sim.md §5.3 and §9.3), reads the ego inside its lane over the next
// stretch: clear of the lane lines' +-0.8 m bands (the 3 s timer) and of the road edges.
void LaneCentres(const Settings& cfg, const map::ReferenceLine& line, Workspace& ws) {
  const double ahead = std::max(ws.start.s_d, 10.0) * cfg.score.horizon + 20.0;
  const int last = cfg.road.num_lanes - 1;
  for (int l = 0; l <= last; ++l) {
    const map::ReferenceLine::OffsetRange r =
        line.ChordOffset(ws.start.s - 10.0, ws.start.s + ahead, ws.lane_nominal[l]);
    const double lo_read = l == 0 ? cfg.limits.d_min : l * cfg.road.lane_width + kLaneLineBand;
    const double hi_read =
        l == last ? cfg.limits.d_max : (l + 1) * cfg.road.lane_width - kLaneLineBand;
    const double lo = lo_read - r.lo, hi = hi_read - r.hi;
    ws.lane_center[l] = lo <= hi ? std::clamp(ws.lane_nominal[l], lo, hi) : 0.5 * (lo + hi);
  }
}

// The lanes of a road that is not uniform, this cycle: each lane there at the start's s, its
// centre where a lateral move would end (lookahead), and the road's edges over the stretch the
// horizons can reach (the off-road check's table). A lane that is not there keeps a centre
// beside its neighbour, so that the centres stay in order. Also ctx.oncoming_right: the right
// border at the start of an oncoming lane there (BuildContext resets it).
void RoadLanes(const Settings& cfg, const map::Road& road, Workspace& ws) {
  const double s0 = ws.start.s;
  const double look = s0 + std::clamp(ws.start.s_d * kLaneLookahead, 0.0, kMaxLaneLookahead);
  for (int l = 0; l < cfg.road.num_lanes; ++l) {
    const map::Road::Span now = road.LaneAt(l, s0), ahead = road.LaneAt(l, look);
    ws.lane_exists[l] = now.exists;
    ws.lane_oncoming[l] = road.Oncoming(l);
    if (ws.lane_oncoming[l] && now.exists) {
      ws.ctx.oncoming_right = std::max(ws.ctx.oncoming_right, now.right);
    }
    if (now.exists) {
      ws.lane_nominal[l] = ahead.exists ? ahead.centre() : now.centre();
    } else {
      ws.lane_nominal[l] = l == 0 ? 0.0 : ws.lane_nominal[l - 1] + cfg.road.lane_width;
    }
    ws.lane_center[l] = ws.lane_nominal[l];
  }
  const map::Road::Span edges = road.EdgesAt(s0);
  ws.road_left = edges.exists ? edges.left : 0.0;
  ws.road_right = edges.exists ? edges.right : cfg.road.num_lanes * cfg.road.lane_width;
  // The edge table: the tightest edges over each bin, from its two ends (borders are linear
  // between stations; a lane that ends shows at the bin holding its end).
  ws.edge_s0 = s0 - Workspace::kEdgeBehind;
  const int bins = static_cast<int>(ws.edge_lo.size());
  map::Road::Span prev = road.EdgesAt(ws.edge_s0);
  ws.edge_widest = 0;
  for (int b = 0; b < bins; ++b) {
    const map::Road::Span next = road.EdgesAt(ws.edge_s0 + (b + 1) * Workspace::kEdgeBin);
    const bool both = prev.exists && next.exists;
    ws.edge_lo[b] = both ? std::max(prev.left, next.left) : NAN;
    ws.edge_hi[b] = both ? std::min(prev.right, next.right) : NAN;
    if (Finite(ws.edge_lo[b])) ws.edge_widest = std::max(ws.edge_widest, std::abs(ws.edge_lo[b]));
    if (Finite(ws.edge_hi[b])) ws.edge_widest = std::max(ws.edge_widest, std::abs(ws.edge_hi[b]));
    prev = next;
  }
}

}  // namespace

int LaneOf(const Settings& cfg, const Workspace& ws, double d) {
  int best = -1;
  for (int l = 0; l < cfg.road.num_lanes; ++l) {
    if (!ws.lane_exists[l]) continue;
    if (best < 0 || std::abs(d - ws.lane_center[l]) < std::abs(d - ws.lane_center[best])) best = l;
  }
  return std::max(best, 0);
}

void BuildContext(const Settings& cfg, const map::Road& road, const Predictor& predictor,
                  Workspace& ws) {
  const map::ReferenceLine& line = road.line();
  const traj::FrenetState& start = ws.start;
  const int n_samples = ws.n_samples, n_steps = ws.n_steps;
  cost::CostContext& c = ws.ctx;
  c.num_samples = n_samples;
  c.dt = cfg.score.dt;
  c.lane_width = cfg.road.lane_width;
  c.num_lanes = cfg.road.num_lanes;
  c.car_length = cfg.check.car_length;
  c.car_width = cfg.check.car_width;
  c.start_s = start.s;
  c.start_d = start.d;
  c.start_speed = start.s_d;
  c.oncoming_right = -std::numeric_limits<double>::infinity();
  if (cfg.road.uniform) {
    LaneCentres(cfg, line, ws);
  } else {
    RoadLanes(cfg, road, ws);  // and c.oncoming_right
  }
  c.current_lane = LaneOf(cfg, ws, start.d);
  c.previous_target_lane = ws.prev_target_lane;
  c.time_since_lane_change = ws.time_since_change;
  c.lane_before_change = ws.lane_before_change;
  // Lane speed limits: the XY speed of an offset curve is s' (1 + kappa d) with d to the right
  // and kappa positive to the left, so the outer lane of a left bend is faster in XY.
  const double reach = cfg.limits.max_speed * cfg.score.horizon + 20;
  double kmax = 0, kmin = 0;
  for (double ds = -10; ds <= reach; ds += 2.0) {
    const double k = line.At(start.s + ds).kappa;
    if (Finite(k)) {
      kmax = std::max(kmax, k);
      kmin = std::min(kmin, k);
    }
  }
  {
    // The speed prefilter's share: on a path at offset d the XY speed is at least
    // s' (1 - kappa d) (its part along the line), so at least s' (1 - K |d|max) with K the
    // largest |kappa| read above (a quarter more and 1e-3 1/m for the curvature between the
    // 2 m reads) and |d|max the farthest across that a candidate passing the limit checks may
    // be: past what its off-road check accepts (on a uniform road limits.d_min / d_max, on
    // another the edge table's widest edges anywhere ahead: a lane that widens, an oncoming lane
    // passed on) by the chords' reading of d (within 1.5 m), or the start's d, or the road's
    // outer lane borders at the start. None on a road that bends so tightly that the share
    // would be under a half.
    const double k = 1.25 * std::max(kmax, -kmin) + 1e-3;
    double d = std::max({std::abs(ws.road_left), std::abs(ws.road_right),
                         Finite(start.d) ? std::abs(start.d) : 1e9});
    d = cfg.road.uniform ? std::max({d, std::abs(cfg.limits.d_min), std::abs(cfg.limits.d_max)})
                         : std::max(d, ws.edge_widest);
    d += 1.5;
    ws.max_abs_d = d;  // the curve prefilter's reach across too
    const double share = 1.0 - k * d;
    ws.speed_share = Finite(share) && share >= 0.5 ? share : 0.0;
    ws.speed_reach = reach;
  }
  if (cfg.check.curve_prefilter) {
    // Each bin's largest |kappa|, from its two ends and its middle (the line's curvature
    // changes over tens of metres).
    ws.kappa_s0 = start.s - Workspace::kEdgeBehind;
    const double h = 0.5 * Workspace::kEdgeBin;
    double prev = line.At(ws.kappa_s0).kappa;
    ws.kappa_abs_max = 0;
    for (int b = 0; b < static_cast<int>(ws.abs_kappa.size()); ++b) {
      const double x = ws.kappa_s0 + b * Workspace::kEdgeBin;
      const double mid = line.At(x + h).kappa, next = line.At(x + 2 * h).kappa;
      const bool finite = Finite(mid) && Finite(next) && Finite(prev);
      ws.abs_kappa[b] = finite ? std::max({std::abs(prev), std::abs(mid), std::abs(next)}) : 0.0;
      // Unknown: a range across 0, which rules nothing out.
      ws.kappa_lo[b] = finite ? std::min({prev, mid, next}) : -1.0;
      ws.kappa_hi[b] = finite ? std::max({prev, mid, next}) : 1.0;
      ws.kappa_abs_max = std::max(ws.kappa_abs_max, finite ? ws.abs_kappa[b] : 1.0);
      prev = next;
    }
  }
  for (int l = 0; l < cfg.road.num_lanes; ++l) {
    c.lane_center[l] = ws.lane_center[l];
    const double d = ws.lane_center[l];
    const double factor = std::max({1.0, 1.0 + kmax * d, 1.0 + kmin * d});
    // A little below the cap: lateral motion and the splice add a few cm/s in XY.
    c.lane_speed_limit[l] = std::min(cfg.limits.max_speed, road.SpeedLimit(l)) / factor - 0.05;
  }
  // Previous choice at this cycle's sample times.
  if (ws.have_prev_traj) {
    for (int k = 0; k < n_samples; ++k) {
      const traj::FrenetState p = ws.prev_traj.At(k * cfg.score.dt + ws.prev_elapsed);
      ws.prev_s[k] = p.s;
      ws.prev_d[k] = p.d;
    }
    c.previous_s = ws.prev_s.data();
    c.previous_d = ws.prev_d.data();
  } else {
    c.previous_s = c.previous_d = nullptr;
  }
  // Traffic: relevant cars only. A car right behind the ego in its lane is its follower's
  // problem (the simulator's traffic brakes for the car ahead) — but only once the ego is
  // squarely in front of it: mid lane change the car may not have seen the ego yet. Traffic
  // that does not react (prediction.followers_react 0: recorded traffic) counts behind too.
  // Predictions are sampled once here: at the scoring samples and at the collision-check
  // steps, t_keep after the observation.
  // The predictor's ghosts (they follow every real car) go last, for the hard checks only.
  const auto cars = predictor.cars();
  int nc = 0, real = 0;
  for (int i = 0; i < static_cast<int>(cars.size()) && nc < kMaxCars; ++i) {
    const TrackedCar& car = cars[i];
    const double hl = 0.5 * car.length, hw = 0.5 * car.width;
    const double sep_s = 0.5 * cfg.check.ego_length + hl;
    if (cfg.followers_react && car.s < -sep_s && std::abs(car.d - start.d) < kFollowerLateral) {
      continue;
    }
    if (!car.ghost) real = nc + 1;
    ws.car_index[nc] = i;
    ws.car_hl[nc] = hl;
    ws.car_hw[nc] = hw;
    ws.car_sep_s[nc] = sep_s;
    ws.car_sep_d[nc] = 0.5 * cfg.check.ego_width + hw;
    const Predictor::Prediction at_start = predictor.Predict(i, ws.t_keep);
    ws.car_s0[nc] = start.s + at_start.s;  // at the start instant, in the start's s frame
    ws.car_d0[nc] = at_start.d;
    for (int k = 0; k < n_samples; ++k) {
      const Predictor::Prediction p = predictor.Predict(i, ws.t_keep + k * cfg.score.dt);
      ws.car_s[nc * n_samples + k] = start.s + p.s;
      ws.car_d[nc * n_samples + k] = p.d;
      ws.car_v[nc * n_samples + k] = p.v;
    }
    const int row = nc * (n_steps + 1);
    for (int j = 1; j <= n_steps; ++j) {
      const Predictor::Prediction p =
          predictor.Predict(i, ws.t_keep + j * ws.collision_step * kTickSeconds);
      ws.step_s[row + j] = start.s + p.s;
      ws.step_d[row + j] = p.d;
      ws.step_v[row + j] = p.v;
      ws.step_vd[row + j] = p.v_d;
      // The car's heading from its predicted velocity (a lane change turns it).
      const double cv = std::max(p.v, 0.5), cvd = p.v_d;
      const double cinv = 1.0 / std::sqrt(cv * cv + cvd * cvd);
      ws.step_dir_s[row + j] = cv * cinv;
      ws.step_dir_d[row + j] = cvd * cinv;
    }
    ++nc;
  }
  c.num_cars = real;
  ws.num_check_cars = nc;
  // FirstCollision's broad reaches: the Udacity footprints' 8 and 5 m, scaled up with the
  // half diagonals of the ego and of each car when they are larger: a base for a car of the
  // Udacity footprint, and per car what its own size adds (a truck's reach is not every car's).
  const double ego_diag = std::hypot(0.5 * cfg.check.ego_length, 0.5 * cfg.check.ego_width);
  auto scale = [&](double car_diag) {
    return std::max(1.0, (ego_diag + car_diag) / (2 * kUdacityHalfDiagonal));
  };
  const double base = scale(kUdacityHalfDiagonal);
  ws.reach_s_base = kReachS * base;
  ws.reach_d = kReachD * base;
  for (int i = 0; i < nc; ++i) {
    const double own = scale(std::hypot(ws.car_hl[i], ws.car_hw[i]));
    ws.car_reach_s[i] = own > base ? kReachS * own - ws.reach_s_base : 0.0;
    ws.car_reach_d[i] = own > base ? kReachD * own - ws.reach_d : 0.0;
  }
  // Bounds the collision check's margins (CollisionChecker::FirstCollision).
  ++ws.traffic_stamp;
  ws.step_v_max = 0;
  for (int i = 0; i < nc; ++i) {
    for (int j = 1; j <= n_steps; ++j) {
      ws.step_v_max = std::max(ws.step_v_max, ws.step_v[i * (n_steps + 1) + j]);
    }
  }
  c.max_car_speed = 0;
  for (int i = 0; i < nc * n_samples; ++i) c.max_car_speed = std::max(c.max_car_speed, ws.car_v[i]);
  c.near_lateral[0] = cost::kNearLateral[0];
  c.near_lateral[1] = cost::kNearLateral[1];
  c.near_longitudinal[0] = cost::kNearLongitudinal[0];
  c.near_longitudinal[1] = cost::kNearLongitudinal[1];
  c.car_s = ws.car_s.data();
  c.car_d = ws.car_d.data();
  c.car_v = ws.car_v.data();
  c.car_half_length = ws.car_hl.data();
  c.car_half_width = ws.car_hw.data();
  c.max_half_length = 0.5 * cfg.check.car_length;
  c.max_half_width = 0.5 * cfg.check.car_width;
  for (int i = 0; i < real; ++i) {
    c.max_half_length = std::max(c.max_half_length, ws.car_hl[i]);
    c.max_half_width = std::max(c.max_half_width, ws.car_hw[i]);
  }
  c.ego_length = cfg.check.ego_length;
  c.ego_width = cfg.check.ego_width;
  c.num_goals = ws.num_goals;
  c.goals = ws.goals;
}

LaneEnds::LaneEnds(const map::Road& road)
    : road_(road), road_end_(-std::numeric_limits<double>::infinity()) {
  rows_.reserve(kMaxCars + cost::kMaxLanes);
  for (int l = 0; l < road_.num_lanes(); ++l) road_end_ = std::max(road_end_, road_.LaneEnd(l));
}

std::span<const SensorCar> LaneEnds::With(const std::vector<SensorCar>& rows, double start_s) {
  if (road_.uniform()) return rows;
  rows_.assign(rows.begin(), rows.begin() + std::min<std::size_t>(rows.size(), kMaxCars));
  const map::ReferenceLine& line = road_.line();
  for (int l = 0; l < road_.num_lanes(); ++l) {
    // The lane's wall (a closed end of the map), or its own end before the road's.
    double end = road_.Wall(l);
    if (road_.LaneEnd(l) < road_end_ - kLaneEndSlack) end = std::min(end, road_.LaneEnd(l));
    if (!std::isfinite(end) || end < start_s - kLaneEndSlack || end > start_s + kLaneEndRange) {
      continue;
    }
    // The car fills the lane's last kLaneEndLength m (inside the road, where the predictor
    // keeps it).
    const double s_car = end - 0.5 * kLaneEndLength;
    const map::Road::Span at = road_.LaneAt(l, s_car);
    if (!at.exists) continue;
    const map::CartesianPose p = line.ToCartesian(s_car, at.centre());
    SensorCar c;
    c.id = kLaneEndId - l;
    c.x = p.x;
    c.y = p.y;
    c.s = s_car;
    c.d = at.centre();
    c.length = kLaneEndLength;
    c.width = std::max(at.width() - 0.2, 0.5);
    rows_.push_back(c);
  }
  return rows_;
}

}  // namespace frenetic::plan::search

#include "plan/search/lattice.h"

#include <algorithm>
#include <cmath>

#include "plan/search/context.h"
#include "plan/search/scoring.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {
namespace {

// m along s: a car in another lane this close is alongside (a lane change must yield to it).
constexpr double kAlongside = 20.0;
// m/s and m: a goal whose speeds reach this low may be stood in; and a stop target this near
// or nearer is no target.
constexpr double kStandingGoal = 0.5;
// m/s: a lane whose limit is within this of the fastest lane's shares the grid's top end speed.
constexpr double kLaneLimitStep = 0.05;
// m/s: a lane's limit this far above the start's speed is worth a constant-acceleration run.
constexpr double kAccelMinGain = 1.0;
constexpr double kLimitRampShare = 0.97;  // of the vehicle's limit (AddLimitRamps)
// m along s: the road is free for a constant-acceleration run when no car is from this far
// behind to this far ahead of the ego (a run from a standstill to the limit takes ~60 m).
constexpr double kAccelFreeBehind = 20.0, kAccelFreeAhead = 100.0;
// m/s: below it a car laterally at rest off its lane's centre holds its d (Lattice::Generate).
constexpr double kCrawlSpeed = 2.0;
// Swerves into a goal region crossed turned (Lattice::AddSwerves): the heading's tangent beyond
// the interval's near end; the durations' step (s); the speed (m/s) their d' is reckoned at, at
// least; the acceleration (m/s^2) that bounds how far the lon bundle spreads about the start's
// speed; the end speeds' count and step; and the end lateral accelerations.
constexpr double kSwerveHeading = 0.03;
constexpr double kSwerveStep = 0.25;
constexpr double kSwerveMinSpeed = 2.0;
constexpr double kSwerveReachAccel = 5.0;
constexpr int kSwerveSpeeds = 3;
constexpr double kSwerveSpeedStep = 3.0;                // m/s
constexpr double kSwerveEndAccels[] = {0.0, 6.0, 9.0};  // m/s^2 across, toward the heading
// A swerve that ended before the goal was met goes on kSwerveLate s at a time (a CommonRoad
// step), for at most kSwerveOverrun s past its end.
constexpr double kSwerveLate = 0.1, kSwerveOverrun = 0.3;
// Passes on a two-way road (Lattice::AddPasses): the moves out and back and the hold between
// (s); how much slower than the ego (m/s) the car ahead must be; and the time (s) below which a
// phase under way counts as done.
constexpr double kPassOut[] = {1.5, 2.5};
constexpr double kPassHold[] = {0.0, 1.0, 2.0, 3.0};
constexpr double kPassBack[] = {1.5, 2.5};
constexpr double kPassMinGain = 2.0;
constexpr double kPassResolve = 0.05;
static_assert(std::size(kPassOut) * std::size(kPassHold) * std::size(kPassBack) + 1 <= kMaxPasses,
              "the workspace's room for passes (and the one under way)");

double Linspace(double lo, double hi, int count, int i) {
  return count <= 1 ? hi : lo + (hi - lo) * i / (count - 1);
}

}  // namespace

void Lattice::AddLon(const LonTraj& l) {
  if (!l.traj.poly.IsFinite()) return;
  const int i = static_cast<int>(ws_.lon.size());
  ws_.lon.push_back(l);
  ws_.lon.back().jerk2 = l.traj.poly.JerkSquaredIntegral(l.traj.duration);
  const int n = ws_.n_samples;
  const double dt = cfg_.score.dt;
  l.traj.Sample(
      0, n, [dt](int k) { return k * dt; }, &ws_.lon_s[i * n], &ws_.lon_sd[i * n],
      &ws_.lon_sdd[i * n]);
  ws_.lon_near_have[i] = 0;  // its masks: when first needed (Scorer::InputFor)
  if (cfg_.check.curve_prefilter && TooFastForTheCurve(i)) {
    ws_.lon.pop_back();
    return;
  }
  ws_.lon.back().too_fast = TooFastForTheVehicle(i);
}

bool Lattice::TooFastForTheVehicle(int i) const {
  if (!(ws_.speed_share > 0)) return false;
  // A sample's s' and the XY speed of the tick ending there (the mean over its 0.02 s) differ
  // by the tick's acceleration times 0.01 s or so: the slack (1.1 m/s at the Udacity track's
  // top speed, 2.5 m/s at a KS vehicle's) covers 100 m/s^2 and more.
  const double limit = (1 + kSpeedSlack) * cfg_.limits.max_speed;
  const int n = ws_.n_samples;
  for (int k = 1; k < n && k * cfg_.score.dt <= cfg_.check.horizon + 1e-9; ++k) {
    // Past the stretch whose curvature was read, the share says nothing.
    if (!(ws_.lon_s[i * n + k] - ws_.start.s <= ws_.speed_reach)) return false;
    if (ws_.lon_sd[i * n + k] * ws_.speed_share > limit) return true;
  }
  return false;
}

bool Lattice::TooFastForTheCurve(int i) const {
  // On a path at offset d the XY curvature is kappa / (1 - kappa d) and the XY speed
  // s' (1 - kappa d): the lateral acceleration s'^2 kappa (1 - kappa d) is at least
  // s'^2 |kappa| (1 - |kappa| max |d|) for any lateral move within the road. The XY check
  // measures the total acceleration (the lateral one and the forward one) on 0.2 s means: a
  // lateral one kCurveSlack above the limit at a sample fails it. From the second sample on
  // (the first is the present state), within the check horizon.
  const int n = ws_.n_samples;
  const double limit = (1 + kCurveSlack) * cfg_.limits.max_accel;
  const int bins = static_cast<int>(ws_.abs_kappa.size());
  for (int k = 1; k < n && k * cfg_.score.dt <= cfg_.check.horizon + 1e-9; ++k) {
    const double v = ws_.lon_sd[i * n + k];
    const int b =
        static_cast<int>(std::floor((ws_.lon_s[i * n + k] - ws_.kappa_s0) / Workspace::kEdgeBin));
    if (b < 0 || b >= bins) continue;
    const double kappa = ws_.abs_kappa[b];
    if (v * v * kappa * std::max(0.0, 1 - kappa * ws_.max_abs_d) > limit) return true;
  }
  return false;
}

void Lattice::AddLat(const LatTraj& l) {
  if (!l.traj.IsFinite()) return;
  const int i = static_cast<int>(ws_.lat.size());
  ws_.lat.push_back(l);
  ws_.lat.back().jerk2 = l.traj.JerkSquared();
  const int n = ws_.n_samples;
  const double dt = cfg_.score.dt;
  l.traj.Sample(
      0, n, [dt](int k) { return k * dt; }, &ws_.lat_d[i * n], &ws_.lat_dd[i * n],
      &ws_.lat_ddd[i * n]);
  NearLat(ws_, ws_.lat_d.data() + i * n, ws_.lat_near.data() + 2 * i * n);
}

LonTraj Lattice::MakeLon(cost::LonKind kind, int lane, double param, double T, int lead) const {
  LonTraj l;
  l.kind = kind;
  l.lane = lane;
  l.param = param;
  l.lead = lead;
  l.traj.duration = T;
  const traj::FrenetState& s0 = ws_.start;
  switch (kind) {
    case cost::LonKind::kVelocityKeeping:
      l.traj.poly = traj::SolveQuartic(s0.s, s0.s_d, s0.s_dd, std::max(param, 0.0), 0.0, T);
      break;
    case cost::LonKind::kFollowing: {
      // Constant time-gap law on the leader's predicted state at T:
      // s_target = s_lead(T) - (D0 + tau v_lead(T)), minus `param` more.
      const Predictor::Prediction lead_at = predictor_.Predict(lead, ws_.t_keep + T);
      const double s_lead = ws_.start.s + lead_at.s;
      // follow_d0 is between the centres of two configured cars: longer ones need more.
      const double longer = 0.5 * (predictor_.cars()[lead].length - cfg_.check.car_length) +
                            0.5 * (cfg_.check.ego_length - cfg_.check.car_length);
      const double target =
          s_lead - (cfg_.grid.follow_d0 + cfg_.grid.follow_tau * lead_at.v) - param - longer;
      l.traj.poly = traj::SolveQuintic(s0.s, s0.s_d, s0.s_dd, target, lead_at.v, 0.0, T);
      break;
    }
    case cost::LonKind::kStopping:
      l.traj.poly =
          traj::SolveQuintic(s0.s, s0.s_d, s0.s_dd, s0.s + std::max(param, 0.0), 0.0, 0.0, T);
      break;
    case cost::LonKind::kBraking:
      // Decelerate at `param` at once for T, then hold the speed reached (the trajectory's
      // constant-velocity continuation): s0 + v0 t - param t^2 / 2.
      l.traj.poly = {};
      l.traj.poly.c[0] = s0.s;
      l.traj.poly.c[1] = s0.s_d;
      l.traj.poly.c[2] = -0.5 * param;
      break;
    case cost::LonKind::kAccelerating:
      // Accelerate at `param` at once for T, then hold the speed reached.
      l.traj.poly = {};
      l.traj.poly.c[0] = s0.s;
      l.traj.poly.c[1] = s0.s_d;
      l.traj.poly.c[2] = 0.5 * param;
      break;
  }
  return l;
}

// Astride a lane line, with less of the simulator's lane-line timer left than the grid's
// shortest lateral move needs to leave the line's band: to the centre of each lane beside the
// line, a move that leaves the band (and the chords' reading of d past it, 0.3 m) with a fifth
// of the time left to spare, over 0.6 s at least. The time is a rest-to-rest move's (the
// stalled move of the case below); MakeLat starts from the ego's motion across, and the limit
// checks judge the move it makes (one too quick for the acceleration limit across fails them).
// The grid's durations start at 2 s; a change that ran late (replanned, or slowed by a car
// braking in the lane it moved into) then had none that left in time, and every candidate
// failed the timer or hit a car: udacity seed 837 stayed astride for 3 s where a move over
// 0.83 s was clear.
void Lattice::AddLineExits(const bool reachable[]) {
  if (ws_.straddle_at_start <= 0) return;
  const traj::FrenetState& start = ws_.start;
  const double w = cfg_.road.lane_width;
  const int line = static_cast<int>(std::lround(start.d / w));
  if (line < 1 || line >= cfg_.road.num_lanes) return;
  const double left = (kMaxStraddleTicks - ws_.straddle_at_start) * kTickSeconds;
  constexpr double kSpare = 0.8, kChordSlack = 0.3, kShortest = 0.6;
  for (const int l : {line - 1, line}) {
    if (!reachable[l]) continue;
    const double span = ws_.lane_center[l] - start.d;
    const double edge = line * w + (l < line ? -1 : 1) * (kStraddle + kChordSlack);
    // The share of the move that leaves the band: none when the centre lies inside it or on
    // the other side (a span of 0 gives inf or NaN, which the test drops too).
    const double f = (edge - start.d) / span;
    if (!(f > 0 && f < 1)) continue;
    // The share u of a rest-to-rest quintic's time at which it has covered f of its span.
    double lo = 0, hi = 1;
    for (int it = 0; it < 40; ++it) {
      const double u = 0.5 * (lo + hi);
      ((10 - 15 * u + 6 * u * u) * u * u * u < f ? lo : hi) = u;
    }
    const double T = std::max(kShortest, kSpare * left / hi);
    if (T < cfg_.lat.min_duration) AddLat(MakeLat(l, 0.0, T));
  }
}

LatTraj Lattice::MakeLat(int lane, double offset, double T, double delay) const {
  LatTraj l;
  l.lane = lane;
  l.offset = offset;
  l.traj.duration = T;
  l.traj.delay = delay;
  const traj::FrenetState& s0 = ws_.start;
  const double target = std::clamp(ws_.lane_center[lane] + offset, ws_.road_left, ws_.road_right);
  // A delayed move holds still first (only offered when the ego is nearly at rest laterally).
  l.traj.poly = delay > 0 ? traj::SolveQuintic(s0.d, 0.0, 0.0, target, 0.0, 0.0, T)
                          : traj::SolveQuintic(s0.d, s0.d_d, s0.d_dd, target, 0.0, 0.0, T);
  return l;
}

LatTraj Lattice::MakeSwerve(int goal, double d, double d_d, double T, double d_dd) const {
  LatTraj l;
  l.kind = LatKind::kSwerve;
  l.goal = goal;
  l.traj.duration = T;
  const traj::FrenetState& s0 = ws_.start;
  l.traj.poly = traj::SolveQuintic(s0.d, s0.d_d, s0.d_dd, d, d_d, d_dd, T);
  l.lane = LaneOf(cfg_, ws_, d);
  l.offset = d - ws_.lane_center[l.lane];
  return l;
}

// Into a goal region whose headings leave out the road's own (a goal crossed turned: cutting
// back into a lane after passing, say): quintic moves that end inside it, at its middle and a
// little in from the side they come from, moving across at a heading kSwerveHeading beyond the
// interval's near end (at a few end speeds) and still turning into it or not (end lateral
// accelerations), after each of the durations the window allows; and the previous cycle's
// swerve, to its end. A lane move never crosses such a region (its d' is 0 at the end). What
// follows a swerve's end leaves the lane turned: a swerve pairs only with the lon trajectories
// that put it in its region at its end (Workspace::SwerveEndsInside), whose checks stop there
// (Workspace::CheckTicks), as the run ends at its goal. At most kMaxSwerves, the shortest first.
void Lattice::AddSwerves() {
  const traj::FrenetState& s0 = ws_.start;
  const double v = std::max(s0.s_d, kSwerveMinSpeed);
  int added = 0;
  for (int g = 0; g < ws_.num_goals; ++g) {
    const cost::GoalRegion& r = ws_.goals[g];
    const int turned = cost::CrossedTurned(r);
    const bool right = turned > 0;
    if (turned == 0 || !std::isfinite(r.d_lo) || !std::isfinite(r.d_hi) || !(r.d_hi > r.d_lo)) {
      continue;
    }
    double h = right ? r.h_lo + kSwerveHeading : r.h_hi - kSwerveHeading;
    if (!(h >= r.h_lo && h <= r.h_hi)) h = 0.5 * (r.h_lo + r.h_hi);
    const double sign = turned;
    const double from_side = right ? 0.25 : 0.75;  // coming from smaller d when moving right
    for (double T = kSwerveStep; T <= cfg_.score.horizon + 1e-9; T += kSwerveStep) {
      if (T < r.t_lo || T > r.t_hi) continue;
      const double s_est = s0.s + s0.s_d * T;
      const double reach = kSwerveReachAccel * T * T;  // the lon bundle's spread about s_est
      if (s_est + reach < r.s_lo || s_est - reach > r.s_hi) continue;
      for (const double f : {0.5, from_side}) {
        const double d = r.d_lo + f * (r.d_hi - r.d_lo) + r.d_slope * (s_est - r.s_ref);
        for (int k = 0; k < kSwerveSpeeds; ++k) {
          for (const double a : kSwerveEndAccels) {
            if (added >= kMaxSwerves) return;
            AddLat(MakeSwerve(g, d, h * (v + k * kSwerveSpeedStep), T, sign * a));
            ++added;
          }
        }
      }
    }
  }
}

// The swerve under way, to its end.
void Lattice::AddSwerveUnderWay() {
  if (!ws_.have_prev_traj || ws_.prev_swerve_goal < 0 || ws_.prev_swerve_goal >= ws_.num_goals) {
    return;
  }
  const traj::Trajectory1d& prev = ws_.prev_traj.lat;
  const double remaining = prev.end_time() - ws_.prev_elapsed;
  if (remaining >= kTickSeconds) {
    const traj::State1d e = prev.poly.At(prev.duration);
    AddLat(MakeSwerve(ws_.prev_swerve_goal, e.p, e.v, remaining, e.a));
    // ...and its longitudinal trajectory, to the same end state at the same time: the
    // swerve's region lies where the two meet.
    const traj::Trajectory1d& lon = ws_.prev_traj.lon;
    const double lon_left = lon.end_time() - ws_.prev_elapsed;
    if (lon_left > 0.05) {
      const traj::State1d le = lon.poly.At(lon.duration);
      const traj::FrenetState& s0 = ws_.start;
      LonTraj l;
      l.kind = cost::LonKind::kVelocityKeeping;
      l.param = le.v;
      l.traj.duration = lon_left;
      l.traj.poly = traj::SolveQuintic(s0.s, s0.s_d, s0.s_dd, le.p, le.v, le.a, lon_left);
      AddLon(l);
    }
  } else if (remaining > -kSwerveOverrun) {
    // Ended between two of the problem's steps, the goal not met yet: on as it goes (constant
    // lateral acceleration) for kSwerveLate s more, a swerve where that is still in the region.
    const traj::FrenetState& s0 = ws_.start;
    const double T = kSwerveLate;
    AddLat(MakeSwerve(ws_.prev_swerve_goal, s0.d + s0.d_d * T + 0.5 * s0.d_dd * T * T,
                      s0.d_d + s0.d_dd * T, T, s0.d_dd));
  }
}

// On a two-way road, past a slow car ahead in the lane beside the oncoming lane: out into the
// oncoming lane's centre, a while there, and back to the own lane's centre (kPassOut x kPassHold x
// kPassBack), each checked over the whole horizon like any move: a lane change into the
// oncoming lane and staying there meets its traffic within the horizon, a pass need not. None
// toward a goal crossed turned (swerves reach those). The pass under way goes on: its move out
// to the same end (and the same hold and move back), or, from its hold on, a lane change back
// that waits out the hold.
void Lattice::AddPasses() {
  const traj::FrenetState& s0 = ws_.start;
  const bool prev_pass = ws_.have_prev_traj && ws_.prev_traj.lat.back_duration > 0;
  if (prev_pass) {
    const traj::Trajectory1d& prev = ws_.prev_traj.lat;
    const double elapsed = ws_.prev_elapsed;
    const int own = ws_.prev_lat_lane;
    if (elapsed < prev.duration - kPassResolve) {
      LatTraj l;
      l.kind = LatKind::kPass;
      l.lane = own;
      l.traj = prev;
      l.traj.duration = prev.duration - elapsed;
      const traj::State1d out = prev.poly.At(prev.duration);
      l.traj.poly = traj::SolveQuintic(s0.d, s0.d_d, s0.d_dd, out.p, 0.0, 0.0, l.traj.duration);
      AddLat(l);
    } else if (elapsed < prev.duration + prev.hold - kPassResolve) {
      AddLat(MakeLat(own, 0.0, prev.back_duration, prev.duration + prev.hold - elapsed));
    } else if (prev.end_time() - elapsed > kPassResolve) {
      AddLat(MakeLat(own, 0.0, prev.end_time() - elapsed));
    }
  }
  if (!cfg_.grid.passes) return;
  // A goal crossed turned is reached by a swerve (AddSwerves), which a pass never ends in.
  for (int g = 0; g < ws_.num_goals; ++g) {
    if (cost::CrossedTurned(ws_.goals[g]) != 0) return;
  }
  const int own = LaneOf(cfg_, ws_, s0.d);
  const int oncoming = own - 1;
  if (oncoming < 0 || !ws_.lane_oncoming[oncoming] || !ws_.lane_exists[oncoming] ||
      ws_.lane_oncoming[own]) {
    return;
  }
  const int lead = Leader(own);
  if (lead < 0 || !(ws_.car_v[lead * ws_.n_samples] < s0.s_d - kPassMinGain)) return;
  for (const double out : kPassOut) {
    for (const double hold : kPassHold) {
      for (const double back : kPassBack) {
        LatTraj l;
        l.kind = LatKind::kPass;
        l.lane = own;
        const double d_out = ws_.lane_center[oncoming], d_own = ws_.lane_center[own];
        l.traj.duration = out;
        l.traj.poly = traj::SolveQuintic(s0.d, s0.d_d, s0.d_dd, d_out, 0.0, 0.0, out);
        l.traj.hold = hold;
        l.traj.back_duration = back;
        l.traj.back = traj::SolveQuintic(d_out, 0.0, 0.0, d_own, 0.0, 0.0, back);
        AddLat(l);
      }
    }
  }
}

// The nearest car ahead in `lane` at the start instant (context index), or -1.
int Lattice::Leader(int lane) const {
  int best = -1;
  double best_s = 1e18;
  for (int c = 0; c < ws_.ctx.num_cars; ++c) {
    if (std::abs(ws_.car_d0[c] - ws_.lane_center[lane]) > 0.6 * cfg_.road.lane_width) continue;
    if (ws_.car_s0[c] <= ws_.start.s) continue;
    if (ws_.car_s0[c] < best_s) {
      best_s = ws_.car_s0[c];
      best = c;
    }
  }
  return best;
}

// Constant-deceleration braking, each level to a few lower speeds (fractions of the current
// one): the quick, strong braking a quintic cannot start with.
void Lattice::AddBraking() {
  const double v0 = std::max(ws_.start.s_d, 0.0);
  if (v0 < 1.0) return;
  for (int bi = 0; bi < cfg_.brake.decels; ++bi) {
    const double a = Linspace(cfg_.brake.min_decel, cfg_.brake.max_decel, cfg_.brake.decels, bi);
    for (int ti = 0; ti < cfg_.brake.targets; ++ti) {
      // Target speeds from standstill up to (but not including) the current speed.
      const double target = v0 * ti / cfg_.brake.targets;
      AddLon(MakeLon(cost::LonKind::kBraking, -1, a, (v0 - target) / a));
    }
  }
}

// Into the gaps between consecutive cars of `lane` (the cfg_.grid.gap_targets nearest the ego along
// s): a following trajectory of the car ahead whose end point is the gap's middle at T, kept
// clear of both cars (their footprints and margin_s), at its speed. A merge into a line of
// traffic needs such a slot; the following law alone puts the ego its own gap behind a car.
void Lattice::AddGapTargets(int lane, double T) {
  int cars[kMaxCars];
  int n = 0;
  for (int c = 0; c < ws_.ctx.num_cars && n < kMaxCars; ++c) {
    if (std::abs(ws_.car_d0[c] - ws_.lane_center[lane]) > 0.6 * cfg_.road.lane_width) continue;
    // Insertion by s at the start instant (ties: index).
    int k = n++;
    while (k > 0 && ws_.car_s0[cars[k - 1]] > ws_.car_s0[c]) {
      cars[k] = cars[k - 1];
      --k;
    }
    cars[k] = c;
  }
  // The gaps (behind car i - 1, ahead of car i... i.e. between cars[i - 1] and cars[i]), nearest
  // the ego first: by the distance of the gap's middle now.
  int gaps[kMaxCars];
  int m = 0;
  for (int i = 1; i < n; ++i) {
    const double mid = 0.5 * (ws_.car_s0[cars[i - 1]] + ws_.car_s0[cars[i]]) - ws_.start.s;
    int k = m++;
    while (k > 0) {
      const int j = gaps[k - 1];
      const double other = 0.5 * (ws_.car_s0[cars[j - 1]] + ws_.car_s0[cars[j]]) - ws_.start.s;
      if (std::abs(other) <= std::abs(mid)) break;
      gaps[k] = gaps[k - 1];
      --k;
    }
    gaps[k] = i;
  }
  for (int g = 0; g < std::min(m, cfg_.grid.gap_targets); ++g) {
    const int ahead = cars[gaps[g]], behind = cars[gaps[g] - 1];
    const Predictor::Prediction pa = predictor_.Predict(ws_.car_index[ahead], ws_.t_keep + T);
    const Predictor::Prediction pb = predictor_.Predict(ws_.car_index[behind], ws_.t_keep + T);
    const double lo = pb.s + ws_.car_sep_s[behind] + cfg_.check.margin_s;
    const double hi = pa.s - ws_.car_sep_s[ahead] - cfg_.check.margin_s;
    if (!(hi > lo)) continue;
    // The following law's target, shifted (param) to the gap's middle.
    const double longer =
        0.5 * (predictor_.cars()[ws_.car_index[ahead]].length - cfg_.check.car_length) +
        0.5 * (cfg_.check.ego_length - cfg_.check.car_length);
    const double law = pa.s - (cfg_.grid.follow_d0 + cfg_.grid.follow_tau * pa.v) - longer;
    AddLon(
        MakeLon(cost::LonKind::kFollowing, lane, law - 0.5 * (lo + hi), T, ws_.car_index[ahead]));
  }
}

// On a free road, constant acceleration up to the fastest lane's limit (for every lane) and to
// each slower reachable lane's own (with grid.lane_limit_speeds): a quartic starts and ends at zero
// acceleration, so it reaches the limit from a standstill in about 1.5 v / a_peak; a step to a
// constant acceleration, which the simulator's block means allow (udacity-sim.md §7.2, §7.3), takes
// v / a.
void Lattice::AddAccelerating(const bool reachable[], double vmax) {
  const double v0 = std::max(ws_.start.s_d, 0.0);
  // On a free road only: in traffic the run meets slow cars and their cut-ins at the limit's
  // closing speed, where the quartics' gentler run leaves time to see them (ungated, dense
  // traffic had 4 incidents in 50 episodes instead of 0).
  for (int c = 0; c < ws_.ctx.num_cars; ++c) {
    const double ds = ws_.car_s0[c] - ws_.start.s;
    if (ds > -kAccelFreeBehind && ds < kAccelFreeAhead) return;
  }
  for (int l = -1; l < cfg_.road.num_lanes; ++l) {
    double target = vmax;
    if (l >= 0) {
      if (!cfg_.grid.lane_limit_speeds || !reachable[l] ||
          ws_.ctx.lane_speed_limit[l] >= vmax - kLaneLimitStep) {
        continue;
      }
      target = ws_.ctx.lane_speed_limit[l];
    }
    if (target - v0 < kAccelMinGain) continue;
    for (int ai = 0; ai < cfg_.grid.accels; ++ai) {
      const double a = Linspace(cfg_.grid.accel_min, cfg_.grid.accel_max, cfg_.grid.accels, ai);
      AddLon(MakeLon(cost::LonKind::kAccelerating, l, a, (target - v0) / a));
    }
  }
}

// With a vehicle's limits, in any traffic: to each end speed of the grid above the ego's, the
// constant acceleration the vehicle can hold up to it (a_max, or a_max v_switch / v above the
// switch speed, at the end speed; 3% inside), within limits.max_accel. In recorded traffic that
// closes in from behind at twice the ego's speed (highD), the polynomials, which start from the
// present acceleration, gain too little in the first second.
void Lattice::AddLimitRamps(double vgrid) {
  const VehicleLimits& veh = cfg_.vehicle;
  if (!(veh.max_accel > 0)) return;
  const double v0 = std::max(ws_.start.s_d, 0.0);
  for (int vi = 0; vi < cfg_.grid.speeds; ++vi) {
    const double target = Linspace(0, vgrid, cfg_.grid.speeds, vi);
    if (target - v0 < kAccelMinGain) continue;
    const double a = kLimitRampShare * std::min(veh.MaxForwardAccel(target), cfg_.limits.max_accel);
    AddLon(MakeLon(cost::LonKind::kAccelerating, -1, a, (target - v0) / a));
  }
}

double ReachableSpeed(const VehicleLimits& veh, double max_accel, double v0, double T) {
  if (!(veh.max_accel > 0)) return v0 + max_accel * T;
  // dv/dt = a up to the switch speed, a v_switch / v above it (v^2 grows linearly).
  const double a = veh.max_accel, vs = veh.switch_speed;
  if (v0 < vs) {
    const double t1 = (vs - v0) / a;
    if (t1 >= T) return v0 + a * T;
    return std::sqrt(vs * vs + 2 * a * vs * (T - t1));
  }
  return std::sqrt(v0 * v0 + 2 * a * vs * T);
}

// The car in `lane` nearest to the ego along s within kAlongside at the start instant (context
// index), or -1: the one a lane change into that lane must pass behind or in front of.
int Lattice::Alongside(int lane) const {
  int best = -1;
  double best_ds = kAlongside;
  for (int c = 0; c < ws_.ctx.num_cars; ++c) {
    if (std::abs(ws_.car_d0[c] - ws_.lane_center[lane]) > 0.6 * cfg_.road.lane_width) continue;
    const double ds = std::abs(ws_.car_s0[c] - ws_.start.s);
    if (ds < best_ds) {
      best_ds = ds;
      best = c;
    }
  }
  return best;
}

void Lattice::Generate() {
  const traj::FrenetState& start = ws_.start;
  ws_.lon.clear();
  ws_.lat.clear();
  ws_.cand_lon.clear();
  ws_.cand_lat.clear();
  ++ws_.candidate_stamp;
  // Lanes within reach (grid.lane_reach lane widths): the current one and its neighbours.
  bool reachable[cost::kMaxLanes] = {};
  for (int l = 0; l < cfg_.road.num_lanes; ++l) {
    reachable[l] = ws_.lane_exists[l] && std::abs(ws_.lane_center[l] - start.d) <=
                                             cfg_.grid.lane_reach * cfg_.road.lane_width;
  }
  double vmax = 0;
  for (int l = 0; l < cfg_.road.num_lanes; ++l) vmax = std::max(vmax, ws_.ctx.lane_speed_limit[l]);
  // The end speeds' grid reaches no higher than the ego can speed up to within the longest
  // duration (its steps stay as fine where it can go, however high the top speed).
  const double vgrid =
      std::min(vmax, ReachableSpeed(cfg_.vehicle, cfg_.limits.max_accel, std::max(start.s_d, 0.0),
                                    cfg_.grid.max_duration));
  for (int di = 0; di < cfg_.grid.durations; ++di) {
    const double T =
        Linspace(cfg_.grid.min_duration, cfg_.grid.max_duration, cfg_.grid.durations, di);
    for (int vi = 0; vi < cfg_.grid.speeds; ++vi) {
      // Velocity keeping to end speeds from 0 to the fastest lane's limit.
      AddLon(MakeLon(cost::LonKind::kVelocityKeeping, -1, Linspace(0, vgrid, cfg_.grid.speeds, vi),
                     T));
    }
    // ...and to each slower lane's own limit (the outer lanes of a bend, where the XY speed is
    // s' (1 + kappa d)): the grid's step would otherwise leave such a lane up to a whole step
    // (2 m/s) below its limit, and the ego driving a bend well under the speed limit.
    for (int l = 0; l < cfg_.road.num_lanes && cfg_.grid.lane_limit_speeds; ++l) {
      if (!reachable[l] || ws_.ctx.lane_speed_limit[l] >= vmax - kLaneLimitStep) continue;
      AddLon(MakeLon(cost::LonKind::kVelocityKeeping, l, ws_.ctx.lane_speed_limit[l], T));
    }
    if (cfg_.grid.stop) {
      AddLon(MakeLon(cost::LonKind::kStopping, -1, 0.5 * start.s_d * T, T));
    }
    // A goal region one may stand in (its speeds reach down to rest): stopping in its middle,
    // to wait there for its time window (a goal in a queue).
    for (int g = 0; g < ws_.num_goals; ++g) {
      const cost::GoalRegion& r = ws_.goals[g];
      const double mid = 0.5 * (r.s_lo + r.s_hi) - start.s;
      if (!(r.v_lo <= kStandingGoal) || !std::isfinite(mid) || !(mid > kStandingGoal) ||
          !(mid < start.s_d * T + kStandingGoal)) {
        continue;
      }
      AddLon(MakeLon(cost::LonKind::kStopping, -1, mid, T));
    }
    if (di == 0) {
      AddBraking();
      AddAccelerating(reachable, vmax);
      if (cfg_.grid.limit_ramps) AddLimitRamps(vgrid);
    }
    for (int l = 0; l < cfg_.road.num_lanes; ++l) {
      if (!reachable[l]) continue;
      // Follow the lane's leader, and yield to (drop behind) the car alongside, which the
      // delayed lane changes below need to pass behind it (Apollo's yield samples).
      const int targets[2] = {Leader(l), Alongside(l)};
      for (int k = 0; k < 2; ++k) {
        const int lead = targets[k];
        if (lead < 0 || (k == 1 && lead == targets[0])) continue;
        for (int g = 0; g < cfg_.grid.follow_gaps; ++g) {
          // Longer time gaps are extra distance on top of the base law.
          const double extra = g * cfg_.grid.follow_tau_step * ws_.car_v[lead * ws_.n_samples];
          AddLon(MakeLon(cost::LonKind::kFollowing, l, extra, T, ws_.car_index[lead]));
        }
      }
      if (cfg_.grid.gap_targets > 0) AddGapTargets(l, T);
    }
  }
  // Laterally at rest (keeping a lane): one duration stands for all for the own lane (they
  // coincide), and lane changes may also wait before they start.
  const bool at_rest = std::abs(start.d_d) < 0.2 && std::abs(start.d_dd) < 0.5;
  // The end offsets around a lane's centre: wider after a search where nothing passed.
  const bool wide = ws_.none_passed_last && cfg_.lat.escape_offsets > 0;
  const int offsets = wide ? cfg_.lat.escape_offsets : cfg_.lat.offsets;
  const double offset_step = wide ? cfg_.lat.escape_offset_step : cfg_.lat.offset_step;
  for (int l = 0; l < cfg_.road.num_lanes; ++l) {
    if (!reachable[l]) continue;
    const bool own = std::abs(ws_.lane_center[l] - start.d) < 0.5 * cfg_.road.lane_width;
    const bool centred = own && at_rest && std::abs(ws_.lane_center[l] - start.d) < 0.1;
    const bool crawl_hold = own && at_rest && !centred && start.s_d < kCrawlSpeed;
    // Moves of T s to each end offset around the lane's centre (for the least harm alone: see
    // LatTraj::least_harm_only).
    const auto add_ends = [&](double T, bool least_harm_only) {
      for (int oi = 0; oi < offsets; ++oi) {
        LatTraj m = MakeLat(l, (oi - offsets / 2) * offset_step, T);
        m.least_harm_only = least_harm_only;
        AddLat(m);
      }
    };
    for (int ti = 0; ti < (centred ? 1 : crawl_hold ? 0 : cfg_.lat.durations); ++ti) {
      add_ends(Linspace(cfg_.lat.min_duration, cfg_.lat.max_duration, cfg_.lat.durations, ti),
               false);
    }
    if (ws_.none_passed_last && cfg_.lat.escape_duration > 0 && !centred && !crawl_hold) {
      add_ends(cfg_.lat.escape_duration, cfg_.lat.escape_least_harm);
    }
    // At a crawl, laterally at rest off the lane's centre: holding d, the own lane's only move. A
    // move across there turns the car far off the lane's heading for the little way it drives
    // (a queue), which a goal's orientation and the lanelets' borders mind.
    if (crawl_hold) {
      AddLat(MakeLat(l, start.d - ws_.lane_center[l], cfg_.lat.max_duration));
    }
    // A lane change that waits holds d where it is: none is offered anew while astride a line,
    // where the simulator's lane-line timer runs on (the least harm, which may drop that check,
    // took one every cycle and held the ego astride for over 3 s: udacity seed 837). One under
    // way (below) goes on.
    if (!own && at_rest && ws_.straddle_at_start == 0) {
      const double T = Linspace(cfg_.lat.min_duration, cfg_.lat.max_duration, 3, 1);
      for (int k = 1; k <= cfg_.lat.delays; ++k) {
        AddLat(MakeLat(l, 0.0, T, k * cfg_.lat.delay_step));
      }
    }
    // The lateral move under way, to its planned end time: replanning with full durations
    // every cycle would stretch a lane change indefinitely (more time astride the line), and
    // a waiting one would never start.
    if (ws_.have_prev_traj && l == ws_.prev_lat_lane && ws_.prev_traj.lat.back_duration <= 0) {
      const traj::Trajectory1d& prev = ws_.prev_traj.lat;
      const double wait = prev.delay - ws_.prev_elapsed;
      const double remaining = prev.end_time() - ws_.prev_elapsed;
      if (wait > 0.05) {
        AddLat(MakeLat(l, ws_.prev_lat_offset, prev.duration, wait));
      } else if (remaining > 0.3 && remaining < cfg_.lat.min_duration - 0.05) {
        AddLat(MakeLat(l, ws_.prev_lat_offset, remaining));
      }
    }
  }
  AddLineExits(reachable);
  AddSwerves();
  AddSwerveUnderWay();
  AddPasses();
  for (int i = 0; i < static_cast<int>(ws_.lon.size()); ++i) {
    for (int j = 0; j < static_cast<int>(ws_.lat.size()); ++j) {
      if (ws_.lon[i].lane >= 0 && ws_.lon[i].lane != ws_.lat[j].lane) continue;
      if (ws_.lat[j].swerve() ? !ws_.SwerveEndsInside(i, j) : ws_.lon[i].too_fast) continue;
      ws_.cand_lon.push_back(i);
      ws_.cand_lat.push_back(j);
    }
  }
}

}  // namespace frenetic::plan::search

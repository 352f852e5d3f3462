// The search planner's collision checks: a candidate against the predicted traffic at every
// collision step of the check horizon, as oriented boxes inflated by the safety margins
// (headway to a car ahead, room for a car behind in another lane), with per-bundle samples
// and reach masks so that the many candidates of a bundle share the work. The limit checks are
// limits.h.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "frenetic/traj/box.h"
#include "frenetic/traj/frenet.h"
#include "plan/search/bundle_rows.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// A candidate's states at the collision-check steps, as FirstCollision asks for them (a tick
// index j * collision_step): s, s', d and d' (the second derivatives read 0), the values
// traj::FrenetTrajectory::At gives at that tick.
// Near(j): the cars (bit c) that pass FirstCollision's reach test at step j with the scales
// StepsOf was given; the others are skipped there without changing its result.
class StepStates {
 public:
  // near_lon, near_lat: per step, the cars passing the longitudinal and the lateral reach
  // tests (Near is their and).
  StepStates(const double* s, const double* sd, const double* d, const double* dd, int step,
             const std::uint64_t* near_lon, const std::uint64_t* near_lat)
      : s_(s), sd_(sd), d_(d), dd_(dd), near_lon_(near_lon), near_lat_(near_lat), step_(step) {}
  traj::FrenetState operator()(int tick) const {
    const int j = tick / step_;
    return {s_[j], sd_[j], 0.0, d_[j], dd_[j], 0.0};
  }
  std::uint64_t Near(int j) const { return near_lon_[j] & near_lat_[j]; }
  // The same states with other lateral reach masks (a narrower test's).
  StepStates WithNearLat(const std::uint64_t* near_lat) const {
    StepStates r = *this;
    r.near_lat_ = near_lat;
    return r;
  }
  // s and d at step j ([0, n_steps]; rows contiguous in j).
  const double* s() const { return s_; }
  const double* d() const { return d_; }

 private:
  const double *s_, *sd_, *d_, *dd_;
  const std::uint64_t *near_lon_, *near_lat_;
  int step_;
};

class CollisionChecker {
 public:
  // `ws` must outlive the checker; it reads the traffic and the start state of ws and, for
  // Collides, the ticks ws.tk_* (Workspace::FillTicks).
  CollisionChecker(const Settings& cfg, Workspace& ws);

  // Oriented-box overlap of the ticks ws.tk_* with every car over the check horizon (inflated
  // boxes).
  bool Collides() const {
    return FirstCollision(
               [this](int i) {
                 return traj::FrenetState{ws_.tk_s[i], ws_.tk_sd[i], 0.0,
                                          ws_.tk_d[i], ws_.tk_dd[i], 0.0};
               },
               1.0) <= ws_.n_steps;
  }

  // The first collision step (1..n_steps) of `state_at` (state at a tick index), or
  // n_steps + 1 when none; car_hit (optional) receives the context index of the car hit. The
  // safety margins are scaled by margin_scale (0: bare boxes), except the room kept for a car
  // behind in another lane, scaled by behind_scale: that car does not see the ego until it is
  // in front of it (the simulator's traffic only brakes for a car within 2 m laterally), so
  // moving into its way is never safe. With ghosts false only the real cars count, not the
  // predictor's lane-change hypotheses (Workspace::num_check_cars).
  // from: the first step tested (the caller knows the earlier ones do not collide); to: the
  // last (0: n_steps; a swerve's Workspace::CheckSteps).
  template <typename StateAt>
  int FirstCollision(StateAt state_at, double margin_scale, double behind_scale = 1.0,
                     int* car_hit = nullptr, bool ghosts = true, int from = 1, int to = 0) const;
  // Whether `steps` collide at step j (1..n_steps) as FirstCollision(steps, margin_scale,
  // behind_scale, nullptr, ghosts) tests it there.
  bool CollidesAt(const StepStates& steps, int j, double margin_scale, double behind_scale,
                  bool ghosts) const {
    return FirstCarHit(steps, j, CarMask(ghosts), margin_scale, behind_scale) >= 0;
  }

  // Candidate c's states at the collision-check steps, with the cars within reach of a
  // FirstCollision(..., margin_scale, behind_scale) at each step. Each bundle trajectory is
  // sampled once and kept while it is unchanged (checked bytewise), and its cars within reach
  // once per cycle's traffic (ws.traffic_stamp) and scales, so the many candidates that share
  // it do not evaluate its polynomial or visit every car again. Valid until the next call.
  StepStates StepsOf(int c, double margin_scale = 1.0, double behind_scale = 1.0);

  // Candidate c's s and d at the collision-check steps (rows [0, n_steps], the same values as
  // StepsOf's), without the reach tests; sampled like StepsOf, and valid as long as its rows.
  struct Rows {
    const double* s;
    const double* d;
  };
  Rows StepRows(int c);

  // Whether candidate c collides with the inflated boxes: FirstCollision(StepsOf(c)) <=
  // n_steps, the same answer, but the steps and cars that the last colliding candidates of its
  // bundles hit are tried first (the candidates of a bundle mostly run into the same car at
  // about the same step), which spares the scan of the steps before.
  bool CandidateCollides(int c);

  // Candidate c's first collision step on bare boxes (margin_scale 0, the room behind kept,
  // no ghosts) over the whole horizon, n_steps + 1 when none: FirstCollision(StepsOf(c, 0.0,
  // 1.0), 0.0, 1.0, nullptr, false), measured once for the candidates and traffic of a cycle
  // (later calls read it). The least-harm choice ranks by it.
  int BareContact(int c);
  // Whether BareContact(c) is measured already.
  bool BareContactKnown(int c) const {
    return bare_traffic_ == ws_.traffic_stamp && bare_candidates_ == ws_.candidate_stamp &&
           static_cast<std::size_t>(c) < bare_epoch_.size() && bare_epoch_[c] == epoch_;
  }
  // Whether a bare-box contact means a collision with the inflated boxes too: the margins
  // only grow the boxes (none is negative). Then a candidate whose BareContact is within its
  // check steps collides (CandidateCollides).
  bool BareContactImpliesCollision() const;

  // FirstCollision's reach along s at a step where the ego's s-speed is s_d: no car farther
  // away can collide (+inf when the margins cannot be bounded).
  double ReachS(double s_d, double margin_scale, double behind_scale) const;
  // The largest margin FirstCollision can give a car at such a step (ReachS less the base).
  double Widest(double s_d, double margin_scale, double behind_scale) const;

 private:
  // FirstCollision at one step: the ego there, and whether car c collides with it.
  struct StepEgo;
  StepEgo EgoAt(const traj::FrenetState& st, double margin_scale, double behind_scale) const;
  bool HitsAt(const StepEgo& e, int j, int c, double margin_scale, double behind_scale) const;
  // FirstCollision's cars: bit c for each context index it tests.
  std::uint64_t CarMask(bool ghosts) const {
    const int num_cars = ghosts ? ws_.num_check_cars : ws_.ctx.num_cars;
    return num_cars >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << num_cars) - 1;
  }
  // The first car (by index) of the mask `cars` that the ego of `state_at` (with Near) collides
  // with at step j, -1 when none.
  template <typename StateAt>
  int FirstCarHit(const StateAt& state_at, int j, std::uint64_t cars, double margin_scale,
                  double behind_scale) const;

  // Row i of `rows` (lon_steps_ or lat_steps_) holds `tr` at the steps (unless kept); true
  // when sampled anew.
  bool SampleSteps(const traj::Trajectory1d& tr, int i, BundleRows& rows);

  const Settings& cfg_;
  Workspace& ws_;
  // Per bundle slot, the trajectory at the steps (p, v: s and s', or d and d').
  BundleRows lon_steps_, lat_steps_;
  // Per bundle slot and step, the cars passing the lateral (lat) and the longitudinal (lon)
  // reach tests, with what they were computed for; the lon ones twice (the second half for
  // bare boxes, margin_scale 0 and behind_scale 1).
  struct LonNearKey {
    std::uint64_t stamp = 0;
    double margin_scale = 0, behind_scale = 0;
  };
  std::vector<std::uint64_t> lon_near_, lat_near_;
  std::vector<double> reach_;      // StepsOf: the lon reach at each step
  std::vector<double> lat_reach_;  // StepsOf: the lat reach (ws.reach_d) at each step
  std::vector<LonNearKey> lon_near_key_;
  std::vector<std::uint64_t> lat_near_stamp_;
  // CandidateCollides' narrower lateral test (the unscaled margins only): per lat slot and
  // step, the cars of lat_near_ whose boxes can reach the ego's along d (HitsAt's d-axis
  // separation with the ego heading bounded by its d' alone and the car's length bounded by
  // its length plus tight_margin_), and the traffic it was computed for (0: to compute). It
  // applies with a lon slot whose steps all give margins of at most tight_margin_
  // (lon_tight_ok_, computed with its lon_near_).
  std::vector<std::uint64_t> lat_tight_, lat_tight_stamp_, lon_tight_stamp_;
  std::vector<char> lon_tight_ok_;
  // Per car and step ([c * (n_steps + 1) + j]), the car's extent along d that the test bounds,
  // for traffic tight_stamp_; tight_margin_ is set with it.
  std::vector<double> car_extent_d_;
  std::vector<double> tight_reach_;  // per step, the ego's bound (scratch)
  std::uint64_t tight_stamp_ = 0;
  double tight_margin_ = 0;
  // The lateral reach masks CandidateCollides uses for lon slot i and lat slot k: lat_tight_'s
  // row, or lat_near_'s when the narrower test does not apply.
  const std::uint64_t* TightLatNear(int i, int k);
  // CandidateCollides: per lon slot, the last step and car hit, and the traffic they were for.
  struct LastHit {
    std::uint64_t stamp = 0;
    int step = 0, car = 0;
  };
  std::vector<LastHit> last_hit_;      // two per lon slot, the latest first
  std::vector<LastHit> lat_last_hit_;  // one per lat slot
  // BareContact per candidate, valid where bare_epoch_[c] is epoch_ for the traffic and
  // candidates it was measured for.
  std::vector<int> bare_hit_;
  std::vector<std::uint32_t> bare_epoch_;
  std::uint32_t epoch_ = 1;
  std::uint64_t bare_traffic_ = 0, bare_candidates_ = 0;
};

// The margin FirstCollision gives a car is at most `widest` (inside <= 1, step_v <=
// step_v_max; rounded products and sums are monotone), so a car farther along s than
// ws.reach_s_base + widest fails its reach test anyway. Only with non-negative factors.
inline double CollisionChecker::Widest(double s_d, double margin_scale, double behind_scale) const {
  const bool bounded = margin_scale >= 0 && behind_scale >= 0 && cfg_.check.margin_s >= 0 &&
                       cfg_.check.headway_min >= 0 && cfg_.check.margin_behind >= 0 &&
                       cfg_.check.behind_time >= 0;
  if (!bounded) return std::numeric_limits<double>::infinity();
  return std::max(
      {margin_scale * std::max(cfg_.check.margin_s, cfg_.check.headway_min * std::max(s_d, 0.0)),
       behind_scale * (cfg_.check.margin_behind +
                       cfg_.check.behind_time * std::max(0.0, ws_.step_v_max - s_d)),
       margin_scale * cfg_.check.margin_s});
}

inline double CollisionChecker::ReachS(double s_d, double margin_scale, double behind_scale) const {
  return ws_.reach_s_base + Widest(s_d, margin_scale, behind_scale);
}

// FirstCollision's ego at one step.
struct CollisionChecker::StepEgo {
  traj::OrientedBox box;
  double s_d = 0;  // the state's s'
  double vs, vd;   // the heading's velocity (s', d') with s' at least 0.5
  double reach_s;  // ReachS
  // The unit heading, from (vs, vd) when a car first comes near enough to need it (most steps
  // have none: the square root is saved there).
  mutable double dir_s = 0, dir_d = 0;
  mutable bool has_dir = false;
  void Direction() const {
    if (has_dir) return;
    const double inv = 1.0 / std::sqrt(vs * vs + vd * vd);
    dir_s = vs * inv;
    dir_d = vd * inv;
    has_dir = true;
  }
};

inline CollisionChecker::StepEgo CollisionChecker::EgoAt(const traj::FrenetState& st,
                                                         double margin_scale,
                                                         double behind_scale) const {
  return {
      traj::OrientedBox{st.s, st.d, 0.0, 0.5 * cfg_.check.ego_length, 0.5 * cfg_.check.ego_width},
      st.s_d, std::max(st.s_d, 0.5), st.d_d, ReachS(st.s_d, margin_scale, behind_scale)};
}

inline bool CollisionChecker::HitsAt(const StepEgo& e, int j, int c, double margin_scale,
                                     double behind_scale) const {
  const traj::OrientedBox& ego = e.box;
  const int at = c * (ws_.n_steps + 1) + j;
  const double cs = ws_.step_s[at], cd = ws_.step_d[at];
  if (std::abs(cd - ego.cy) > ws_.reach_d + ws_.car_reach_d[c] ||
      std::abs(cs - ego.cx) > e.reach_s + ws_.car_reach_s[c]) {
    return false;
  }
  // A car behind in another lane than the start's is one the ego would cut in front of:
  // the simulator's traffic brakes hard when its gap falls below 10-20 m, so entering
  // its lane needs more room than a mere non-overlap (the seeds' rule: 15 m behind).
  // A car ahead needs room to brake behind it: headway_min at the ego's speed.
  const bool behind_other_lane =
      cs < ego.cx && std::abs(ws_.car_d0[c] - ws_.start.d) > 0.5 * cfg_.road.lane_width;
  // A car behind in another lane needs room to react and brake when it closes in.
  const double closing = std::max(0.0, ws_.step_v[at] - e.s_d);
  // The headway to a car ahead is kept in full while the ego is in its lane and tapers
  // to margin_s as the ego moves out of it (pulling out from behind a car is how a
  // lane change starts).
  const double sep_d = ws_.car_sep_d[c];  // the two half widths: centres this close touch
  const double inside =
      std::clamp((sep_d - std::abs(cd - ego.cy)) / (sep_d - kFollowerLateral), 0.0, 1.0);
  // An oncoming car (moving the other way: a two-way road's other lane) is passed, not
  // followed: no headway.
  double margin = margin_scale * cfg_.check.margin_s;
  if (cs >= ego.cx && ws_.step_v[at] >= 0) {
    margin = margin_scale * std::max(cfg_.check.margin_s, inside * cfg_.check.headway_min * e.s_d);
  } else if (behind_other_lane) {  // (only ever behind: cs < ego.cx)
    margin = behind_scale * (cfg_.check.margin_behind + cfg_.check.behind_time * closing);
  }
  if (std::abs(cs - ego.cx) > ws_.reach_s_base + ws_.car_reach_s[c] + margin ||
      std::abs(cd - ego.cy) > ws_.reach_d + ws_.car_reach_d[c]) {
    return false;
  }
  const double cu = ws_.step_dir_s[at], cw = ws_.step_dir_d[at];  // the car's unit heading
  e.Direction();
  const traj::OrientedBox car{cs, cd, 0.0, ws_.car_hl[c] + margin,
                              ws_.car_hw[c] + margin_scale * cfg_.check.margin_d};
  // The d axis separates the boxes when their extents along it do not reach (most cars
  // alongside, in the next lane): a gap over 1 mm is one Overlap finds on its axes too.
  const double reach_d = ego.half_length * std::abs(e.dir_d) + ego.half_width * e.dir_s +
                         car.half_length * std::abs(cw) + car.half_width * cu;
  if (std::abs(cd - ego.cy) > reach_d + 1e-3) return false;
  return traj::Overlap(ego, e.dir_s, e.dir_d, car, cu, cw);
}

template <typename StateAt>
int CollisionChecker::FirstCarHit(const StateAt& state_at, int j, std::uint64_t cars,
                                  double margin_scale, double behind_scale) const {
  const std::uint64_t near = state_at.Near(j) & cars;
  if (near == 0) return -1;  // no car within reach at this step: nothing to test
  const StepEgo ego = EgoAt(state_at(j * ws_.collision_step), margin_scale, behind_scale);
  for (std::uint64_t m = near; m != 0; m &= m - 1) {
    const int c = std::countr_zero(m);
    if (HitsAt(ego, j, c, margin_scale, behind_scale)) return c;
  }
  return -1;
}

template <typename StateAt>
int CollisionChecker::FirstCollision(StateAt state_at, double margin_scale, double behind_scale,
                                     int* car_hit, bool ghosts, int from, int to) const {
  const int num_cars = ghosts ? ws_.num_check_cars : ws_.ctx.num_cars;
  const std::uint64_t cars = CarMask(ghosts);
  const int n_steps = ws_.n_steps;
  const int last = to > 0 ? std::min(to, n_steps) : n_steps;
  for (int j = std::max(from, 1); j <= last; ++j) {
    // Cars in index order either way: the first one hit is the same.
    int hit = -1;
    if constexpr (requires { state_at.Near(j); }) {
      hit = FirstCarHit(state_at, j, cars, margin_scale, behind_scale);
    } else {
      const StepEgo ego = EgoAt(state_at(j * ws_.collision_step), margin_scale, behind_scale);
      for (int c = 0; c < num_cars && hit < 0; ++c) {
        if (HitsAt(ego, j, c, margin_scale, behind_scale)) hit = c;
      }
    }
    if (hit >= 0) {
      if (car_hit != nullptr) *car_hit = hit;
      return j;
    }
  }
  return n_steps + 1;
}

}  // namespace frenetic::plan::search

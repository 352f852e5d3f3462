// The buffers and state the search planner's stages share, in one plain struct: sized once at
// construction (struct of arrays, capacities from the settings), then only overwritten, so a
// cycle does not allocate after warm-up. Each stage takes it by reference; the comments say
// which stage writes what.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "frenetic/cost/cost_term.h"
#include "frenetic/plan/search_planner.h"
#include "frenetic/traj/frenet.h"
#include "plan/search/lattice.h"
#include "plan/search/settings.h"

namespace frenetic::plan::search {

// Milliseconds since the start of the cycle, on the planner's clock: what the stages compare
// with their share of budget_ms.
class CycleClock {
 public:
  explicit CycleClock(PlannerClock now_ms) : now_ms_(std::move(now_ms)) {}
  void Start() { t0_ = now_ms_(); }
  double Elapsed() const { return now_ms_() - t0_; }
  // The search's deadline: the checks' share (kChecksShare) of budget_ms spent. Scoring, the
  // checks, least harm and the selection all stop there (tested every few candidates), so that
  // the output always fits in the budget.
  static constexpr double kChecksShare = 0.85;
  bool ChecksOver(double budget_ms) const { return Elapsed() > kChecksShare * budget_ms; }

 private:
  PlannerClock now_ms_;
  double t0_ = 0;  // ms, now_ms_ at the start of the cycle
};

// Swerves into goal regions a cycle offers at most (Lattice::AddSwerves), besides the one under
// way.
inline constexpr int kMaxSwerves = 216;
// Passes a cycle offers at most (Lattice::AddPasses), the one under way included.
inline constexpr int kMaxPasses = 17;

struct Workspace {
  explicit Workspace(const Settings& cfg);

  // The ticks [1, CheckTicks(c)] and collision steps [1, CheckSteps(c)] candidate c is checked
  // over: the whole horizon (n_ticks, n_steps); for a swerve, up to its end (a swerve is paired
  // only with the lon trajectories that put it in its goal region there, SwerveEndsInside): the
  // run ends at its goal, and what would follow leaves the lane turned.
  int CheckTicks(int c) const;
  // Whether lon trajectory i with swerve j (lat[j].swerve()) is inside the swerve's goal region
  // at the swerve's end: time, s, d, speed and heading.
  bool SwerveEndsInside(int i, int j) const;
  int CheckSteps(int c) const {
    const int t = CheckTicks(c);
    return t == n_ticks ? n_steps : std::max(1, t / collision_step);
  }

  // The candidate c's trajectory (an index into cand_lon / cand_lat).
  traj::FrenetTrajectory Candidate(int c) const {
    return {lon[cand_lon[c]].traj, lat[cand_lat[c]].traj};
  }
  // Samples a trajectory at every tick of the check horizon, t0 + i ticks (s), into tk_*
  // [1, n_ticks].
  void FillTicks(const traj::FrenetTrajectory& tr, double t0 = 0);
  // FillTicks' s, s' and d (and d'), what LimitChecker::Violation reads, with the same values;
  // the other rows are left as they were.
  void FillTicksForLimits(const traj::FrenetTrajectory& tr);
  // Makes candidate c the cycle's winner.
  void TakeWinner(int c) {
    winner_index = c;
    winner = Candidate(c);
    winner_lon = cand_lon[c];
    winner_lat = cand_lat[c];
    winner_cost = cand_cost[c];
  }

  // Sizes, fixed at construction.
  int n_samples = 0;       // scoring samples, score.dt apart over score.horizon
  int n_ticks = 0;         // check ticks (kTickSeconds) over check.horizon, >= output_points
  int collision_step = 5;  // ticks between collision-check steps
  int n_steps = 0;         // collision-check steps over the check horizon

  // Start of the cycle (Plan): the start state, the number of kept points, their duration (s).
  traj::FrenetState start;
  int kept = 0;
  double t_keep = 0;
  // Ticks the simulator may have read the ego astride a lane line, up to the start state (kept
  // points included): where the hard check's lane-line timer starts.
  int straddle_at_start = 0;

  // Context (BuildContext): the lanes and the traffic the costs read.
  double lane_nominal[cost::kMaxLanes] = {};  // the road's lane centres (uniform: fixed), m
  double lane_center[cost::kMaxLanes] = {};   // this cycle's (moved off the lane lines), m
  bool lane_exists[cost::kMaxLanes] = {};     // the lane is there at the start's s
  bool lane_oncoming[cost::kMaxLanes] = {};   // a two-way road's oncoming lane (Road::Oncoming)
  // The road's edges at the start (the lateral moves' range), m, and for the off-road check on
  // a road that is not uniform, its edges over the stretch ahead: edge_lo / edge_hi[b] are the
  // largest left and the smallest right edge over s in edge_s0 + [b, b + 1] * kEdgeBin (NaN
  // where no lane exists), from kEdgeBehind m behind the start to kEdgeAhead m past the
  // farthest the ego can get within the horizons.
  double road_left = 0, road_right = 0;
  static constexpr double kEdgeBin = 2.0, kEdgeBehind = 10.0, kEdgeAhead = 20.0;  // m
  double edge_s0 = 0;
  std::vector<double> edge_lo, edge_hi;
  double edge_widest = 0;  // m: the largest |edge| of the table where a lane exists
  // The line's largest |kappa| (1/m) over each kEdgeBin m from kappa_s0 (the edges' reach;
  // filled only with Settings::curve_prefilter), and max_abs_d, the farthest across (m) that a
  // candidate passing the limit checks may be (the speed prefilter's |d|max, BuildContext; not
  // the lane borders at the start: a lane that widens ahead, a pass on the oncoming lane or an
  // overshoot goes past them): the lattice's curve prefilter.
  double kappa_s0 = 0;
  std::vector<double> abs_kappa;
  // The same bins' smallest and largest signed kappa (1/m, left positive), from the same three
  // reads: the limit checks' curve test of each candidate (LimitChecker::CurveExcess).
  std::vector<double> kappa_lo, kappa_hi;
  // The largest of abs_kappa (1/m), a bin whose reads were not finite counting as 1: the curve
  // test's bound of what any candidate can meet (LimitChecker::CurveExcess).
  double kappa_abs_max = 0;
  // The lattice's speed prefilter (Lattice::TooFastForTheVehicle): the share of s' that is at
  // least the XY speed anywhere within the road up to speed_reach m along s from the start (0:
  // none is known), from the line's largest |kappa| there.
  double speed_share = 0, speed_reach = 0;
  double max_abs_d = 0;
  cost::CostContext ctx;
  // The goals of this cycle (Telemetry::goals), times relative to the start state.
  cost::GoalRegion goals[cost::kMaxGoalRegions];
  int num_goals = 0;
  // Cars the hard checks test against: ctx.num_cars real ones, then the predictor's lane-change
  // ghosts (a hypothesis the plan must survive, not traffic the costs should weigh).
  int num_check_cars = 0;
  // Traffic of the cycle (context index c): predicted s, d, speed at the scoring samples
  // ([c * n_samples + k]), where it is at the start instant, its predictor index, and its
  // predicted s, d, speed and lateral speed at the collision-check steps ([c * (n_steps + 1) +
  // j], t_keep + j * collision_step ticks), and its unit heading (s', d') there, with s' at
  // least 0.5.
  std::vector<double> car_s, car_d, car_v, car_s0, car_d0;
  std::vector<int> car_index;
  // Per car: its half length and half width (m), and the ego's and its together (the
  // separation of two aligned boxes' centres at contact: 0.5 ego_length + car_hl...).
  std::vector<double> car_hl, car_hw, car_sep_s, car_sep_d;
  // Settings::Check::side_clear, set once: least harm's clearance counts a separation across the
  // road (bare boxes) of at least this as clear (SidePart in least_harm.h).
  double side_clear = std::numeric_limits<double>::infinity();
  // FirstCollision's broad reach along s (before margins) and across (m): 8 and 5 for the
  // Udacity footprints, more with a larger ego; per car, the more its own size adds (0 for a
  // car no larger than the Udacity footprint).
  double reach_s_base = 8, reach_d = 5;
  std::vector<double> car_reach_s, car_reach_d;
  std::vector<double> step_s, step_d, step_v, step_vd, step_dir_s, step_dir_d;
  double step_v_max = std::numeric_limits<double>::infinity();  // >= every step_v (inf: unknown)
  std::uint64_t traffic_stamp = 0;     // changes whenever the traffic arrays above are rewritten
  std::uint64_t candidate_stamp = 0;   // changes whenever the candidates are generated anew
  std::vector<double> prev_s, prev_d;  // the previous winner at the scoring samples

  // Bundles (Lattice): the 1-D trajectories, sampled at the scoring samples ([i * n_samples +
  // k]), with their broad-phase masks (cost::CostInput::near_lat, near_lon; 2 * n_samples words
  // each), and the candidates: every compatible lon x lat pair.
  std::vector<LonTraj> lon;
  std::vector<LatTraj> lat;
  std::vector<double> lon_s, lon_sd, lon_sdd, lat_d, lat_dd, lat_ddd;
  std::vector<std::uint64_t> lat_near, lon_near;
  // Whether lon bundle i's masks are filled: the scorer fills them when a candidate of the
  // bundle is first costed in full (most bundles' candidates never are).
  std::vector<char> lon_near_have;
  std::vector<int> cand_lon, cand_lat;

  // Scores (Scorer): the weighted cost per candidate and the candidates by rank; order[0,
  // sorted) is in cost order (Scorer::SortUpTo).
  std::vector<double> cand_cost;
  std::vector<int> order;
  int sorted = 0;

  // One trajectory sampled at every tick of the check horizon, [1, n_ticks] (FillTicks,
  // the fallback); what the hard checks read and what Output stores.
  std::vector<double> tk_s, tk_sd, tk_sdd, tk_d, tk_dd, tk_ddd;

  // The cycle's winner (TakeWinner; Refiner may replace the trajectory).
  int winner_index = -1, winner_lon = -1, winner_lat = -1;
  double winner_cost = 0;
  traj::FrenetTrajectory winner;

  // The last decision, kept across cycles: the previous winner (consistency cost, the lateral
  // move under way, the fallback ContinuePrevious) and the lane-change timer.
  bool have_prev_traj = false;
  // The last search's checks found no candidate passing (a box-in): the lattice widens its
  // lateral offsets (Settings::Lateral::escape_offsets), and the selection and least harm take
  // it as a hint for their order of work.
  bool none_passed_last = false;
  traj::FrenetTrajectory prev_traj;
  double prev_elapsed = 0;  // s: the current start's time on prev_traj
  double prev_base = 0;     // s: the stored plan start's time on prev_traj (see ContinuePrevious)
  int prev_target_lane = -1, lane_before_change = -1;
  int prev_lat_lane = -1;  // lane and end offset (m) of the previous winner's lateral move
  double prev_lat_offset = 0;
  int prev_swerve_goal = -1;  // the goal region the previous winner swerved into, or -1
  double time_since_change = 1e9;
};

}  // namespace frenetic::plan::search

// The closed loop's rescue: when the path the planner sends would hit a predicted car within a
// few seconds, or misses every goal region while the last of them closes or is passed, a search
// of the vehicle's own KS inputs looks for a way that does not, and the ego drives that way's
// first input instead.
//
// The lattice planner's candidates are a few thousand smooth Frenet manoeuvres; in recorded
// highway traffic the only way through a box-in is sometimes none of them: full acceleration
// from the first step, a lateral move of a metre and a half in a second, then a hold at the
// lane's edge while the cars of two lanes pass 0.2 m away. The rescue searches that space
// directly: breadth first over the KS model's states, step by step (the scenario's dt; at a
// shorter dt a layer of the search holds its input for as many steps as make about 0.1 s, every
// step checked), at each step five accelerations (from -a_max to the limit at the speed) and
// five steering rates, all within `limit_share` of the vehicle's limits and within its friction
// circle; a state is kept
// while the ego's box (grown by `ego_margin`) is clear of every predicted car's box at that step
// and lies between the road's edges (the planner's road, its ends closed; where a lane begins or
// ends under the box, or where the outline runs inside the edges, also inside the lanelets' own
// outline: SetRoadArea). It uses what the
// planner was told and nothing else: the telemetry's futures of the cars (recorded
// predictions), else each car carried on along the road at its speed, a car moving across it
// faster than `lateral_threshold` into the next lane's centre as the planner's predictor has it
// (then straight on). States share grid cells; above
// `max_states` valid states a step keeps a spread over coarse strata of position and speed.
//
// The way kept is the first found to meet a goal region (in its window, with its speed and
// heading), else one that lasts the whole horizon, the nearest a goal region at its end (then
// the farthest along the road); with none of either, no way (the planner's least harm knows
// the goals). The search steps the KS model by Simpson's rule; the ego drives SimulateKs.
// Each later cycle the rest of the way is checked again with SimulateKs from the ego's state
// against the new predictions and kept while it stays clear to its end and is at least half
// the horizon long (a way to a goal: while it still meets it); otherwise a new search runs. The
// way only stands in for the planner's path while that path still hits a car or misses the goal.
//
// For a goal the planner's path misses (GoalAtRisk: every region either closes within the path
// or lies behind its end, or the planner's whole plan misses it too while it closes within
// `goal_steps` and the path ends outside it), only a way that meets a region will do, searched
// up to the windows' close (past `steps` with fewer states a step, as many in all); the search
// leaves out the states that can no longer meet one (window closed, region passed, or its start
// beyond reach at full acceleration), so a goal out of reach costs no search at all.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/reach_grid.h"
#include "frenetic/commonroad/road_area.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/cost/goal_region.h"
#include "frenetic/map/road.h"
#include "frenetic/plan/telemetry.h"
#include "frenetic/traj/box.h"

namespace frenetic::commonroad {

struct RescueOptions {
  // s searched ahead, in the scenario's steps (40 at the benchmark's usual 0.1 s; a file's
  // own step size, 0.04 s or 0.2 s, keeps the same seconds).
  double horizon = 4.0;
  // s a search for a way to a goal region the planner's path misses may run, when every
  // window closes within them (at least `horizon`): see Rescue::GoalAtRisk.
  double goal_horizon = 6.0;
  int max_states = 150;       // valid states kept per step (a spread when more)
  int retry_states = 300;     // when none is found, once more with this many (0: no retry)
  double limit_share = 0.97;  // of the vehicle's acceleration, steering and steering-rate limits
  double ego_margin = 0.05;   // m added to each side of the ego's box
  double car_length = 5.0;    // m, the footprint of a car whose row gives none
  double car_width = 2.0;
  // m/s: a car without a future moving across the road faster than this changes lanes: it moves
  // on across at that speed until it reaches the centre of the lane it moves into (the one
  // holding the point half a lane on), then straight on; <= 0: every car keeps its offset. The
  // planner's prediction.lateral_threshold, so that both predict the same lane changes.
  double lateral_threshold = 0.7;
};

// What the rescue made of one cycle's path (Rescue::Check, Rescue::Answer).
struct RescueStep {
  enum class Why { kNone, kHit, kGoal, kNoPath };
  Why why = Why::kNone;  // kNone: the path is left as it is; kNoPath: the planner sent none
                         // that passes its checks (Continue)
  int hit = 0;           // kHit: the step (1..steps) at which the path hits a predicted car
                         // or leaves the road
  // The way's input to drive instead of the path; none: the path is driven.
  std::optional<KsInput> input;
};

class Rescue {
 public:
  // `road` must outlive the rescue; dt: the scenario's step, s.
  Rescue(const map::Road& road, const VehicleParams& vehicle, double dt,
         const RescueOptions& options = {});

  // The path the planner sends for t (points every plan::kTickSeconds, the first one tick on)
  // checked on the cars of the last Predict (of the same t): a way (Next) when it hits a car,
  // else a way to a goal (Next, goal_only) when GoalAtRisk; else (or when no way to the goal is
  // found) the way is forgotten. `ego`: the vehicle's state; plan_misses: the planner's own plan
  // (its winner, continued as its goal term does) meets no goal region (GoalAtRisk).
  RescueStep Check(const plan::Telemetry& t, const std::vector<double>& x,
                   const std::vector<double>& y, const KsState& ego, bool plan_misses = false);
  // The closed loop's answer to the path the planner sent, after Predict(t) and Holds(ego,
  // t.goals) this cycle: when the way held and no candidate passed (none_passed: the planner
  // skipped its least harm), the way driven on (Continue); otherwise Check.
  RescueStep Answer(const plan::Telemetry& t, const std::vector<double>& x,
                    const std::vector<double>& y, const KsState& ego, bool none_passed,
                    bool plan_misses = false);
  // s: the paths given from now on have their first point this much later than a tick after
  // the ego's state (a step that is not a whole number of ticks: path_time.h). Default 0.
  void SetPathPhase(double phase) { path_phase_ = std::isfinite(phase) ? phase : 0.0; }

  // Whether the rest of the way from `ego` (one step driven since it was found or last kept)
  // is a way to a goal region that still meets it, clear to its end: one Next keeps whatever
  // the planner's path hits or misses. On the cars of the last Predict; the answer is kept
  // for Continue and Answer until the next Predict or change of the way. The closed loop asks
  // before the planner runs: when it holds, a cycle in which no candidate passes drives the
  // way (Continue) instead of the planner's least harm, which the way stands in for whenever
  // that path hits a car or misses the goal. (A way that only lasts does not hold: a least-harm
  // path toward the goal then still counts. Tried: 2 fewer derived highD problems solved with
  // either prediction; see docs/commonroad.md.)
  bool Holds(const KsState& ego, const std::vector<cost::GoalRegion>& goals);
  // The way's next input (why kNoPath) when the last Holds, since the last Predict, said it
  // holds; none (and the way forgotten) otherwise.
  RescueStep Continue();

  // The predicted boxes of the telemetry's cars at steps 1..goal_steps from its instant: a car's
  // future where it has one (a car to come appears at its start), else its row carried on along
  // the road at its speed and into the next lane as RescueOptions::lateral_threshold says (a car
  // with no speed lies along the road: its heading is unknown, as in the planner's prediction).
  // The boxes are laid out as the checks reach their steps, from t's futures: t must outlive the
  // calls up to the next Predict (the closed loop's telemetry of the cycle does).
  void Predict(const plan::Telemetry& t);

  // The first step (1..steps) at which a path of points every plan::kTickSeconds (the first one
  // tick from now) hits a predicted car, or, until it meets a region of `goals` (where the run
  // ends), leaves the road (OnRoad: the planner's lanes, which run on past the map's ends); 0
  // when neither within the steps it covers.
  int PathHit(const std::vector<double>& x, const std::vector<double>& y,
              const std::vector<cost::GoalRegion>& goals = {}) const;

  // The way's input for the next step from `ego`, when a way that lasts the whole horizon (or
  // meets a goal region of `goals`, the telemetry's) is found: the rest of the last way while
  // it is still clear to its end and at least half the horizon long, else a new search's.
  // nullopt when none does (the planner's path is driven then: its least harm knows the goals).
  // goal_only: only a way that meets a goal region (the planner's path misses a goal). When
  // every goal window closes within the horizon (GoalSteps), a way to a goal is searched for
  // first in either case, up to that step, with steps / GoalSteps times the states a step.
  // far (with goal_only): the goal is at risk only as the planner's plan is (GoalAtRisk's last
  // case); the search runs to FarGoalSteps, with fewer states a step past `steps`.
  std::optional<KsInput> Next(const KsState& ego, const std::vector<cost::GoalRegion>& goals,
                              bool goal_only = false, bool far = false);

  // The stratum of a search's state (its spread keeps states of every stratum, round-robin):
  // cells of 2 m x 2 m, 1 m/s of speed and 0.5 m/s of speed across the search's start heading
  // `heading0` (v sin(heading - heading0)), and the steering's sign. The speed across keeps a
  // state turning out of its lane apart from one going straight at the same place and speed (an
  // escape across lanes from a car closing from behind); at low speed the same turn moves little
  // across and shares its stratum. Was the heading's sign alone; see docs/commonroad.md ("The
  // rescue's strata") for what each cell size solved.
  static std::uint64_t Stratum(const KsState& q, double heading0);

  // The most (m) a state at s may move across the road toward +d (toward 1) or -d (-1) within
  // `time` s, with the vehicle's limits: an upper bound (its steering turned toward it at the
  // largest rate).
  double LateralReach(double s, const KsState& state, int toward, double time) const;

  // The way's centre points every plan::kTickSeconds from `ego` (the first one tick on): the
  // path sent in its place.
  void Points(const KsState& ego, std::vector<double>* x, std::vector<double>* y) const;

  // Whether a path (as PathHit's, one that neither hits a car nor leaves the road: Check asks
  // only then) meets no goal region of `goals` (in its window, with its speed and heading) while
  // every region's window closes within the path, or the path runs past the region's end, or
  // (plan_misses: the planner's plan beyond the path misses every region too) the window closes
  // within RescueOptions::goal_horizon and the path ends short of the region or beside it. The
  // path the planner sends is 2 s; a goal a car has to be passed for is lost long before its
  // window closes within that.
  bool GoalAtRisk(const std::vector<double>& x, const std::vector<double>& y,
                  const std::vector<cost::GoalRegion>& goals, bool plan_misses = false) const;

  // Forget the way (the planner's path is clear again).
  void Drop() {
    way_.clear();
    goal_way_ = false;
    held_ = false;
  }

  int searches() const { return searches_; }
  std::int64_t checked() const { return checked_; }

  // The lanelets' own outline (the verdict's road; must outlive the rescue), checked where a lane
  // of the road begins or ends within 5 m of the ego's box along the road. The road's lane
  // begins and ends at one station, while a lanelet's first or last edge may lie slanted across
  // the road: a box over the lane's first metres can be between the lane's borders and still
  // stick out of the lanelets (US-101's merging lanes). It is checked too wherever a segment of
  // the outline lies more than 5 cm inside the road's borders (found once, here): a sliver
  // between two lanelets that are not adjacent, which the solution checker counts as road
  // boundary (DEU_Muc-2: a lane change must cross where the lanes touch), or the wedge where a
  // ramp leaves the lane beside it. Elsewhere the borders are the lanelets'.
  // nullptr (the default): the road's borders only.
  void SetRoadArea(const RoadArea* area);

 private:
  struct Car {
    traj::OrientedBox box;
    double cos_h, sin_h, radius;
  };
  // Where a car's boxes come from (Predict): its future, its row standing (x, y; rel: the
  // road's heading there, which its box lies along), or its row carried on along the road (x,
  // y: its s and d; along: m/s along the road; rel: its heading less the road's; across: m/s
  // across it, toward d_target, where the move ends and the car turns to the road's heading;
  // 0: none).
  struct Source {
    enum Kind { kFuture, kStill, kAlong };
    Kind kind = kStill;
    const plan::CarFuture* future = nullptr;
    double x = 0, y = 0, along = 0, rel = 0;
    double across = 0, d_target = 0;
    double half_length = 0, half_width = 0, radius = 0;
  };
  // Stratum with the speed across given: the search has its children's sines and cosines at
  // hand (v sin(heading - heading0) = v (sin heading cos heading0 - cos heading sin heading0)).
  static std::uint64_t StratumAcross(const KsState& q, double across);
  static double SpeedAcross(double v, double cos_heading, double sin_heading, double cos_h0,
                            double sin_h0) {
    return v * (sin_heading * cos_h0 - cos_heading * sin_h0);
  }
  struct Node {
    KsState state;
    double s, d;  // in the road's frame (s: the Frenet hint of its children)
    int parent;  // index in the step before
    KsInput input;
    double across;  // m/s: the speed across the search's start heading (Stratum)
  };
  // Whether `s` at step k (1..goal_steps) is clear of the predicted cars and on the road; *s_out: its
  // s along the road (from the hint s_hint).
  bool Clear(const KsState& s, int k, double s_hint, map::FrenetPoint* at) const;
  // One walk along a path (PathHit's points and checks) for both of Check's questions: the step
  // it hits a car or leaves the road (0: none), and, up to there, whether a point meets a goal
  // region (the road past it is not checked), whether every speed is finite, and the last
  // point's time (s from now) and s.
  struct PathCheck {
    int hit = 0;
    bool met = false, judged = true;
    double t_end = 0, s_end = -std::numeric_limits<double>::infinity(), d_end = 0;
  };
  PathCheck Walk(const std::vector<double>& x, const std::vector<double>& y,
                 const std::vector<cost::GoalRegion>& goals) const;
  // GoalAtRisk of a walked path: kNear when every region closes within the path or lies behind
  // its end; kFar when some region is at risk only as the planner's plan is (its last case).
  enum class Risk { kNone, kNear, kFar };
  Risk AtRisk(const PathCheck& path, const std::vector<cost::GoalRegion>& goals,
              bool plan_misses) const;
  // The predicted cars at step k (1..goal_steps), laid out up to k on first use.
  const std::vector<Car>& CarsAt(int k) const;
  // The same for the cars alone, and for the road alone (the box, the margin's wider, between
  // the road's edges at both its ends; *at as Clear's).
  bool ClearOfCars(const KsState& s, int k) const;
  bool OnRoad(const KsState& s, double s_hint, map::FrenetPoint* at) const;
  // Whether the states `input` reaches from `from` at scenario steps k0 + 1 .. k0 + n - 1
  // (SimulateKs a step at a time) are all Clear: within a search layer that holds its input
  // for n steps. With goals: *met becomes the first j whose state meets one (GoalDistance 0),
  // and the steps after it are not looked at (true).
  bool ClearBetween(const KsState& from, const KsInput& input, int k0, int n, double s_hint,
                    const std::vector<cost::GoalRegion>* goals = nullptr, int* met = nullptr) const;
  // A way from `ego` (fe0: its point in the road's frame) that meets a goal region (the first
  // found), else one that lasts the whole horizon of `steps`, the nearest a goal region at its
  // end (then the farthest along the road), in way_ (empty when none), with at most max_states
  // (>= 1) states a step. goal_only: none unless it meets a goal region.
  void Search(const KsState& ego, const map::FrenetPoint& fe0,
              const std::vector<cost::GoalRegion>& goals, int max_states, int steps,
              bool goal_only = false);
  // Whether a state at (s, d) in the road's frame, t s from now, may still meet a goal region
  // within the horizon: one whose window is open at t or later, not passed, whose start lies
  // within reach at the vehicle's full acceleration before its window closes, and whose band
  // across the road lies within LateralReach.
  bool MayMeetGoal(double s, double d, const KsState& state, double t,
                   const std::vector<cost::GoalRegion>& goals, int steps) const;
  // The distance (s, d) of a state (speed v, heading) at t s from the nearest goal region whose
  // window holds t (0 inside it with its speed and heading, 1e-3 inside without), +inf when
  // none does.
  double GoalDistance(double s, double d, double v, double orientation, double t,
                      const std::vector<cost::GoalRegion>& goals) const;
  // The step (1..horizon - 1) by which every window of `goals` has closed; 0 when none are
  // given or one stays open to the horizon or beyond.
  int GoalSteps(const std::vector<cost::GoalRegion>& goals, int horizon) const;
  // The step (1..goal_steps) by which region g's window has closed (its slack added); 0 when it
  // stays open past goal_steps (or has no end).
  int ClosingStep(const cost::GoalRegion& g) const;
  // The step by which the window of every region not yet passed at s (along the road) has
  // closed, for a search to a goal at risk only as the planner's plan is; 0 when one stays
  // open past goal_steps.
  int FarGoalSteps(const std::vector<cost::GoalRegion>& goals, double s) const;
  // A state's distance (m, in s and d) from the nearest goal region whose window is open at the
  // horizon's end (any region when none is; 0 without regions).
  double GoalGap(const Node& n, const std::vector<cost::GoalRegion>& goals) const;
  // How many steps of way_ from its element `from` on stay clear from `ego`.
  // With goals: -1 unless the way's end meets one of them.
  int Lasts(const KsState& ego, const std::vector<cost::GoalRegion>* goals = nullptr,
            int from = 0);

  const map::Road& road_;
  const RoadArea* area_ = nullptr;
  // [s_lo, s_hi] along the line where a box is checked against the road area (SetRoadArea): every
  // lane's begin and end, and where the area's boundary runs inside the road's edges (a gap
  // between lanelets that are not adjacent, a wedge where a ramp leaves the lane beside it);
  // merged, disjoint and sorted.
  std::vector<std::pair<double, double>> area_stretches_;
  VehicleParams vehicle_;
  double dt_;
  RescueOptions options_;
  // The horizons in the scenario's steps (RescueOptions::horizon, goal_horizon).
  int steps_ = 40, goal_steps_ = 60;
  int sub_ = 1;            // scenario steps a search layer holds its input for (Search)
  double path_phase_ = 0;  // SetPathPhase
  double half_length_ = 0, half_width_ = 0;  // m, of the ego's box grown by ego_margin
  double ego_radius_ = 0;                     // m, its circumradius
  std::vector<Source> sources_;
  mutable std::vector<std::vector<Car>> cars_;  // [k - 1]: the predicted cars at step k
  mutable int ready_ = 0;                       // steps of cars_ laid out
  std::vector<KsInput> way_;
  bool goal_way_ = false;  // way_ ends in a goal region
  bool held_ = false;      // the last Holds' answer, until Predict or the way changes
  // Searches for a goal at risk only as the planner's plan is (Check): found no way in a row,
  // and cycles to wait before the next.
  int far_fails_ = 0, far_wait_ = 0;
  std::vector<std::vector<Node>> layers_;
  std::vector<std::pair<std::uint64_t, Node>> next_;
  KeyTable seen_;
  reach::SpreadScratch spread_;
  std::vector<std::pair<std::size_t, std::size_t>> rank_;
  int searches_ = 0;
  mutable std::int64_t checked_ = 0;
};

}  // namespace frenetic::commonroad

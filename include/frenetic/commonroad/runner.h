// Closed-loop planning through a CommonRoad scenario (`frenetic commonroad`): for each planning
// problem, the road is built from the lanelets (BuildRoad), the search planner plans at every time
// step from the ego's state, the ego follows the plan for one step as the benchmark's KS vehicle,
// and the other traffic follows its recording (non-reactive). The run's KS trajectory is then
// judged by the verdict (verdict.h), independently of the planner.
//
// Each step (dt, 0.1 s in the benchmark) the planner gets, as from a simulator: the ego's centre,
// orientation and speed; the rest of its last path (its 0.02 s points after the dt driven); the
// obstacles there at that step as sensor rows (centre, velocity, footprint); with
// --prediction recorded, each dynamic obstacle's recorded future (the benchmark's convention for
// "T" scenarios), else nothing beyond the present: the planner's own predictor then carries each
// car on at its velocity (along its lane, and across it to the next lane's centre), a car
// braking hard since the last step braking on for up to 2 s; and
// the goal states as regions of its road's Frenet frame. The ego then moves dt with the constant
// KS input (steering rate, acceleration) that best lands it on the planned state dt ahead
// (position, orientation, steering angle, speed: a few Gauss-Newton steps on SimulateKs, the
// inputs within the vehicle's limits), so the trajectory is a KS trajectory by construction.
// When the planned path would run into a predicted car, the ego drives the rescue's way instead
// (rescue.h; RunOptions::rescue), the KS input it found, exactly.
// The run ends at the first step that meets a goal state, after the last goal time window (or,
// for goals without one, the scenario's last recorded step), once the ego has driven past every
// goal region, at the first step its box overlaps an obstacle or leaves the road (the verdict's
// own checks: the problem is failed then), or after kMaxSeconds (in the scenario's steps).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/rescue.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/commonroad/verdict.h"
#include "frenetic/map/road.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/plan/telemetry.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

enum class PredictionMode { kRecorded, kConstantVelocity };
const char* ToString(PredictionMode mode);  // "recorded", "constant-velocity"
StatusOr<PredictionMode> ParsePredictionMode(std::string_view text);

// s: the longest run (3000 steps at 0.1 s; as long at any other step size).
inline constexpr double kMaxSeconds = 300.0;

struct ProblemRun;

// What the planner is given at one cycle of a run (RunOptions::on_cycle).
struct CycleInput {
  const PlanningProblem& problem;
  int step;
  const std::shared_ptr<const map::Road>& road;
  const plan::PlannerConfig& config;  // the problem's (its speed limit raised: CommonRoadConfig)
  const plan::Telemetry& telemetry;
  const KsState& ego;  // the vehicle's state the telemetry is read from
  // Whether the planner's least-harm choice is on (plan::Planner::set_least_harm): off while
  // the rescue holds a way to a goal (Rescue::Holds), which then stands in for it.
  bool least_harm = true;
};

struct RunOptions {
  PredictionMode prediction = PredictionMode::kRecorded;
  int vehicle_type = 2;  // CommonRoad vehicle 1, 2 or 3 (KS1..KS3)
  bool timing = true;    // false: planning times are recorded as 0 (byte-stable output)
  // When the planner's path would hit a predicted car or leave the road, drive a way the
  // rescue finds instead (rescue.h); its time counts as planning time.
  bool rescue = true;
  // States a step of a second rescue search when the first (RescueOptions::max_states) finds no
  // way; 0: none. Twice the first's by default; a narrow way may need thousands, and such a
  // search takes up to a second.
  int rescue_retry_states = RescueOptions().retry_states;
  // Called before each Plan() with its input (bench/ keeps cycles to time Plan() on); may be empty.
  std::function<void(const CycleInput&)> on_cycle;
  // Called after each Plan() with its input and result (the ego has not moved yet; the time it
  // takes is not planning time); may be empty.
  std::function<void(const CycleInput&, const plan::PlanResult&)> on_plan;
  // Called once a problem's run is complete (verdict included), also for one that never ran
  // (no road); may be empty.
  std::function<void(const PlanningProblem&, const ProblemRun&)> on_problem_end;
  Status Validate() const;
};

// One planning cycle of a run.
struct RunCycle {
  int step = 0;
  double plan_ms = 0;
  double rescue_ms = 0;  // the rescue's part of plan_ms (its checks and searches)
  int candidates = 0, checked = 0;
  plan::PlanStatus status = plan::PlanStatus::kOk;
  double tracking_error = 0;  // m: the ego's centre after the step from the planned one
  bool rescued = false;       // the ego drove the rescue's way, not the planner's path
};

struct ProblemRun {
  int problem_id = 0;
  Status road;  // why no road could be built (then nothing ran)
  int lanes = 0;
  double road_length = 0;  // m
  std::vector<int> route;  // lanelet ids
  std::vector<KsState> trajectory;
  std::vector<RunCycle> cycles;
  // "goal"; "time" (the last goal window ended); "goal_passed" (the ego drove past every goal
  // region: none can be met any more, the planner never reverses); "collision" or "off_road"
  // (the ego's box overlapped an obstacle or left the road: the problem is failed);
  // "infeasible_at_start" (nothing planned).
  std::string stop_reason;
  Verdict verdict;
  double computation_s = 0;  // planning time of the whole run (0 without timing)
};

struct ScenarioRun {
  std::string source, benchmark_id;
  std::vector<ProblemRun> problems;
};

// The planner configuration for CommonRoad: `base` (config/planner.yaml with
// config/commonroad.yaml on top, as the command loads it) with the ego's footprint, the
// vehicle's kinematic limits (vehicle.*, 15% inside the verdict's), its top speed
// (limits.max_speed_mph: 97% of its v_max; the lanes' traffic signs limit it further, as
// targets) and the wall-clock deadlines pinned (the prediction mode changes what the runner
// tells the planner, not its config).
inline constexpr const char* kCommonRoadConfig = "config/commonroad.yaml";  // in the source tree
StatusOr<plan::PlannerConfig> CommonRoadConfig(plan::PlannerConfig base, const VehicleParams& vehicle,
                                               PredictionMode prediction);

// The ego after one step of dt s toward a planned path (x, y: 0.02 s points from the step's
// start, the first one 0.02 s in, or `phase` s later than that): a constant KS input for the
// step, never backwards. A step that is not a whole number of ticks aims between two points.
// Feed-forward from the path at the step's end (the steering angle of its curvature, the rear
// axle's speed, the slip angle between the centre's path and the axis), corrected as a Stanley
// controller does (Hoffmann et al., "Autonomous Automobile Trajectory Tracking for Off-Road
// Driving", ACC 2007): the heading error and atan(k e / v) of the cross-track error e, both of
// the state the feed-forward input would reach; the speed corrected by the along-track error. A
// one-step fit of the position instead steers back and forth at speed (the position answers
// the steering rate only within the step).
KsState FollowPath(const KsState& ego, const std::vector<double>& x, const std::vector<double>& y,
                   double dt, const VehicleParams& vp, double phase = 0.0);

// Whether the planner's plan, as its goal term sees it (the winner continued past its end),
// meets no goal region: the term is 0 only when it passes through one in its window. False when
// the term is not configured (nothing known). What the rescue is told (Rescue::Answer).
bool PlanMissesGoal(const plan::PlanResult& res);

// Runs every planning problem of the scenario. `config` is used as given (see CommonRoadConfig).
// Never fails: a problem whose road cannot be built reports it in ProblemRun::road.
ScenarioRun RunScenario(const Scenario& scenario, const plan::PlannerConfig& config,
                        const RunOptions& options);

}  // namespace frenetic::commonroad

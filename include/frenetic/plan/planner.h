// The planner interface every planner implements (`search`, `baseline`), and what one planning
// cycle returns. Plan() never throws, never returns NaN and never returns fewer than
// kMinPathPoints points; after warm-up it does not allocate.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/road.h"
#include "frenetic/plan/telemetry.h"
#include "frenetic/status.h"

namespace frenetic::plan {

inline constexpr int kMinPathPoints = 50;
inline constexpr double kTickSeconds = 0.02;  // the simulator's physics step
// The whole ticks in `seconds`, at least one.
inline int TicksIn(double seconds) {
  return std::max(1, static_cast<int>(std::lround(seconds / kTickSeconds)));
}

enum class PlanStatus : std::uint8_t {
  kOk,             // the search found a feasible, collision-free trajectory
  kFallbackUsed,   // nothing passed; the keep-lane braking backup was sent
  kInvalidInput,   // telemetry was unusable (NaN, empty...); a safe path was still returned
  kOverBudget,     // the deadline cut the search short; the best result so far was sent
};
const char* ToString(PlanStatus status);

// Why a candidate was rejected (hard filters, counted per reason). kLaneLine: it would keep the
// ego astride a lane line past the simulator's 3 s timer.
enum class Reject : std::uint8_t {
  kSpeed, kAcceleration, kJerk, kOffRoad, kCollision, kLaneLine, kCount
};
const char* ToString(Reject reason);

// One weighted cost term of a candidate: name, weight, unweighted value.
struct CostTermValue {
  std::string name;
  double weight = 0;
  double value = 0;  // unweighted; contribution = weight * value
};

struct PlanSummary {
  int candidates_generated = 0;
  int candidates_scored = 0;
  int candidates_checked = 0;   // tested by the lazy collision / feasibility check
  int candidates_feasible = 0;  // passed it (the cheapest one that passed wins)
  std::array<int, static_cast<int>(Reject::kCount)> rejections{};
  std::vector<CostTermValue> winner_costs;  // per term, in config order (capacity kept)
  double winner_total_cost = 0;
  int winner_lane = -1;           // target lane of the winner (0 = left)
  double winner_end_speed = 0;    // m/s
  double winner_duration = 0;     // s
  int refine_iterations = 0;
  double refine_cost_before = 0;
  double refine_cost_after = 0;
  int points_kept = 0;            // from the previous path
  // The stage the per-cycle deadline (budget_ms) cut short, kNone when it did not: scoring (the
  // candidates not yet scored are left out), the lazy check or the least-harm choice (the best
  // found so far, else last cycle's plan or the braking fallback), refinement (skipped).
  enum class Stage : std::uint8_t { kNone, kScore, kCheck, kRefine };
  Stage deadline_stage = Stage::kNone;
  // Time per stage, milliseconds.
  double ms_prepare = 0, ms_generate = 0, ms_score = 0, ms_check = 0, ms_refine = 0,
         ms_output = 0, ms_total = 0;
};

const char* ToString(PlanSummary::Stage stage);  // "none", "score", "check", "refine"

struct PlanResult {
  PlanStatus status = PlanStatus::kOk;
  std::vector<double> x, y;  // map frame, m, one point per 0.02 s tick
  PlanSummary summary;
};

// Optional per-cycle explanation for reports (`frenetic drive --record`): the best candidates
// of the cycle with their costs and what became of them. Filling it may allocate; it is off
// unless a trace is attached.
struct CandidateTrace {
  int lane = -1;              // target lane
  double end_speed = 0;       // m/s
  double duration = 0;        // s
  double total_cost = 0;      // weighted sum
  bool checked = false;       // went through the feasibility / collision check
  bool winner = false;
  int reject = -1;            // static_cast<int>(Reject) when checked and rejected, else -1
  int reject_car = -1;        // collision rejections: the other car's sensor_fusion id...
  double reject_time = 0;     // ...and when the (margin-inflated) boxes would first meet, s
  std::vector<double> x, y;   // the candidate's path in the map frame, coarsely sampled (~0.25 s)
  std::vector<CostTermValue> costs;  // per term, config order
};
struct CycleTrace {
  std::vector<CandidateTrace> candidates;  // best first
};

class Planner {
 public:
  virtual ~Planner() = default;
  // One planning cycle. The returned reference stays valid until the next call.
  virtual const PlanResult& Plan(const Telemetry& telemetry) = 0;
  // Forget all state (a new episode).
  virtual void Reset() = 0;
  virtual std::string_view name() const = 0;
  // Attach (or detach with nullptr) a trace the next Plan() calls fill with up to
  // `max_candidates` candidates. Planners without candidates leave it empty.
  virtual void set_trace(CycleTrace* trace, int max_candidates) {
    (void)trace;
    (void)max_candidates;
  }
  // Whether a cycle in which no candidate passes every check takes the least harmful feasible
  // one (on, the default) or the cheap fallback path at once, with status kFallbackUsed (off:
  // a caller that holds a way of its own to drive then, as the CommonRoad runner's rescue
  // does). Planners without a least-harm choice ignore it.
  virtual void set_least_harm(bool on) { (void)on; }
};

class PlannerConfig;  // plan/planner_config.h

// Names accepted by MakePlanner: "search", "baseline".
std::vector<std::string> PlannerNames();

// Builds the named planner on a road with a validated configuration. The `search` planner reads
// the road's lanes (their number, borders, ends and speed limits); `baseline` (the seeds'
// Udacity planner) reads only its line and the configured road.lane_width / road.num_lanes.
StatusOr<std::unique_ptr<Planner>> MakePlanner(std::string_view name, const PlannerConfig& config,
                                               std::shared_ptr<const map::Road> road);
// The same on the configured uniform road (road.num_lanes lanes of road.lane_width from d = 0)
// along `line`: the Udacity layout.
StatusOr<std::unique_ptr<Planner>> MakePlanner(std::string_view name, const PlannerConfig& config,
                                               std::shared_ptr<const map::ReferenceLine> line);
// That uniform road.
std::shared_ptr<const map::Road> ConfiguredRoad(const PlannerConfig& config,
                                                std::shared_ptr<const map::ReferenceLine> line);

}  // namespace frenetic::plan

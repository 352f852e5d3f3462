// What `frenetic commonroad` keeps of each scenario file's run: everything its output needs and
// nothing more (no trajectories), so the output is made from reports alone, whichever process ran
// the file. Per problem: the JSON object and the text lines of the results, and how ours compares
// with the recorded human driver's trajectory when a solution file gives one.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/verdict.h"
#include "frenetic/commonroad/way_through.h"
#include "frenetic/status.h"

namespace frenetic::apps::commonroad_cli {

namespace cr = ::frenetic::commonroad;

// A problem's reference: the trajectory a CommonRoad solution file gives for it (in the highD set,
// the recorded human driver's), judged and costed as ours is, over its own states.
struct ReferenceReport {
  std::string file;           // the solution file
  int vehicle_type = 1;       // the file's KS<type>: the costs and the verdict use it
  std::string cost_function;  // the file's cost id (e.g. TR2); not evaluated
  int first_step = 0, last_step = 0, states = 0;
  std::map<std::string, double> costs;  // "WX1", "JB1" (commonroad::EvaluateCost)
  std::optional<int> goal_step;         // of the first state meeting a goal state
  // The distance its positions move over the distance its velocities give at the scenario's dt
  // (trapezoidal); 1 for a consistent trajectory, ~2 for the highD recordings (sampled every
  // 0.2 s, labelled 0.1 s). 0 when it does not move.
  double distance_ratio = 0;
  // The verdict in one field: "solved", or "failed: " and its failure kinds in the verdict's
  // order ("failed: start, dynamics").
  std::string verdict;
};

struct ProblemReport {
  int problem_id = 0;
  std::string road_error;  // why no road could be built ("" when one was; then nothing ran)
  cr::Verdict verdict;
  std::string stop;        // ProblemRun::stop_reason
  int initial_step = 0;    // the problem's initial time step
  int lanes = 0;
  double road_length_m = 0;
  std::vector<int> route;  // lanelet ids
  std::vector<double> plan_ms;  // per cycle (0 without timing)
  std::vector<double> rescue_ms;  // per cycle, the rescue's part of plan_ms
  double candidates = 0;        // summed over the cycles
  int not_ok_cycles = 0;        // cycles whose plan status was not kOk
  int rescued_cycles = 0;       // cycles that drove the rescue's way (rescue.h)
  double tracking_error_max_m = 0;
  double computation_s = 0;
  std::map<std::string, double> costs;  // "WX1", "JB1" of the trajectory, when it has states
  std::optional<ReferenceReport> reference;
  // --way-through: for a problem left unsolved (not infeasible at start), whether the search of
  // way_through.h found a way through its traffic.
  std::optional<cr::WayThrough> way_through;
};

struct FileReport {
  std::string path;
  std::string error;  // the file could not be read (nothing below is set)
  std::string benchmark_id;
  cr::Vec2 origin;    // the scenario's local frame (Scenario::origin)
  double dt = 0.1;    // s per time step
  std::vector<ProblemReport> problems;
  std::string solution_file;   // written by --solution-dir
  std::string solution_error;  // why it could not be written
  std::string record_error;    // why a --record record could not be written
};

// The largest of the values; 0 for none.
double Max(const std::vector<double>& values);

// Per-cycle times (ms) as {"p50", "p99", "max"}: Percentile's nearest ranks and the largest.
nlohmann::json TimesJson(const std::vector<double>& ms);

// How a problem with a reference compares. Ours reaches the goal when its verdict says solved;
// the reference when one of its states meets a goal state (its verdict is not asked: recorded
// trajectories fail the start and dynamics checks for reasons of the recording, see
// docs/commonroad.md). A problem infeasible at start is not compared.
enum class Outcome { kInfeasibleAtStart, kBothReachGoal, kOnlyOurs, kOnlyReference, kNeither };
Outcome CompareOutcome(const ProblemReport& p);  // p.reference must be set
// "infeasible_at_start", "both_reach_goal", "only_ours", "only_human", "neither".
const char* ToString(Outcome outcome);
// When both reach the goal and both have the cost `id` ("WX1", "JB1"): whether ours is lower.
std::optional<bool> OursCheaper(const ProblemReport& p, const std::string& id);

// Steps from the first state to the goal step (none without one), and the same in seconds.
std::optional<int> StepsToGoal(int first_step, const std::optional<int>& goal_step);
double Seconds(int steps, double dt);

// A problem's object in the JSON output; `dt` (s per step) gives the times to the goal.
nlohmann::json ProblemJson(const ProblemReport& p, double dt);
// A file's object in the JSON output's "scenarios".
nlohmann::json FileJson(const FileReport& f);
// A file's results as text: two lines per problem (the run, then its verdict), a third with the
// reference when there is one, or the path and why it could not be read.
std::string FileText(const FileReport& f);

}  // namespace frenetic::apps::commonroad_cli

// The summary of `frenetic commonroad` over every file's report (commonroad_report.h): overall and
// per family of scenarios, problems infeasible at start counted apart everywhere, and how ours
// compares with the reference trajectories when there are any.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commonroad_report.h"

namespace frenetic::apps::commonroad_cli {

// The family of a benchmark id: the country code and the map's name, the part before the first
// '-' ("USA_US101-15_2_T-1" -> "USA_US101", "ZAM_Zip-1_16_T-1" -> "ZAM_Zip"), with the map's
// trailing digits dropped when they follow a lower-case letter (a recording site's number:
// "DEU_LocationALower26-1_261504_T-1579" -> "DEU_LocationALower") and kept after a capital (a
// road's number: "USA_US101", "DEU_A9", "DEU_B471").
std::string Family(std::string_view benchmark_id);

// Why an unsolved problem failed, in one word: "road" when no road was built, else the kind of
// its earliest failure other than the goal (by step; at the same step, the verdict's order of
// kinds), else "goal" (a goal miss is judged at the trajectory's last state, where a run that
// collided or left the road ended).
std::string FirstFailure(const ProblemReport& p);

// What the summary says besides the reports: the run's settings.
struct SummarySettings {
  std::string prediction;  // "recorded", "constant-velocity"
  int vehicle_type = 2;
};

// A collision counts as with a car new in the scene when the car came into it at most this many
// seconds before (Counts::collisions_entering).
inline constexpr double kEnteringSeconds = 1.0;

// The counts of a set of problems (one family, or all).
struct Counts {
  int problems = 0;
  int infeasible_at_start = 0;  // apart: neither solved nor unsolved
  int solved = 0;               // of the problems - infeasible_at_start others
  std::map<std::string, int> unsolved;  // by FirstFailure: sums to the unsolved problems
  // Of unsolved["collision"]: the car hit came into the scene (a recording's view) at most
  // kEnteringSeconds before, after the run's start (Failure::entered_s).
  int collisions_entering = 0;
  std::vector<double> plan_ms;          // every cycle's planning time
  std::vector<double> rescue_ms;        // every cycle's rescue time (part of plan_ms)
};

// Ours against the references (ReferenceReport), over the problems that have one.
struct Comparison {
  int solution_files = 0;        // loaded (paired or not)
  int with_reference = 0;        // problems with a reference trajectory
  int infeasible_at_start = 0;   // of those: not compared
  int both_reach_goal = 0;       // Outcome::kBothReachGoal
  int ours_cheaper_wx1 = 0;      // of those: ours strictly lower in WX1
  int ours_cheaper_jb1 = 0;      // ... in JB1 (the time to the goal)
  int only_ours = 0, only_reference = 0, neither = 0;
  std::vector<std::string> unpaired;  // solution files whose scenario was not among the paths
};

struct Summary {
  Counts all;
  std::map<std::string, Counts> families;  // by Family()
  int unreadable_files = 0;
  // Per failure kind (and "road" for a problem without a road): the unsolved problems with a
  // failure of that kind (a problem counts under each of its kinds).
  std::map<std::string, int> failures;
  double candidates = 0;  // summed over every cycle
  Comparison comparison;
  // --way-through: the unsolved problems searched, and of those the ones with a way found; the
  // ones with none found where no step was capped (WayThrough::exhaustive).
  int way_searched = 0, way_found = 0, way_none_exhaustive = 0;
  int way_to_goal = 0;  // of those searched, the ones where a state met a goal (goal_step)
};

// `solution_files`: scenario id -> path of each loaded solution file (gives the unpaired ones).
Summary Summarise(const std::vector<FileReport>& files,
                  const std::map<std::string, std::string>& solution_files = {});

nlohmann::json SummaryJson(const Summary& s, const SummarySettings& settings);
std::string SummaryText(const Summary& s, const SummarySettings& settings);

}  // namespace frenetic::apps::commonroad_cli

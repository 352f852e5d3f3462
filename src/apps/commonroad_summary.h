// The summary of `frenetic commonroad` over every file's report (commonroad_report.h).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commonroad_report.h"

namespace frenetic::apps::commonroad_cli {

// What the summary says besides the reports: the run's settings.
struct SummarySettings {
  std::string prediction;  // "recorded", "constant-velocity"
  int vehicle_type = 2;
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
  int problems = 0, solved = 0, unreadable_files = 0;
  // Per failure kind (and "road" for a problem without a road): the problems with one.
  std::map<std::string, int> failures;
  std::vector<double> plan_ms;  // every cycle's
  double candidates = 0;        // summed over every cycle
  Comparison comparison;
};

// `solution_files`: scenario id -> path of each loaded solution file (pairs the unpaired).
Summary Summarise(const std::vector<FileReport>& files,
                  const std::map<std::string, std::string>& solution_files = {});

nlohmann::json SummaryJson(const Summary& s, const SummarySettings& settings);
std::string SummaryText(const Summary& s, const SummarySettings& settings);

}  // namespace frenetic::apps::commonroad_cli

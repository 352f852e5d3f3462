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

struct Summary {
  int problems = 0, solved = 0, unreadable_files = 0;
  // Per failure kind (and "road" for a problem without a road): the problems with one.
  std::map<std::string, int> failures;
  std::vector<double> plan_ms;  // every cycle's
  double candidates = 0;        // summed over every cycle
};

Summary Summarise(const std::vector<FileReport>& files);

nlohmann::json SummaryJson(const Summary& s, const SummarySettings& settings);
std::string SummaryText(const Summary& s, const SummarySettings& settings);

}  // namespace frenetic::apps::commonroad_cli

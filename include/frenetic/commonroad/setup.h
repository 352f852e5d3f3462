// What the tools that run CommonRoad scenarios share (`frenetic commonroad`, `frenetic tune` with
// a CommonRoad suite, bench/): the scenario files that paths name, and the planner configuration
// they plan with by default (config/planner.yaml with config/commonroad.yaml on top).
#pragma once

#include <string>
#include <vector>

#include "frenetic/plan/planner_config.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

// The scenario files that `paths` name: a file as given, a directory's *.xml sorted by name, in
// the order of `paths`. Errors (one line): a path that does not exist, a directory that cannot be
// listed, no file at all.
StatusOr<std::vector<std::string>> ScenarioFiles(const std::vector<std::string>& paths);

// config/commonroad.yaml of the source tree (kCommonRoadConfig), as an absolute path.
std::string DefaultOverlayPath();

// The planner configuration before the vehicle is applied (CommonRoadConfig): `config_path`
// ("" = PlannerConfig::DefaultPath()) with `overlay_path` ("" = DefaultOverlayPath()) on top.
// Errors name the file and the key.
StatusOr<plan::PlannerConfig> LoadBaseConfig(const std::string& config_path = "",
                                             const std::string& overlay_path = "");

}  // namespace frenetic::commonroad

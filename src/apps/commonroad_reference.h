// The reference trajectories `frenetic commonroad` compares its own with: CommonRoad solution
// files (in the highD set, the recorded human drivers') among the paths or under --compare. A
// solution file is told from a scenario by its root element (<CommonRoadSolution>) and paired
// with the scenario whose benchmark id is the scenario id inside its own benchmark id
// ("KS1:TR2:<scenario id>:2020a"), never by its file name.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "apps/commonroad_report.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/solution.h"
#include "frenetic/status.h"

namespace frenetic::apps::commonroad_cli {

// True when the file's root element is <CommonRoadSolution> (commonroad::PeekRootElement).
bool IsSolutionFile(const std::string& path);

// The solution files --compare names: files as given and the *.xml of directories whose root is
// <CommonRoadSolution> (others are skipped). Errors (one line): a path that does not exist, or no
// solution file at all.
StatusOr<std::vector<std::string>> CompareFiles(const std::vector<std::string>& paths);

struct Reference {
  std::string path;
  cr::Solution solution;
};

struct ReferenceSet {
  std::map<std::string, Reference> by_scenario;  // scenario id -> the first file naming it
  struct Unreadable {
    std::string path, message;
  };
  std::vector<Unreadable> unreadable;  // files that failed to load
  std::vector<std::string> notes;      // one line each: a second file for a scenario, ignored
};

// Loads the solution files in order; a path given twice (the same file) is loaded once.
ReferenceSet LoadReferences(const std::vector<std::string>& files);

// One file to run: a scenario, or a solution file that could not be read (reported as an
// unreadable scenario is, with `error`).
struct InputFile {
  std::string path;
  std::string error;
};

struct Inputs {
  std::vector<InputFile> files;  // in the paths' order; --compare's unreadable ones last
  ReferenceSet references;
};

// `files` (commonroad::ScenarioFiles of the paths) sorted by root element, with the solution
// files --compare names (`compare`: its paths, may be empty). An error (one line) when no
// scenario is left or --compare names nothing usable (CompareFiles).
StatusOr<Inputs> SortInputs(const std::vector<std::string>& files,
                            const std::vector<std::string>& compare);

// The trajectory `t` (the solution file `file`'s, in the file's coordinates) judged and costed
// on the scenario's problem with the file's vehicle (see ReferenceReport).
ReferenceReport EvaluateReference(const cr::Scenario& scenario, const cr::PlanningProblem& problem,
                                  const std::string& file, const cr::SolutionTrajectory& t);

}  // namespace frenetic::apps::commonroad_cli

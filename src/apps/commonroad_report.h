// What `frenetic commonroad` keeps of each scenario file's run: everything its output needs and
// nothing more (no trajectories), so the output is made from reports alone, whichever process ran
// the file. Per problem: the JSON object and the two text lines of the results.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/verdict.h"
#include "frenetic/status.h"

namespace frenetic::apps::commonroad_cli {

namespace cr = ::frenetic::commonroad;

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
  double candidates = 0;        // summed over the cycles
  int not_ok_cycles = 0;        // cycles whose plan status was not kOk
  double tracking_error_max_m = 0;
  double computation_s = 0;
  std::map<std::string, double> costs;  // "WX1", "JB1" of the trajectory, when it has states
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

// The element of the sorted values at q (0..1) of their range, rounded to the nearest index; 0
// for none.
double Percentile(std::vector<double> values, double q);

// A problem's object in the JSON output.
nlohmann::json ProblemJson(const ProblemReport& p);
// A file's object in the JSON output's "scenarios".
nlohmann::json FileJson(const FileReport& f);
// A file's results as text: two lines per problem (the run, then its verdict), or the path and
// why it could not be read.
std::string FileText(const FileReport& f);

}  // namespace frenetic::apps::commonroad_cli

// CommonRoad solution files: KS trajectories, one per planning problem, as the benchmark's
// submission format (commonroad-io, common/solution.py: CommonRoadSolutionWriter and
// CommonRoadSolutionReader):
//
//   <CommonRoadSolution benchmark_id="KS2:WX1:DEU_A9-2_1_T-1:2020a" computation_time="0.82"
//                       date="2024-05-01T12:00:00" processor_name="...">
//     <ksTrajectory planningProblem="10">
//       <ksState><x/><y/><steeringAngle/><velocity/><orientation/><time/></ksState> ...
//
// The benchmark id is <vehicle>:<cost>:<scenario id>:<version>; with several trajectories the
// vehicle and cost ids become bracketed lists, "[KS2,KS2]:[WX1,WX1]:...". The file is named
// "solution_<benchmark id>.xml". Values are written with the shortest text that reads back to the
// same double, so a write/read round trip is exact.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

struct SolutionTrajectory {
  int problem_id = 0;
  int vehicle_type = 2;                 // 1, 2, 3 (vehicle id "KS<type>")
  std::string cost_function = "WX1";    // JB1, SA1, WX1, SM1, SM2, SM3, MW1, TR1, TR2
  std::vector<KsState> states;          // ordered by time step
};

struct Solution {
  std::string scenario_id;             // e.g. "DEU_A9-2_1_T-1"
  std::string version = "2020a";
  std::string date;                    // "YYYY-MM-DDThh:mm:ss"; omitted when empty
  std::optional<double> computation_time;  // s; omitted when absent
  std::string processor_name;          // omitted when empty
  std::vector<SolutionTrajectory> trajectories;

  std::string BenchmarkId() const;
  // "solution_" + FileNamePart(BenchmarkId()) + ".xml"
  std::string FileName() const;
};

// `text` fit to be part of a file name: every byte other than a letter, a digit or one of
// - _ . : [ ] , becomes '_' (a scenario's benchmark id, which names the files written for it, may
// hold anything: a '/' or a control character). The brackets and commas stay: CommonRoad names
// a solution of several planning problems solution_[KS2,KS2]:[WX1,WX1]:<id>:<version>.xml.
std::string FileNamePart(std::string_view text);

// The solution as XML text.
std::string WriteSolution(const Solution& solution);
// Writes WriteSolution() to dir/FileName(); an error names the path.
Status SaveSolution(const Solution& solution, const std::string& dir);

// Reads KS-trajectory solutions. Errors (one line, naming source, line and element): XML syntax,
// a root other than <CommonRoadSolution>, a malformed benchmark id, a vehicle other than KS1-3,
// a cost id CommonRoad does not define, vehicle/cost lists that do not match the trajectories, a
// trajectory type other than ksTrajectory, a missing or non-finite state field, repeated time steps.
// States are sorted by time step.
StatusOr<Solution> ParseSolution(std::string_view xml, std::string_view source);
StatusOr<Solution> LoadSolution(const std::string& path);

// The name of the root element of the XML file at `path`, read from its first 64 KiB without
// parsing the document (the XML declaration, processing instructions, comments and a doctype
// skipped): "CommonRoadSolution" for a solution file, "commonRoad" for a scenario. "" when the
// file cannot be read or no element starts there. Tells a directory's solution files from its
// scenarios at the cost of one small read each.
std::string PeekRootElement(const std::string& path);
// The same on the start of a document.
std::string PeekRootElementOf(std::string_view text);

// "YYYY-MM-DDThh:mm:ss" of the current local time, and the processor's model name from
// /proc/cpuinfo with "(R)" and "(TM)" removed ("" when unknown), as commonroad-io fills them in.
std::string CurrentDate();
std::string ProcessorName();

}  // namespace frenetic::commonroad

// A CommonRoad scenario (format 2020a) and its reader.
//
// The reader keeps what a motion-planning benchmark needs: the lanelet network, traffic signs (for
// speed limits), static and dynamic obstacles with their trajectories or set-based predictions
// (<occupancySet>), and the planning problems.
// Elements it does not know (location, scenarioTags' contents, trafficLight, intersection, signal
// states, ...) are ignored.
//
// A malformed file gives one error, one line: "<source>:<line>: <element>: <what is wrong>", the
// line of the offending element. Errors: XML syntax, wrong root element, commonRoadVersion other
// than 2020a, a missing required element or attribute, a number that does not parse or is NaN or
// infinite, a length or radius not positive, a bound with fewer than two points, a polygon with
// fewer than three, duplicate ids within lanelets, obstacles, problems or signs, a reference
// (predecessor, successor, adjacent, traffic sign, goal lanelet) to an id that does not exist,
// trajectory time steps that are not consecutive after the initial state's, an obstacle with both
// a <trajectory> and an <occupancySet>, an <occupancySet> without <occupancy>, an occupancy
// without <shape> or <time>, and an occupancy's time (an exact step or an interval of steps) that
// is not integers within [0, 10^8] or does not lie after the initial state's. Nothing in the input
// makes the reader crash.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "frenetic/commonroad/lanelet.h"
#include "frenetic/commonroad/obstacle.h"
#include "frenetic/commonroad/planning_problem.h"
#include "frenetic/commonroad/traffic_sign.h"
#include "frenetic/status.h"

namespace frenetic::commonroad {

struct Scenario {
  std::string benchmark_id;  // e.g. "DEU_A9-2_1_T-1"
  std::string version;       // "2020a"
  std::string source;        // where it was read from (the path, or the name given to ParseScenario)
  double dt = 0.1;           // s per time step
  std::vector<std::string> tags;  // <scenarioTags> children: "highway", "multi_lane", ...
  std::vector<Lanelet> lanelets;
  std::vector<TrafficSign> signs;
  std::vector<Obstacle> obstacles;  // static first, then dynamic, each in file order
  std::vector<PlanningProblem> problems;
  // The file's coordinates are these plus `origin`: a file whose lanelets lie farther than
  // kLocalFrameBeyond from its origin (map projections: UTM northings run to millions of
  // metres) is read into a frame centred on them (origin rounded to the kilometre), where the
  // reference-line fit and the planner keep their precision and their input bounds; (0, 0)
  // otherwise. Solution files add it back.
  Vec2 origin;

  // nullptr when there is none with that id. Linear searches.
  const Lanelet* FindLanelet(int id) const;
  const Obstacle* FindObstacle(int id) const;
  const PlanningProblem* FindProblem(int id) const;
  const TrafficSign* FindSign(int id) const;
};

// m: see Scenario::origin.
inline constexpr double kLocalFrameBeyond = 1e4;

// Parses a scenario from XML text. `source` names it in error messages and Scenario::source.
StatusOr<Scenario> ParseScenario(std::string_view xml, std::string_view source);
// Reads and parses the file; an unreadable file is an error naming the path.
StatusOr<Scenario> LoadScenario(const std::string& path);

}  // namespace frenetic::commonroad

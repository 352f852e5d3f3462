// Builds small CommonRoad 2020a scenario files in the tests (straight, two-way, curved and
// lane-drop roads, obstacles with trajectories or set-based predictions, planning problems with
// goals by lanelet, rectangle or time only), one element per line so that a test can name the line
// an error must point at.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/scenario.h"

namespace frenetic::commonroad::testing {

inline std::string Num(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.10g", v);
  return buffer;
}

inline std::string PointXml(Vec2 p) {
  return "<point><x>" + Num(p.x) + "</x><y>" + Num(p.y) + "</y></point>";
}

struct LaneletXml {
  int id = 1;
  std::vector<Vec2> left, right;
  std::vector<int> predecessors, successors;
  std::optional<std::pair<int, bool>> adjacent_left, adjacent_right;  // id, same direction
  std::string left_marking = "dashed", right_marking = "solid";
  std::vector<int> signs;
};

inline LaneletXml Lane(int id, std::vector<Vec2> left, std::vector<Vec2> right) {
  LaneletXml l;
  l.id = id;
  l.left = std::move(left);
  l.right = std::move(right);
  return l;
}

// An obstacle state: time step, position, orientation, velocity.
struct StateXml {
  int time = 0;
  Vec2 position;
  double orientation = 0, velocity = 0;
};

// Shapes as XML fragments (for an <occupancy>'s <shape>, say).
inline std::string RectangleXml(double length, double width, Vec2 center = {},
                                double orientation = 0) {
  return "<rectangle><length>" + Num(length) + "</length><width>" + Num(width) +
         "</width><orientation>" + Num(orientation) + "</orientation><center><x>" + Num(center.x) +
         "</x><y>" + Num(center.y) + "</y></center></rectangle>";
}
inline std::string CircleXml(double radius, Vec2 center) {
  return "<circle><radius>" + Num(radius) + "</radius><center><x>" + Num(center.x) + "</x><y>" +
         Num(center.y) + "</y></center></circle>";
}
inline std::string PolygonXml(const std::vector<Vec2>& points) {
  std::string s = "<polygon>";
  for (Vec2 p : points) s += PointXml(p);
  return s + "</polygon>";
}

// One occupancy of a set-based prediction: steps start..end (an <exact> one when equal), shapes
// as XML fragments.
struct OccupancyXml {
  int start = 1, end = 1;
  std::string shapes;
};

// Goal states as XML fragments.
inline std::string GoalTimeXml(int start, int end) {
  return "<time><intervalStart>" + std::to_string(start) + "</intervalStart><intervalEnd>" +
         std::to_string(end) + "</intervalEnd></time>";
}
inline std::string GoalLaneletXml(int lanelet, int start, int end) {
  return "<goalState>\n" + GoalTimeXml(start, end) + "\n<position><lanelet ref=\"" +
         std::to_string(lanelet) + "\"/></position>\n</goalState>";
}
inline std::string GoalRectangleXml(Vec2 center, double length, double width, double orientation,
                                    int start, int end, std::string extra = "") {
  return "<goalState>\n" + GoalTimeXml(start, end) + "\n<position><rectangle><length>" +
         Num(length) + "</length><width>" + Num(width) + "</width><orientation>" +
         Num(orientation) + "</orientation><center><x>" + Num(center.x) + "</x><y>" +
         Num(center.y) + "</y></center></rectangle></position>\n" + extra + "</goalState>";
}
inline std::string GoalTimeOnlyXml(int start, int end, std::string extra = "") {
  return "<goalState>\n" + GoalTimeXml(start, end) + "\n" + extra + "</goalState>";
}
inline std::string IntervalXml(const char* name, double start, double end) {
  return std::string("<") + name + "><intervalStart>" + Num(start) + "</intervalStart><intervalEnd>" +
         Num(end) + "</intervalEnd></" + name + ">\n";
}

class ScenarioXml {
 public:
  explicit ScenarioXml(std::string benchmark_id = "ZAM_Test-1_1_T-1", double dt = 0.1)
      : benchmark_id_(std::move(benchmark_id)), dt_(dt) {}

  ScenarioXml& Lanelet(const LaneletXml& l) {
    std::string s = "<lanelet id=\"" + std::to_string(l.id) + "\">\n<leftBound>\n";
    for (Vec2 p : l.left) s += PointXml(p) + "\n";
    s += "<lineMarking>" + l.left_marking + "</lineMarking>\n</leftBound>\n<rightBound>\n";
    for (Vec2 p : l.right) s += PointXml(p) + "\n";
    s += "<lineMarking>" + l.right_marking + "</lineMarking>\n</rightBound>\n";
    for (int id : l.predecessors) s += "<predecessor ref=\"" + std::to_string(id) + "\"/>\n";
    for (int id : l.successors) s += "<successor ref=\"" + std::to_string(id) + "\"/>\n";
    if (l.adjacent_left) {
      s += "<adjacentLeft ref=\"" + std::to_string(l.adjacent_left->first) + "\" drivingDir=\"" +
           (l.adjacent_left->second ? "same" : "opposite") + "\"/>\n";
    }
    if (l.adjacent_right) {
      s += "<adjacentRight ref=\"" + std::to_string(l.adjacent_right->first) +
           "\" drivingDir=\"" + (l.adjacent_right->second ? "same" : "opposite") + "\"/>\n";
    }
    s += "<laneletType>interstate</laneletType>\n";
    for (int id : l.signs) s += "<trafficSignRef ref=\"" + std::to_string(id) + "\"/>\n";
    s += "</lanelet>\n";
    body_ += s;
    return *this;
  }

  // A German maximum-speed sign (274) in m/s.
  ScenarioXml& SpeedSign(int id, double speed) {
    body_ += "<trafficSign id=\"" + std::to_string(id) +
             "\">\n<trafficSignElement><trafficSignID>274</trafficSignID><additionalValue>" +
             Num(speed) + "</additionalValue></trafficSignElement>\n<virtual>false</virtual>\n"
             "</trafficSign>\n";
    return *this;
  }

  ScenarioXml& StaticObstacle(int id, double length, double width, Vec2 position,
                              double orientation) {
    body_ += "<staticObstacle id=\"" + std::to_string(id) + "\">\n<type>parkedVehicle</type>\n" +
             RectangleShape(length, width) + InitialState(StateXml{0, position, orientation, 0}) +
             "</staticObstacle>\n";
    return *this;
  }

  // states.front() is the initial state; the rest form the trajectory.
  ScenarioXml& DynamicObstacle(int id, double length, double width,
                               const std::vector<StateXml>& states) {
    std::string s = "<dynamicObstacle id=\"" + std::to_string(id) + "\">\n<type>car</type>\n" +
                    RectangleShape(length, width) + InitialState(states.front());
    if (states.size() > 1) {
      s += "<trajectory>\n";
      for (size_t i = 1; i < states.size(); ++i) s += "<state>\n" + StateBody(states[i]) + "</state>\n";
      s += "</trajectory>\n";
    }
    body_ += s + "</dynamicObstacle>\n";
    return *this;
  }

  // A car with a set-based prediction: its initial state, then an <occupancySet>, one element
  // per line.
  ScenarioXml& SetBasedObstacle(int id, double length, double width, const StateXml& initial,
                                const std::vector<OccupancyXml>& occupancies) {
    std::string s = "<dynamicObstacle id=\"" + std::to_string(id) + "\">\n<type>car</type>\n" +
                    RectangleShape(length, width) + InitialState(initial) + "<occupancySet>\n";
    for (const OccupancyXml& o : occupancies) {
      s += "<occupancy>\n<shape>" + o.shapes + "</shape>\n<time>";
      s += o.start == o.end
               ? "<exact>" + std::to_string(o.start) + "</exact>"
               : "<intervalStart>" + std::to_string(o.start) + "</intervalStart><intervalEnd>" +
                     std::to_string(o.end) + "</intervalEnd>";
      s += "</time>\n</occupancy>\n";
    }
    body_ += s + "</occupancySet>\n</dynamicObstacle>\n";
    return *this;
  }

  ScenarioXml& Problem(int id, Vec2 position, double orientation, double velocity,
                       const std::vector<std::string>& goals) {
    std::string s = "<planningProblem id=\"" + std::to_string(id) + "\">\n<initialState>\n" +
                    "<position>" + PointXml(position) + "</position>\n<orientation><exact>" +
                    Num(orientation) + "</exact></orientation>\n<time><exact>0</exact></time>\n" +
                    "<velocity><exact>" + Num(velocity) + "</exact></velocity>\n" +
                    "<yawRate><exact>0</exact></yawRate>\n<slipAngle><exact>0</exact></slipAngle>\n" +
                    "</initialState>\n";
    for (const std::string& g : goals) s += g + "\n";
    body_ += s + "</planningProblem>\n";
    return *this;
  }

  // Raw text appended to the body (for malformed cases).
  ScenarioXml& Raw(std::string_view text) {
    body_ += text;
    return *this;
  }

  std::string Str() const {
    return "<?xml version='1.0' encoding='UTF-8'?>\n<commonRoad timeStepSize=\"" + Num(dt_) +
           "\" commonRoadVersion=\"2020a\" author=\"test\" affiliation=\"test\" source=\"hand-made\" "
           "benchmarkID=\"" +
           benchmark_id_ + "\" date=\"2024-01-01\">\n<location>\n<geoNameId>-999</geoNameId>\n"
           "</location>\n<scenarioTags>\n<highway/>\n<multi_lane/>\n</scenarioTags>\n" +
           body_ + "</commonRoad>\n";
  }

 private:
  static std::string RectangleShape(double length, double width) {
    return "<shape>\n<rectangle><length>" + Num(length) + "</length><width>" + Num(width) +
           "</width></rectangle>\n</shape>\n";
  }
  static std::string StateBody(const StateXml& s) {
    return "<position>" + PointXml(s.position) + "</position>\n<orientation><exact>" +
           Num(s.orientation) + "</exact></orientation>\n<time><exact>" + std::to_string(s.time) +
           "</exact></time>\n<velocity><exact>" + Num(s.velocity) + "</exact></velocity>\n";
  }
  static std::string InitialState(const StateXml& s) {
    return "<initialState>\n" + StateBody(s) + "</initialState>\n";
  }

  std::string benchmark_id_;
  double dt_;
  std::string body_;
};

// Points along x from x0 to x1 every `step` m at height y.
inline std::vector<Vec2> Line(double x0, double x1, double y, double step = 10) {
  std::vector<Vec2> out;
  const int n = static_cast<int>(std::round((x1 - x0) / step));
  for (int i = 0; i <= n; ++i) out.push_back({x0 + (x1 - x0) * i / n, y});
  return out;
}

// Two lanes along +x from x = 0 to `length`, 3.5 m wide, moved by `offset` (a file in
// map-projection coordinates): lanelet 1 (right, y in [-3.5, 0]) and lanelet 2 (left, y in
// [0, 3.5]), adjacent in the same direction.
inline ScenarioXml& AddStraightRoadAt(ScenarioXml& xml, Vec2 offset, double length = 300) {
  auto at = [offset](std::vector<Vec2> line) {
    for (Vec2& p : line) p = p + offset;
    return line;
  };
  LaneletXml right = Lane(1, at(Line(0, length, 0)), at(Line(0, length, -3.5)));
  right.adjacent_left = {{2, true}};
  LaneletXml left = Lane(2, at(Line(0, length, 3.5)), at(Line(0, length, 0)));
  left.adjacent_right = {{1, true}};
  left.left_marking = "solid";
  left.right_marking = "dashed";
  return xml.Lanelet(right).Lanelet(left);
}

// The same at the origin.
inline ScenarioXml& AddStraightRoad(ScenarioXml& xml, double length = 300) {
  return AddStraightRoadAt(xml, {}, length);
}

// A two-way road along +x from x = 0 to `length`, lanes 3.5 m wide: lanelet 1 driven +x
// (y in [-3.5, 0]) and lanelet 2 driven -x (y in [0, 3.5], its points from x = length back to
// 0), each the other's adjacent left in the opposite direction (their left bounds are the centre
// line).
inline ScenarioXml& AddTwoWayRoad(ScenarioXml& xml, double length = 300) {
  LaneletXml ours = Lane(1, Line(0, length, 0), Line(0, length, -3.5));
  ours.adjacent_left = {{2, false}};
  ours.left_marking = "dashed";
  std::vector<Vec2> centre = Line(0, length, 0), edge = Line(0, length, 3.5);
  std::reverse(centre.begin(), centre.end());
  std::reverse(edge.begin(), edge.end());
  LaneletXml theirs = Lane(2, centre, edge);
  theirs.adjacent_left = {{1, false}};
  theirs.left_marking = "dashed";
  return xml.Lanelet(ours).Lanelet(theirs);
}

// One lane of width 4 m along a left-turning arc about (0, radius): the centre line has the
// given radius, from angle 0 (at the origin, heading +x) through `sweep` rad.
inline ScenarioXml& AddCurvedRoad(ScenarioXml& xml, double radius, double sweep, int id = 1) {
  LaneletXml l = Lane(id, {}, {});
  const int n = 60;
  for (int i = 0; i <= n; ++i) {
    const double a = sweep * i / n;
    const Vec2 center{0, radius};
    const Vec2 out{std::sin(a), -std::cos(a)};  // from the arc's centre to the road
    l.left.push_back(center + (radius - 2) * out);
    l.right.push_back(center + (radius + 2) * out);
  }
  return xml.Lanelet(l);
}

// A motorway exit drawn as a split: two lanes along +x (lanelet 1 right, y in [-3.5, 0], and 2
// left, y in [0, 3.5], from x = 0 to 200), the left lane going on as 3 (to 500) and the right one
// splitting at x = 200 into 4 (straight on to 500) and the ramp 5, which starts on top of 4 and
// bends off to the right (0.0002 (x - 200)^2 m: 3.5 m at x = 332, 8 m at 400, where it ends).
// No adjacency between the halves of the split; 3 and 4 are neighbours, as are 1 and 2.
inline ScenarioXml& AddSplitExit(ScenarioXml& xml) {
  const auto ramp = [](double y) {
    std::vector<Vec2> out = Line(200, 400, y);
    for (Vec2& p : out) p.y -= 0.0002 * (p.x - 200) * (p.x - 200);
    return out;
  };
  LaneletXml l1 = Lane(1, Line(0, 200, 0), Line(0, 200, -3.5));
  l1.adjacent_left = {{2, true}};
  l1.successors = {4, 5};
  LaneletXml l2 = Lane(2, Line(0, 200, 3.5), Line(0, 200, 0));
  l2.adjacent_right = {{1, true}};
  l2.successors = {3};
  LaneletXml l3 = Lane(3, Line(200, 500, 3.5), Line(200, 500, 0));
  l3.adjacent_right = {{4, true}};
  l3.predecessors = {2};
  LaneletXml l4 = Lane(4, Line(200, 500, 0), Line(200, 500, -3.5));
  l4.adjacent_left = {{3, true}};
  l4.predecessors = {1};
  LaneletXml l5 = Lane(5, ramp(0), ramp(-3.5));
  l5.predecessors = {1};
  return xml.Lanelet(l1).Lanelet(l2).Lanelet(l3).Lanelet(l4).Lanelet(l5);
}

// A hand-crafted zipper merge drawn as such files are, each border straight in a few points:
// two lanes along +x from x = -180 to -20 (lanelet 25 left, y in [7, 10.5]; 26 right, y in
// [3.5, 7]), each border in three points; 25 goes on into 28, which moves 3.5 m right over 20 m,
// and 26 into 27, straight; both meet in 24 (x 0 to 150, y in [3.5, 7]).
inline ScenarioXml& AddZipperMerge(ScenarioXml& xml) {
  LaneletXml l25 = Lane(25, {{-180, 10.5}, {-100, 10.5}, {-20, 10.5}}, {{-180, 7}, {-100, 7}, {-20, 7}});
  l25.adjacent_right = {{26, true}};
  l25.successors = {28};
  LaneletXml l26 = Lane(26, {{-180, 7}, {-100, 7}, {-20, 7}}, {{-180, 3.5}, {-100, 3.5}, {-20, 3.5}});
  l26.adjacent_left = {{25, true}};
  l26.successors = {27};
  LaneletXml l28 = Lane(28, {{-20, 10.5}, {0, 7}}, {{-20, 7}, {0, 3.5}});
  l28.predecessors = {25};
  l28.successors = {24};
  LaneletXml l27 = Lane(27, {{-20, 7}, {0, 7}}, {{-20, 3.5}, {0, 3.5}});
  l27.predecessors = {26};
  l27.successors = {24};
  LaneletXml l24 = Lane(24, {{0, 7}, {150, 7}}, {{0, 3.5}, {150, 3.5}});
  l24.predecessors = {27, 28};
  return xml.Lanelet(l25).Lanelet(l26).Lanelet(l28).Lanelet(l27).Lanelet(l24);
}

// The 1-based line of the first occurrence of `needle` in `text` (0 when absent).
inline int LineOf(std::string_view text, std::string_view needle) {
  const size_t at = text.find(needle);
  if (at == std::string_view::npos) return 0;
  int line = 1;
  for (size_t i = 0; i < at; ++i) line += text[i] == '\n';
  return line;
}

// The scenario of `xml`; a test failure, and an empty scenario, when it does not parse.
inline Scenario Parse(const ScenarioXml& xml) {
  StatusOr<Scenario> s = ParseScenario(xml.Str(), "test.xml");
  EXPECT_TRUE(s.ok()) << s.message();
  return s.ok() ? std::move(s).value() : Scenario{};
}

}  // namespace frenetic::commonroad::testing

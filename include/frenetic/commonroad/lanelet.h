// A CommonRoad lanelet: a piece of lane between a left and a right bound, driven from the bounds'
// first points to their last (format 2020a, §lanelet). Coordinates in metres, scenario frame.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/commonroad/geometry.h"

namespace frenetic::commonroad {

enum class LineMarking { kNone, kUnknown, kDashed, kSolid, kBroadDashed, kBroadSolid, kNoMarking };
// "dashed", "solid", "broad_dashed", "broad_solid", "no_marking", "unknown"; any other text gives
// kUnknown (markings are informative only). kNone: the bound has no <lineMarking>.
LineMarking ParseLineMarking(std::string_view text);
const char* ToString(LineMarking marking);

struct Adjacent {
  int id = 0;
  bool same_direction = true;  // drivingDir="same"
};

struct Lanelet {
  int id = 0;
  // The bounds as the file gives them, repeated points included. The format (2020a) asks for equal
  // point counts; the reader accepts unequal ones (CenterLine() resamples them).
  std::vector<Vec2> left, right;
  std::vector<int> predecessors, successors;
  std::optional<Adjacent> adjacent_left, adjacent_right;
  LineMarking left_marking = LineMarking::kNone, right_marking = LineMarking::kNone;
  std::vector<std::string> types;        // <laneletType>: "interstate", "urban", ...
  std::vector<std::string> user_one_way;  // <userOneWay>: "vehicle", "car", ...
  std::vector<int> traffic_signs;         // <trafficSignRef> ids
  // m/s: the lowest maximum speed among the traffic signs the lanelet references (2020a signs
  // "274" and "R2-1" with their additional value in m/s); absent when none gives one.
  std::optional<double> speed_limit;
  int line = 0;  // line of the <lanelet> element in the source, 0 when built in code

  // The bound without consecutive repeated points.
  std::vector<Vec2> CleanLeft() const { return CleanPolyline(left); }
  std::vector<Vec2> CleanRight() const { return CleanPolyline(right); }
  // Midpoints of the bounds' point pairs (CommonRoad's center_vertices) when the counts match;
  // otherwise both bounds resampled to the larger count at equal arc-length fractions first.
  // Repeated points are dropped from the result.
  std::vector<Vec2> CenterLine() const;
  // The lanelet's area: left bound, then the right bound reversed (CommonRoad's
  // convert_to_polygon), repeated points dropped.
  std::vector<Vec2> Polygon() const;
  // Length of the centre line, m.
  double Length() const;
};

}  // namespace frenetic::commonroad

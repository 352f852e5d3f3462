// A CommonRoad traffic sign (format 2020a, §trafficSign): one or more elements, each a sign ID of
// the scenario's country (e.g. "274" maximum speed in Germany, "R2-1" in the USA) with its
// additional values as text.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frenetic/commonroad/geometry.h"

namespace frenetic::commonroad {

struct TrafficSignElement {
  std::string sign_id;                         // <trafficSignID>
  std::vector<std::string> additional_values;  // <additionalValue>
};

struct TrafficSign {
  int id = 0;
  std::vector<TrafficSignElement> elements;
  std::optional<Vec2> position;
  bool is_virtual = false;
  int line = 0;  // source line, 0 when built in code

  // m/s: the lowest maximum speed this sign gives (elements "274" or "R2-1" whose first additional
  // value is a finite positive number: CommonRoad 2020a gives it in m/s); absent otherwise.
  std::optional<double> MaxSpeed() const;
};

}  // namespace frenetic::commonroad

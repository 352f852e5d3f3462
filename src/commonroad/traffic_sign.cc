#include "frenetic/commonroad/traffic_sign.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace frenetic::commonroad {

std::optional<double> TrafficSign::MaxSpeed() const {
  std::optional<double> best;
  for (const TrafficSignElement& e : elements) {
    if ((e.sign_id != "274" && e.sign_id != "R2-1") || e.additional_values.empty()) continue;
    const std::string& text = e.additional_values.front();
    double v = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v) || v <= 0) {
      continue;
    }
    best = best ? std::min(*best, v) : v;
  }
  return best;
}

}  // namespace frenetic::commonroad

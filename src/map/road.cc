#include "frenetic/map/road.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "frenetic/check.h"

namespace frenetic::map {
namespace {

constexpr int kMaxRoadLanes = 16;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

std::shared_ptr<const Road> Road::Uniform(std::shared_ptr<const ReferenceLine> line, int num_lanes,
                                          double lane_width) {
  FRENETIC_CHECK(line != nullptr);
  FRENETIC_CHECK(num_lanes >= 1 && num_lanes <= kMaxRoadLanes);
  FRENETIC_CHECK(lane_width > 0 && std::isfinite(lane_width));
  std::shared_ptr<Road> road(new Road());
  road->line_ = std::move(line);
  for (int l = 0; l < num_lanes; ++l) {
    LaneProfile p;
    p.s = {-kInf, kInf};
    p.left = {l * lane_width, l * lane_width};
    p.right = {(l + 1) * lane_width, (l + 1) * lane_width};
    road->lanes_.push_back(std::move(p));
  }
  road->uniform_ = true;
  road->lane_width_ = lane_width;
  return road;
}

StatusOr<std::shared_ptr<const Road>> Road::Make(std::shared_ptr<const ReferenceLine> line,
                                                 std::vector<LaneProfile> lanes,
                                                 std::string_view source) {
  const std::string src = source.empty() ? std::string("road") : std::string(source);
  if (line == nullptr) return Status::Error(src + ": no reference line");
  if (lanes.empty()) return Status::Error(src + ": a road needs at least one lane");
  if (static_cast<int>(lanes.size()) > kMaxRoadLanes) {
    return Status::Error(src + ": " + std::to_string(lanes.size()) + " lanes, at most " +
                         std::to_string(kMaxRoadLanes));
  }
  std::vector<double> widths;
  for (size_t l = 0; l < lanes.size(); ++l) {
    const LaneProfile& p = lanes[l];
    const std::string where = src + ": lane " + std::to_string(l) + ": ";
    if (p.s.size() < 2 || p.left.size() != p.s.size() || p.right.size() != p.s.size()) {
      return Status::Error(where + "needs at least 2 stations, each with both borders");
    }
    for (size_t i = 0; i < p.s.size(); ++i) {
      if (!std::isfinite(p.s[i]) || !std::isfinite(p.left[i]) || !std::isfinite(p.right[i])) {
        return Status::Error(where + "station " + std::to_string(i) + " is not finite");
      }
      if (i > 0 && !(p.s[i] > p.s[i - 1])) {
        return Status::Error(where + "stations must increase in s (station " + std::to_string(i) +
                             ")");
      }
      if (!(p.right[i] > p.left[i])) {
        return Status::Error(where + "right border not right of the left one at station " +
                             std::to_string(i));
      }
      widths.push_back(p.right[i] - p.left[i]);
    }
    if (!(p.speed_limit > 0)) return Status::Error(where + "speed limit must be > 0");
    if (std::isnan(p.wall)) return Status::Error(where + "wall is not a number");
  }
  std::shared_ptr<Road> road(new Road());
  road->line_ = std::move(line);
  road->lanes_ = std::move(lanes);
  std::nth_element(widths.begin(), widths.begin() + widths.size() / 2, widths.end());
  road->lane_width_ = widths[widths.size() / 2];
  return std::shared_ptr<const Road>(std::move(road));
}

Road::Span Road::LaneAt(int lane, double s) const {
  Span out{kNaN, kNaN, false};
  if (lane < 0 || lane >= num_lanes()) return out;
  const LaneProfile& p = lanes_[lane];
  if (uniform_) return {p.left[0], p.right[0], true};
  s = line_->WrapS(s);
  if (!(s >= p.s.front() && s <= p.s.back())) return out;
  // The segment [s_i, s_i+1] holding s.
  const size_t i = std::clamp<size_t>(
      std::upper_bound(p.s.begin(), p.s.end(), s) - p.s.begin(), 1, p.s.size() - 1);
  const double f = (s - p.s[i - 1]) / (p.s[i] - p.s[i - 1]);
  out.left = p.left[i - 1] + f * (p.left[i] - p.left[i - 1]);
  out.right = p.right[i - 1] + f * (p.right[i] - p.right[i - 1]);
  out.exists = true;
  return out;
}

double Road::LaneBegin(int lane) const {
  if (lane < 0 || lane >= num_lanes()) return kNaN;
  return uniform_ ? -kInf : lanes_[lane].s.front();
}

double Road::LaneEnd(int lane) const {
  if (lane < 0 || lane >= num_lanes()) return kNaN;
  return uniform_ ? kInf : lanes_[lane].s.back();
}

double Road::SpeedLimit(int lane) const {
  if (lane < 0 || lane >= num_lanes()) return kNaN;
  return lanes_[lane].speed_limit;
}

double Road::Wall(int lane) const {
  if (lane < 0 || lane >= num_lanes()) return kNaN;
  return lanes_[lane].wall;
}

bool Road::Oncoming(int lane) const {
  return lane >= 0 && lane < num_lanes() && lanes_[lane].oncoming;
}

bool Road::Drops(int lane) const {
  return lane >= 0 && lane < num_lanes() && lanes_[lane].drops;
}

Road::Span Road::EdgesAt(double s) const {
  Span out{kNaN, kNaN, false};
  for (int l = 0; l < num_lanes(); ++l) {
    const Span a = LaneAt(l, s);
    if (!a.exists) continue;
    out.left = out.exists ? std::min(out.left, a.left) : a.left;
    out.right = out.exists ? std::max(out.right, a.right) : a.right;
    out.exists = true;
  }
  return out;
}

int Road::LaneOf(double s, double d) const {
  int best = -1;
  double best_off = kInf;
  for (int l = 0; l < num_lanes(); ++l) {
    const Span a = LaneAt(l, s);
    if (!a.exists || d < a.left || d > a.right) continue;
    const double off = std::abs(d - a.centre());
    if (off < best_off) {
      best_off = off;
      best = l;
    }
  }
  return best;
}

double Road::CentreToward(double s, double d, double toward) const {
  const double ahead = d + std::copysign(0.5 * lane_width() + 0.01, toward);
  int lane = LaneOf(s, ahead);
  if (lane < 0) lane = LaneOf(s, d);
  const Span span = LaneAt(lane, s);
  return span.exists && (span.centre() - d) * toward > 0 ? span.centre() : kNaN;
}

}  // namespace frenetic::map

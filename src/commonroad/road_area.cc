#include "frenetic/commonroad/road_area.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <boost/geometry/index/rtree.hpp>

#include "commonroad/boost_geometry.h"

// Boost.Geometry 1.74's rescale policy (get_rescale_policy.hpp) trips GCC 12's
// -Wmaybe-uninitialized once inlined into Build(); the value is set on every path that reads it.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace frenetic::commonroad {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

namespace {

// Holes below this are the rounding of shared points, not gaps of the network (see the header).
constexpr double kMinHoleArea = 1e-9;  // m^2

bool Finite(Vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }

BoostMultiPolygon Buffered(const BoostPolygon& polygon, double distance) {
  BoostMultiPolygon out;
  if (distance <= 0) {
    out.push_back(polygon);
    return out;
  }
  const bg::strategy::buffer::distance_symmetric<double> dist(distance);
  const bg::strategy::buffer::join_miter join;
  const bg::strategy::buffer::end_flat end;
  const bg::strategy::buffer::point_square point;
  const bg::strategy::buffer::side_straight side;
  bg::buffer(polygon, out, dist, side, join, end, point);
  return out;
}

// The quadrilateral that continues a lanelet beyond one end: `a` and `b` the bounds' end points,
// `da` and `db` the bounds' directions there (unit vectors pointing away from the lanelet).
std::vector<Vec2> EndExtension(Vec2 a, Vec2 da, Vec2 b, Vec2 db, double margin) {
  return {a, a + margin * da, b + margin * db, b};
}

Vec2 Unit(Vec2 from, Vec2 to) {
  const Vec2 d = to - from;
  const double n = Norm(d);
  return n > 0 ? (1.0 / n) * d : Vec2{};
}

// The rings that make up a lanelet's area: its polygon and the extensions of its open ends.
std::vector<std::vector<Vec2>> LaneletRings(const Lanelet& lanelet, double open_end_margin) {
  std::vector<std::vector<Vec2>> rings{lanelet.Polygon()};
  const std::vector<Vec2> left = lanelet.CleanLeft(), right = lanelet.CleanRight();
  if (open_end_margin <= 0 || left.size() < 2 || right.size() < 2) return rings;
  if (lanelet.predecessors.empty()) {
    rings.push_back(EndExtension(left[0], Unit(left[1], left[0]), right[0],
                                 Unit(right[1], right[0]), open_end_margin));
  }
  if (lanelet.successors.empty()) {
    const size_t l = left.size() - 1, r = right.size() - 1;
    rings.push_back(EndExtension(left[l], Unit(left[l - 1], left[l]), right[r],
                                 Unit(right[r - 1], right[r]), open_end_margin));
  }
  return rings;
}

// The outline of each lane section, as CommonRoad's drivability checker builds its road
// (commonroad_dc.boundary.lanelet_bounds.lane_sections and lane_hull): a section is a lanelet with
// every lanelet reached from it through adjacentLeft / adjacentRight (either driving direction);
// its outline runs across its start from the rightmost lanelet's right bound to the leftmost's
// left bound, along that left bound, back across its end and along the rightmost's right bound.
// The lane lines inside a section are not part of it. A section is listed once per lanelet the
// walk starts from that it has not met (as the checker's does; the union does not mind).
struct Section {
  std::vector<Vec2> ring;
  std::vector<int> members;  // lanelet ids
};

std::vector<Section> SectionRings(std::span<const Lanelet> lanelets) {
  std::unordered_map<int, const Lanelet*> by_id;
  for (const Lanelet& l : lanelets) by_id.emplace(l.id, &l);
  const auto find = [&](const std::optional<Adjacent>& a) -> const Lanelet* {
    if (!a) return nullptr;
    const auto it = by_id.find(a->id);
    return it == by_id.end() ? nullptr : it->second;
  };
  const int limit = static_cast<int>(lanelets.size());  // a cycle of references ends there
  std::unordered_set<int> met;
  std::vector<Section> rings;
  for (auto it = lanelets.rbegin(); it != lanelets.rend(); ++it) {  // the checker pops the last
    if (met.count(it->id) != 0) continue;
    met.insert(it->id);
    const Lanelet* current = &*it;
    std::vector<int> members{it->id};
    bool direction = true;  // whether `current` is driven as the first lanelet is
    // One lanelet to the right (or left), seen in the first lanelet's driving direction; false
    // when there is none.
    const auto step = [&](bool rightward) {
      const std::optional<Adjacent>& a =
          direction == rightward ? current->adjacent_right : current->adjacent_left;
      const Lanelet* next = find(a);
      if (next == nullptr) return false;
      direction = direction == a->same_direction;
      current = next;
      members.push_back(current->id);
      return true;
    };
    // To the rightmost lanelet.
    for (int n = 0; n < limit; ++n) {
      if (!step(true)) break;
    }
    const auto bounds_of = [](const Lanelet* l) {
      return std::make_pair(CleanPolyline(l->left), CleanPolyline(l->right));
    };
    std::vector<Vec2> start, end_reversed;  // across the start (right to left); the end's reverse
    auto [left0, right0] = bounds_of(current);
    if (left0.empty() || right0.empty()) continue;
    std::vector<Vec2> right_side = direction ? right0 : left0;  // along the section
    if (!direction) std::reverse(right_side.begin(), right_side.end());
    const auto add_across = [&](const std::vector<Vec2>& left, const std::vector<Vec2>& right,
                                bool dir, bool initial) {
      if (initial) {
        start.push_back(dir ? right.front() : left.back());
        end_reversed.push_back(dir ? right.back() : left.front());
      }
      start.push_back(dir ? left.front() : right.back());
      end_reversed.push_back(dir ? left.back() : right.front());
    };
    add_across(left0, right0, direction, true);
    // Leftward to the leftmost lanelet.
    bool ok = true;
    for (int n = 0; n < limit && step(false); ++n) {
      met.insert(current->id);
      auto [l, r] = bounds_of(current);
      if (l.empty() || r.empty()) {
        ok = false;
        break;
      }
      add_across(l, r, direction, false);
    }
    if (!ok) continue;
    auto [left1, right1] = bounds_of(current);
    std::vector<Vec2> left_side = direction ? left1 : right1;
    if (!direction) std::reverse(left_side.begin(), left_side.end());
    // start, the left side's inner points, the end (left to right), the right side's inner
    // points backwards: one closed outline.
    std::vector<Vec2> ring = start;
    for (size_t i = 1; i + 1 < left_side.size(); ++i) ring.push_back(left_side[i]);
    ring.insert(ring.end(), end_reversed.rbegin(), end_reversed.rend());
    for (size_t i = right_side.size() - 1; i-- > 1;) ring.push_back(right_side[i]);
    rings.push_back({CleanPolyline(ring), std::move(members)});
  }
  return rings;
}

// Unites `ring` into `area`, grown by `tolerance` (then unbuffered when Boost.Geometry cannot
// grow it). False when neither could be united.
bool Unite(BoostMultiPolygon& area, const std::vector<Vec2>& ring, double tolerance) {
  const BoostPolygon polygon = ToBoostPolygon(ring);
  for (const double distance : {tolerance, 0.0}) {
    try {
      const BoostMultiPolygon grown = Buffered(polygon, distance);
      if (grown.empty()) continue;
      BoostMultiPolygon merged;
      bg::union_(area, grown, merged);
      if (merged.empty()) continue;
      area = std::move(merged);
      return true;
    } catch (const std::exception&) {
    }
  }
  return false;
}

bool UsableRing(const std::vector<Vec2>& ring) {
  return ring.size() >= 3 && std::all_of(ring.begin(), ring.end(), Finite);
}

}  // namespace

struct RoadArea::Impl {
  BoostMultiPolygon area;
  bgi::rtree<BoostSegment, bgi::quadratic<16>> boundary;
  std::vector<int> skipped;
};

RoadArea::RoadArea() : impl_(std::make_shared<Impl>()) {}

RoadArea RoadArea::Build(std::span<const Lanelet> lanelets, double tolerance,
                         double open_end_margin) {
  auto impl = std::make_shared<Impl>();
  tolerance = std::isfinite(tolerance) ? std::max(tolerance, 0.0) : 0.0;
  open_end_margin = std::isfinite(open_end_margin) ? std::max(open_end_margin, 0.0) : 0.0;
  // The lane sections' outlines. One that is no simple polygon (a section whose lanelets end at
  // different places can fold its outline), or that Boost.Geometry cannot unite, gives way to its
  // lanelets' own polygons.
  std::unordered_set<int> in_section;
  std::unordered_set<int> own_polygon;
  for (const Section& section : SectionRings(lanelets)) {
    in_section.insert(section.members.begin(), section.members.end());
    bool united = false;
    if (UsableRing(section.ring)) {
      const BoostPolygon polygon = ToBoostPolygon(section.ring);
      united = std::abs(bg::area(polygon)) >= 1e-9 && bg::is_valid(polygon) &&
               Unite(impl->area, section.ring, tolerance);
    }
    if (!united) own_polygon.insert(section.members.begin(), section.members.end());
  }
  for (const Lanelet& lanelet : lanelets) {
    bool lanelet_ok = true;
    const bool own = own_polygon.count(lanelet.id) != 0 || in_section.count(lanelet.id) == 0;
    const std::vector<std::vector<Vec2>> rings = LaneletRings(lanelet, open_end_margin);
    for (size_t i = own ? 0 : 1; i < rings.size(); ++i) {  // rings[0]: its polygon
      const std::vector<Vec2>& ring = rings[i];
      if (!UsableRing(ring)) {
        lanelet_ok = false;
        continue;
      }
      // A degenerate extension (a lane that ends in a point) adds nothing.
      if (std::abs(bg::area(ToBoostPolygon(ring))) < 1e-9) continue;
      // Boost.Geometry reports input it cannot handle with exceptions: fall back to the
      // unbuffered polygon, then to leaving the ring out.
      lanelet_ok = Unite(impl->area, ring, tolerance) && lanelet_ok;
    }
    if (!lanelet_ok) impl->skipped.push_back(lanelet.id);
  }
  for (BoostPolygon& p : impl->area) {
    auto& inners = p.inners();
    inners.erase(std::remove_if(inners.begin(), inners.end(),
                                [](const auto& hole) {
                                  return std::abs(bg::area(hole)) < kMinHoleArea;
                                }),
                 inners.end());
  }
  std::vector<BoostSegment> segments;
  const auto add_ring = [&](const auto& ring) {
    for (size_t i = 1; i < ring.size(); ++i) segments.emplace_back(ring[i - 1], ring[i]);
  };
  for (const BoostPolygon& p : impl->area) {
    add_ring(p.outer());
    for (const auto& hole : p.inners()) add_ring(hole);
  }
  impl->boundary = decltype(impl->boundary)(segments.begin(), segments.end());
  RoadArea road;
  road.impl_ = std::move(impl);
  road.tolerance_ = tolerance;
  return road;
}

bool RoadArea::ContainsConvex(std::span<const Vec2> convex) const {
  if (convex.empty() || !std::all_of(convex.begin(), convex.end(), Finite)) return false;
  Vec2 mean;
  for (const Vec2& p : convex) mean = mean + p;
  mean = (1.0 / convex.size()) * mean;
  // Inside, unless the area's boundary enters the polygon.
  return Contains(mean) && !BoundaryTouches(convex);
}

bool RoadArea::BoundaryTouches(std::span<const Vec2> convex) const {
  if (convex.empty() || !std::all_of(convex.begin(), convex.end(), Finite)) return true;
  const BoostPolygon polygon = ToBoostPolygon(convex);
  BoostBox box;
  bg::envelope(polygon, box);
  for (auto it = impl_->boundary.qbegin(bgi::intersects(box)); it != impl_->boundary.qend(); ++it) {
    if (convex.size() < 3 || bg::intersects(*it, polygon)) return true;
  }
  return false;
}

bool RoadArea::Contains(Vec2 point) const {
  return Finite(point) && bg::covered_by(point, impl_->area);
}

double RoadArea::Area() const { return bg::area(impl_->area); }

int RoadArea::PolygonCount() const { return static_cast<int>(impl_->area.size()); }

int RoadArea::HoleCount() const {
  int holes = 0;
  for (const BoostPolygon& p : impl_->area) holes += static_cast<int>(p.inners().size());
  return holes;
}

std::vector<std::vector<Vec2>> RoadArea::HoleRings() const {
  std::vector<std::vector<Vec2>> rings;
  for (const BoostPolygon& p : impl_->area) {
    for (const auto& hole : p.inners()) rings.emplace_back(hole.begin(), hole.end());
  }
  return rings;
}

std::vector<std::vector<Vec2>> RoadArea::BoundaryRings() const {
  std::vector<std::vector<Vec2>> rings;
  for (const BoostPolygon& p : impl_->area) {
    rings.emplace_back(p.outer().begin(), p.outer().end());
    for (const auto& hole : p.inners()) rings.emplace_back(hole.begin(), hole.end());
  }
  return rings;
}

std::span<const int> RoadArea::SkippedLanelets() const { return impl_->skipped; }

}  // namespace frenetic::commonroad

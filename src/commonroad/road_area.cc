#include "frenetic/commonroad/road_area.h"

#include <algorithm>
#include <cmath>
#include <iterator>
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

// Holes below this are slivers between lanelets, not road features (see the header).
constexpr double kMinHoleArea = 1.0;  // m^2

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
  for (const Lanelet& lanelet : lanelets) {
    bool lanelet_ok = true;
    for (const std::vector<Vec2>& ring : LaneletRings(lanelet, open_end_margin)) {
      if (ring.size() < 3 || !std::all_of(ring.begin(), ring.end(), Finite)) {
        lanelet_ok = false;
        continue;
      }
      // A degenerate extension (a lane that ends in a point) adds nothing.
      const BoostPolygon polygon = ToBoostPolygon(ring);
      if (std::abs(bg::area(polygon)) < 1e-9) continue;
      bool united = false;
      // Boost.Geometry reports input it cannot handle with exceptions: fall back to the
      // unbuffered polygon, then to leaving the ring out.
      for (const double distance : {tolerance, 0.0}) {
        try {
          const BoostMultiPolygon grown = Buffered(polygon, distance);
          if (grown.empty()) continue;
          BoostMultiPolygon merged;
          bg::union_(impl->area, grown, merged);
          if (merged.empty()) continue;
          impl->area = std::move(merged);
          united = true;
          break;
        } catch (const std::exception&) {
        }
      }
      lanelet_ok = lanelet_ok && united;
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

std::span<const int> RoadArea::SkippedLanelets() const { return impl_->skipped; }

}  // namespace frenetic::commonroad

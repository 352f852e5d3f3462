#include "frenetic/commonroad/road_area.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

#include <boost/geometry/index/rtree.hpp>

#include "commonroad/boost_geometry.h"

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

}  // namespace

struct RoadArea::Impl {
  BoostMultiPolygon area;
  bgi::rtree<BoostSegment, bgi::quadratic<16>> boundary;
  std::vector<int> skipped;
};

RoadArea::RoadArea() : impl_(std::make_shared<Impl>()) {}

RoadArea RoadArea::Build(std::span<const Lanelet> lanelets, double tolerance) {
  auto impl = std::make_shared<Impl>();
  tolerance = std::isfinite(tolerance) ? std::max(tolerance, 0.0) : 0.0;
  for (const Lanelet& lanelet : lanelets) {
    const std::vector<Vec2> ring = lanelet.Polygon();
    if (ring.size() < 3 || !std::all_of(ring.begin(), ring.end(), Finite)) {
      impl->skipped.push_back(lanelet.id);
      continue;
    }
    const BoostPolygon polygon = ToBoostPolygon(ring);
    bool united = false;
    // Boost.Geometry reports input it cannot handle with exceptions: fall back to the unbuffered
    // polygon, then to leaving the lanelet out.
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
    if (!united) impl->skipped.push_back(lanelet.id);
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
  if (!Contains(mean)) return false;
  // Inside, unless the area's boundary enters the polygon.
  BoostBox box;
  bg::envelope(ToBoostPolygon(convex), box);
  if (convex.size() < 3) {
    return impl_->boundary.qbegin(bgi::intersects(box)) == impl_->boundary.qend();
  }
  const BoostPolygon polygon = ToBoostPolygon(convex);
  for (auto it = impl_->boundary.qbegin(bgi::intersects(box)); it != impl_->boundary.qend();
       ++it) {
    if (bg::intersects(*it, polygon)) return false;
  }
  return true;
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

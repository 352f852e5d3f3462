// Boost.Geometry adapters for the commonroad module (private: public headers stay free of Boost).
#pragma once

#include <span>

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/register/point.hpp>

#include "frenetic/commonroad/geometry.h"

BOOST_GEOMETRY_REGISTER_POINT_2D(frenetic::commonroad::Vec2, double,
                                 boost::geometry::cs::cartesian, x, y)

namespace frenetic::commonroad {

// Clockwise, closed (Boost's defaults).
using BoostPolygon = boost::geometry::model::polygon<Vec2>;
using BoostMultiPolygon = boost::geometry::model::multi_polygon<BoostPolygon>;
using BoostBox = boost::geometry::model::box<Vec2>;
using BoostSegment = boost::geometry::model::segment<Vec2>;

// The vertices as a Boost polygon, closed and wound clockwise (boost::geometry::correct).
inline BoostPolygon ToBoostPolygon(std::span<const Vec2> vertices) {
  BoostPolygon polygon;
  polygon.outer().assign(vertices.begin(), vertices.end());
  boost::geometry::correct(polygon);
  return polygon;
}

}  // namespace frenetic::commonroad

#include "frenetic/commonroad/shape.h"

#include <algorithm>
#include <cmath>

namespace frenetic::commonroad {

Shape Shape::Rectangle(double length, double width, Vec2 center, double orientation) {
  Shape s;
  s.kind = Kind::kRectangle;
  s.length = length;
  s.width = width;
  s.center = center;
  s.orientation = orientation;
  return s;
}

Shape Shape::Circle(double radius, Vec2 center) {
  Shape s;
  s.kind = Kind::kCircle;
  s.radius = radius;
  s.center = center;
  return s;
}

Shape Shape::Polygon(std::vector<Vec2> points) {
  Shape s;
  s.kind = Kind::kPolygon;
  s.points = std::move(points);
  return s;
}

bool Shape::Contains(Vec2 point) const {
  switch (kind) {
    case Kind::kRectangle: {
      const Vec2 d = point - center;
      const double c = std::cos(orientation), s = std::sin(orientation);
      const double along = c * d.x + s * d.y, across = -s * d.x + c * d.y;
      return std::abs(along) <= length / 2 && std::abs(across) <= width / 2;
    }
    case Kind::kCircle:
      return Distance(point, center) <= radius;
    case Kind::kPolygon:
      return PolygonContains(points, point);
  }
  return false;
}

Shape Shape::Transformed(Vec2 translation, double rotation) const {
  const double c = std::cos(rotation), s = std::sin(rotation);
  auto move = [&](Vec2 p) { return Vec2{c * p.x - s * p.y, s * p.x + c * p.y} + translation; };
  Shape out = *this;
  out.center = move(center);
  if (kind == Kind::kRectangle) out.orientation = orientation + rotation;
  for (Vec2& p : out.points) p = move(p);
  return out;
}

std::vector<Vec2> Shape::Vertices() const {
  if (kind == Kind::kRectangle) {
    const auto corners = BoxCorners(center, orientation, length, width);
    return {corners.begin(), corners.end()};
  }
  if (kind == Kind::kPolygon) return points;
  return {};
}

Vec2 Shape::Centroid() const {
  if (kind != Kind::kPolygon) return center;
  Vec2 sum;
  for (const Vec2& p : points) sum = sum + p;
  return points.empty() ? Vec2{} : (1.0 / points.size()) * sum;
}

double Shape::BoundingRadius() const {
  switch (kind) {
    case Kind::kRectangle:
      return std::hypot(length, width) / 2;
    case Kind::kCircle:
      return radius;
    case Kind::kPolygon: {
      const Vec2 c = Centroid();
      double r = 0;
      for (const Vec2& p : points) r = std::max(r, Distance(p, c));
      return r;
    }
  }
  return 0;
}

bool ShapeGroup::Contains(Vec2 point) const {
  return std::any_of(shapes.begin(), shapes.end(),
                     [&](const Shape& s) { return s.Contains(point); });
}

ShapeGroup ShapeGroup::Transformed(Vec2 translation, double rotation) const {
  ShapeGroup out;
  out.shapes.reserve(shapes.size());
  for (const Shape& s : shapes) out.shapes.push_back(s.Transformed(translation, rotation));
  return out;
}

bool ShapeGroup::Overlaps(std::span<const Vec2> polygon) const {
  for (const Shape& s : shapes) {
    if (s.kind == Shape::Kind::kCircle) {
      if (PolygonDistance(polygon, s.center) <= s.radius) return true;
    } else if (PolygonsOverlap(s.Vertices(), polygon)) {
      return true;
    }
  }
  return false;
}

Vec2 ShapeGroup::Centroid() const {
  Vec2 sum;
  for (const Shape& s : shapes) sum = sum + s.Centroid();
  return shapes.empty() ? Vec2{} : (1.0 / shapes.size()) * sum;
}

}  // namespace frenetic::commonroad

#include "frenetic/commonroad/shape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

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

namespace {

double Dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
double Cross(Vec2 o, Vec2 a, Vec2 b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// The convex hull, counter-clockwise, without collinear or repeated points (Andrew's monotone
// chain).
std::vector<Vec2> ConvexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(),
            [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Vec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

// The box with axes u (unit) and its left normal around the points' extents along them, its
// heading the axis direction (of u, n, -u, -n) nearest `reference`.
OrientedBox BoxOnAxes(Vec2 u, double lo_u, double hi_u, double lo_n, double hi_n,
                      double reference) {
  const Vec2 n{-u.y, u.x};
  OrientedBox box;
  box.center = (0.5 * (lo_u + hi_u)) * u + (0.5 * (lo_n + hi_n)) * n;
  const double base = std::atan2(u.y, u.x);
  int best = 0;
  double best_off = std::abs(WrapAngle(base - reference));
  for (int q = 1; q < 4; ++q) {
    const double off = std::abs(WrapAngle(base + q * 0.5 * std::numbers::pi - reference));
    if (off < best_off) {
      best = q;
      best_off = off;
    }
  }
  box.heading = WrapAngle(base + best * 0.5 * std::numbers::pi);
  box.length = best % 2 == 0 ? hi_u - lo_u : hi_n - lo_n;
  box.width = best % 2 == 0 ? hi_n - lo_n : hi_u - lo_u;
  return box;
}

}  // namespace

OrientedBox ShapeGroup::BoundingBox(double reference_heading) const {
  std::vector<Vec2> points;
  for (const Shape& s : shapes) {
    if (s.kind == Shape::Kind::kCircle) {
      constexpr int kSides = 16;
      const double r = s.radius / std::cos(std::numbers::pi / kSides);
      for (int i = 0; i < kSides; ++i) {
        const double a = 2 * std::numbers::pi * i / kSides;
        points.push_back(s.center + Vec2{r * std::cos(a), r * std::sin(a)});
      }
    } else {
      for (const Vec2& v : s.Vertices()) points.push_back(v);
    }
  }
  std::erase_if(points, [](Vec2 p) { return !std::isfinite(p.x) || !std::isfinite(p.y); });
  const std::vector<Vec2> hull = ConvexHull(std::move(points));
  const size_t h = hull.size();
  if (h == 0) return BoxOnAxes({1, 0}, 0, 0, 0, 0, reference_heading);
  if (h == 1) {
    return BoxOnAxes({1, 0}, hull[0].x, hull[0].x, hull[0].y, hull[0].y, reference_heading);
  }
  auto unit = [](Vec2 d) { return (1.0 / Norm(d)) * d; };
  if (h == 2) {
    const Vec2 u = unit(hull[1] - hull[0]), n{-u.y, u.x};
    return BoxOnAxes(u, Dot(hull[0], u), Dot(hull[1], u), Dot(hull[0], n), Dot(hull[0], n),
                     reference_heading);
  }
  // Rotating calipers (Toussaint, "Solving geometric problems with the rotating calipers", 1983):
  // the smallest box has a side on a hull edge; for each edge in turn the farthest points along
  // it, against it and away from it only move forward around the hull.
  auto next = [h](size_t i) { return i + 1 == h ? 0 : i + 1; };
  size_t hi_u = 0, lo_u = 0, far = 0;
  double best_area = std::numeric_limits<double>::infinity();
  OrientedBox best;
  for (size_t i = 0; i < h; ++i) {
    const Vec2 u = unit(hull[next(i)] - hull[i]), n{-u.y, u.x};
    if (i == 0) {
      for (size_t j = 1; j < h; ++j) {
        if (Dot(hull[j], u) > Dot(hull[hi_u], u)) hi_u = j;
        if (Dot(hull[j], u) < Dot(hull[lo_u], u)) lo_u = j;
        if (Dot(hull[j], n) > Dot(hull[far], n)) far = j;
      }
    } else {
      for (size_t step = 0; step < h && Dot(hull[next(hi_u)], u) > Dot(hull[hi_u], u); ++step) {
        hi_u = next(hi_u);
      }
      for (size_t step = 0; step < h && Dot(hull[next(lo_u)], u) < Dot(hull[lo_u], u); ++step) {
        lo_u = next(lo_u);
      }
      for (size_t step = 0; step < h && Dot(hull[next(far)], n) > Dot(hull[far], n); ++step) {
        far = next(far);
      }
    }
    const double a0 = Dot(hull[lo_u], u), a1 = Dot(hull[hi_u], u);
    const double b0 = Dot(hull[i], n), b1 = Dot(hull[far], n);
    const double area = (a1 - a0) * (b1 - b0);
    if (area < best_area) {
      best_area = area;
      best = BoxOnAxes(u, a0, a1, b0, b1, reference_heading);
    }
  }
  return best;
}

Vec2 ShapeGroup::Centroid() const {
  Vec2 sum;
  for (const Shape& s : shapes) sum = sum + s.Centroid();
  return shapes.empty() ? Vec2{} : (1.0 / shapes.size()) * sum;
}

}  // namespace frenetic::commonroad

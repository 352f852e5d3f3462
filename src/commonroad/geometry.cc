#include "frenetic/commonroad/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "commonroad/boost_geometry.h"

namespace frenetic::commonroad {

double Norm(Vec2 a) { return std::hypot(a.x, a.y); }
double Distance(Vec2 a, Vec2 b) { return Norm(a - b); }

double WrapAngle(double angle) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  double w = std::fmod(angle + std::numbers::pi, kTwoPi);
  if (w < 0) w += kTwoPi;
  return w - std::numbers::pi;
}

bool AngleInInterval(double angle, double start, double end) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  if (!std::isfinite(angle) || !std::isfinite(start) || !std::isfinite(end) || end < start) {
    return false;
  }
  if (end - start >= kTwoPi) return true;
  double offset = std::fmod(angle - start, kTwoPi);
  if (offset < 0) offset += kTwoPi;
  // An angle a hair below `start` wraps to nearly 2 pi: it lies on the interval's start.
  constexpr double kEps = 1e-12;
  return offset <= end - start + kEps || offset >= kTwoPi - kEps;
}

std::vector<Vec2> CleanPolyline(std::span<const Vec2> points) {
  std::vector<Vec2> out;
  out.reserve(points.size());
  for (const Vec2& p : points) {
    if (out.empty() || !(Distance(out.back(), p) < 1e-9)) out.push_back(p);
  }
  return out;
}

double PolylineLength(std::span<const Vec2> points) {
  double length = 0;
  for (size_t i = 1; i < points.size(); ++i) length += Distance(points[i - 1], points[i]);
  return length;
}

std::vector<Vec2> ResamplePolyline(std::span<const Vec2> points, int count) {
  count = std::max(count, 2);
  std::vector<Vec2> out;
  out.reserve(count);
  const double total = PolylineLength(points);
  if (points.size() < 2 || !(total > 0)) {
    out.assign(count, points.empty() ? Vec2{} : points.front());
    return out;
  }
  size_t seg = 1;
  double seg_start = 0;  // arc length at points[seg - 1]
  for (int k = 0; k < count; ++k) {
    const double s = total * k / (count - 1);
    while (seg + 1 < points.size() && seg_start + Distance(points[seg - 1], points[seg]) < s) {
      seg_start += Distance(points[seg - 1], points[seg]);
      ++seg;
    }
    const double len = Distance(points[seg - 1], points[seg]);
    const double t = len > 0 ? std::clamp((s - seg_start) / len, 0.0, 1.0) : 0.0;
    out.push_back(points[seg - 1] + t * (points[seg] - points[seg - 1]));
  }
  out.back() = points.back();
  return out;
}

PolylineProjection ProjectOntoPolyline(std::span<const Vec2> points, Vec2 p) {
  const std::vector<Vec2> line = CleanPolyline(points);
  PolylineProjection best;
  if (line.size() < 2) {
    best.d = line.empty() ? Norm(p) : Distance(line.front(), p);
    return best;
  }
  double best_dist = std::numeric_limits<double>::infinity();
  double s_start = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    const Vec2 a = line[i - 1], seg = line[i] - a;
    const double len = Norm(seg);
    const Vec2 u = (1.0 / len) * seg;
    const Vec2 ap = p - a;
    double t = u.x * ap.x + u.y * ap.y;  // along the segment, m
    // Clamp to the segment, except beyond the polyline's ends.
    const double lo = i == 1 ? -std::numeric_limits<double>::infinity() : 0.0;
    const double hi = i + 1 == line.size() ? std::numeric_limits<double>::infinity() : len;
    t = std::clamp(t, lo, hi);
    const Vec2 foot = a + t * u;
    const double dist = Distance(foot, p);
    if (dist < best_dist) {
      best_dist = dist;
      best.s = s_start + t;
      best.d = u.x * ap.y - u.y * ap.x;
      best.heading = std::atan2(u.y, u.x);
    }
    s_start += len;
  }
  return best;
}

std::array<Vec2, 4> BoxCorners(Vec2 center, double orientation, double length, double width) {
  const Vec2 u{std::cos(orientation), std::sin(orientation)};
  const Vec2 n{-u.y, u.x};
  const Vec2 a = (length / 2) * u, b = (width / 2) * n;
  return {center - a - b, center + a - b, center + a + b, center - a + b};
}

namespace {

bool AllFinite(std::span<const Vec2> points) {
  return std::all_of(points.begin(), points.end(),
                     [](const Vec2& p) { return std::isfinite(p.x) && std::isfinite(p.y); });
}

}  // namespace

bool PolygonContains(std::span<const Vec2> polygon, Vec2 point) {
  if (polygon.size() < 3 || !AllFinite(polygon) || !std::isfinite(point.x) ||
      !std::isfinite(point.y)) {
    return false;
  }
  return boost::geometry::covered_by(point, ToBoostPolygon(polygon));
}

bool PolygonsOverlap(std::span<const Vec2> a, std::span<const Vec2> b) {
  if (a.size() < 3 || b.size() < 3 || !AllFinite(a) || !AllFinite(b)) return false;
  return boost::geometry::intersects(ToBoostPolygon(a), ToBoostPolygon(b));
}

double PolygonDistance(std::span<const Vec2> polygon, Vec2 point) {
  if (polygon.size() < 3 || !AllFinite(polygon) || !std::isfinite(point.x) ||
      !std::isfinite(point.y)) {
    return std::numeric_limits<double>::infinity();
  }
  return boost::geometry::distance(point, ToBoostPolygon(polygon));
}

}  // namespace frenetic::commonroad

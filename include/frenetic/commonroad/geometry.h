// Planar geometry for CommonRoad scenarios: points, polylines, polygons and oriented boxes in the
// scenario's Cartesian frame (metres, angles in radians counter-clockwise from +x). The polygon
// tests run on Boost.Geometry; none of these functions throws or aborts on NaN input (a NaN point
// is never inside anything and overlaps nothing).
#pragma once

#include <array>
#include <span>
#include <vector>

namespace frenetic::commonroad {

struct Vec2 {
  double x = 0, y = 0;
};
inline Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
inline Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
inline Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
inline bool operator==(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }
double Norm(Vec2 a);
double Distance(Vec2 a, Vec2 b);

// The angle wrapped into [-pi, pi).
double WrapAngle(double angle);
// True when `angle` lies in [start, end] modulo 2 pi (CommonRoad's AngleInterval): the interval
// runs counter-clockwise from start; one of 2 pi or more contains every angle.
bool AngleInInterval(double angle, double start, double end);

// The points with consecutive repeats (closer than 1e-9 m) dropped; the first point is kept.
std::vector<Vec2> CleanPolyline(std::span<const Vec2> points);
// Sum of the segment lengths, m.
double PolylineLength(std::span<const Vec2> points);
// `count` >= 2 points at equal arc-length fractions along the polyline (its ends included). A
// polyline of fewer than two distinct points gives `count` copies of its first point (or of the
// origin when empty).
std::vector<Vec2> ResamplePolyline(std::span<const Vec2> points, int count);

// Where a point lies relative to a polyline: arc length s of its foot point (m, negative before
// the start / beyond the length after the end: the end segments are extended), signed lateral
// offset d (m, positive to the left of the direction of travel) and the polyline's heading there
// (rad). A polyline of fewer than two distinct points gives s = 0, d = the distance, heading 0.
struct PolylineProjection {
  double s = 0, d = 0, heading = 0;
};
PolylineProjection ProjectOntoPolyline(std::span<const Vec2> points, Vec2 p);

// The corners of an oriented rectangle (centre, heading along `length`), counter-clockwise from
// the rear right corner.
std::array<Vec2, 4> BoxCorners(Vec2 center, double orientation, double length, double width);

// Closed polygons are given by their vertices without the closing repeat, in either winding;
// they may be non-convex and may repeat a vertex. Boundaries count as inside / overlapping.
bool PolygonContains(std::span<const Vec2> polygon, Vec2 point);
bool PolygonsOverlap(std::span<const Vec2> a, std::span<const Vec2> b);
// Distance from the point to the polygon's area (0 inside), m.
double PolygonDistance(std::span<const Vec2> polygon, Vec2 point);

}  // namespace frenetic::commonroad

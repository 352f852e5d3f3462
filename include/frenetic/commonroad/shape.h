// CommonRoad shapes (format 2020a: rectangle, circle, polygon) and shape groups. An obstacle's
// shape is given in the obstacle's own frame (centred on its state's position, heading along +x)
// and placed with Transformed(); goal regions and uncertain positions are given in the scenario
// frame. Lengths in metres, angles in radians.
#pragma once

#include <span>
#include <vector>

#include "frenetic/commonroad/geometry.h"

namespace frenetic::commonroad {

// An oriented rectangle: centre, heading (rad, counter-clockwise from +x, along `length`), length
// and width (m).
struct OrientedBox {
  Vec2 center;
  double heading = 0, length = 0, width = 0;
};

struct Shape {
  enum class Kind { kRectangle, kCircle, kPolygon };
  Kind kind = Kind::kRectangle;
  // Rectangle: length along `orientation`, width across it, centred on `center`.
  double length = 0, width = 0, orientation = 0;
  // Circle.
  double radius = 0;
  Vec2 center;             // rectangle and circle
  std::vector<Vec2> points;  // polygon: vertices without the closing repeat (at least 3)

  static Shape Rectangle(double length, double width, Vec2 center = {}, double orientation = 0);
  static Shape Circle(double radius, Vec2 center = {});
  static Shape Polygon(std::vector<Vec2> points);

  // True when the point lies inside or on the boundary.
  bool Contains(Vec2 point) const;
  // The shape rotated by `rotation` about the origin, then moved by `translation`.
  Shape Transformed(Vec2 translation, double rotation) const;
  // The rectangle's corners or the polygon's vertices (a circle gives none).
  std::vector<Vec2> Vertices() const;
  // The centre of the rectangle or circle, the vertex mean of a polygon.
  Vec2 Centroid() const;
  // Radius of a circle about Centroid() that holds the whole shape.
  double BoundingRadius() const;
};

// Several shapes that act as one (the union): an obstacle's <shape> or a goal's <position> may
// list more than one.
struct ShapeGroup {
  std::vector<Shape> shapes;

  bool Contains(Vec2 point) const;
  ShapeGroup Transformed(Vec2 translation, double rotation) const;
  // True when any member overlaps the convex or non-convex polygon (touching counts).
  bool Overlaps(std::span<const Vec2> polygon) const;
  // The mean of the members' centroids (the origin when empty).
  Vec2 Centroid() const;
  // The smallest-area rectangle that holds every member (a circle by its circumscribed 16-gon),
  // heading along whichever of its four side directions lies nearest `reference_heading` (rad),
  // its length along that heading. Collinear members give a width of 0, one point a box of
  // size 0 there; an empty group (or one without a finite vertex) a box of size 0 at the origin.
  // Non-finite vertices are ignored. O(n log n) in the vertex count.
  OrientedBox BoundingBox(double reference_heading) const;
};

}  // namespace frenetic::commonroad

// Oriented rectangles (car footprints) and their overlap test (separating axis theorem). Works
// in any planar frame; the planner uses it in Frenet coordinates (s, d), where the road's
// curvature distorts boxes negligibly at car scale.
#pragma once

namespace frenetic::traj {

struct OrientedBox {
  double cx = 0, cy = 0;   // centre, m
  double heading = 0;      // rad, direction of the long side
  double half_length = 0;  // m, along heading
  double half_width = 0;   // m
};

// True when the boxes overlap (touching counts). Never fails; NaN input gives false.
bool Overlap(const OrientedBox& a, const OrientedBox& b);
// The same with each box's heading given as its unit direction (cos, sin): no trigonometry,
// for hot loops that know the direction as a velocity vector. `heading` fields are ignored.
bool Overlap(const OrientedBox& a, double cos_a, double sin_a, const OrientedBox& b,
             double cos_b, double sin_b);

}  // namespace frenetic::traj

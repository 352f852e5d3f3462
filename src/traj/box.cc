#include "frenetic/traj/box.h"

#include <cmath>

namespace frenetic::traj {
namespace {

// Half-extent of box b projected on the unit axis (ux, uy).
double Radius(const OrientedBox& b, double c, double s, double ux, double uy) {
  return b.half_length * std::abs(c * ux + s * uy) + b.half_width * std::abs(-s * ux + c * uy);
}

}  // namespace

bool Overlap(const OrientedBox& a, const OrientedBox& b) {
  return Overlap(a, std::cos(a.heading), std::sin(a.heading), b, std::cos(b.heading),
                 std::sin(b.heading));
}

bool Overlap(const OrientedBox& a, double ca, double sa, const OrientedBox& b, double cb,
             double sb) {
  const double dx = b.cx - a.cx, dy = b.cy - a.cy;
  // The four candidate separating axes are the boxes' own edge normals.
  const double axes[4][2] = {{ca, sa}, {-sa, ca}, {cb, sb}, {-sb, cb}};
  for (const auto& ax : axes) {
    const double dist = std::abs(dx * ax[0] + dy * ax[1]);
    const double ra = Radius(a, ca, sa, ax[0], ax[1]);
    const double rb = Radius(b, cb, sb, ax[0], ax[1]);
    if (!(dist <= ra + rb)) return false;  // also false for NaN
  }
  return true;
}

}  // namespace frenetic::traj

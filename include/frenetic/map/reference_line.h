// The smooth reference line: a curve fitted through a track's waypoints with Ceres (stay close
// to the waypoints, penalise change of curvature), re-parametrised by its own arc length and
// sampled densely. All Frenet conversion of the planner happens on it. d is positive to the
// right of the driving direction (the simulator's convention).
//
// Closed (a loop: the Udacity track, Fit): periodic, so smooth across the seam; s is periodic
// with period length(), s = 0 at the fit's point for waypoint 0 (the map's s is taken relative
// to waypoint 0's s).
// Open (a road with two ends: a CommonRoad lane, FitOpen): s = 0 at the first point and
// length() at the last; s is not wrapped, and beyond either end the line continues straight
// along its end tangent (ToCartesian, Centre, At and ToFrenet all extend it), so a trajectory
// that runs past the end still has coordinates.
#pragma once

#include <cmath>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "frenetic/map/track.h"
#include "frenetic/status.h"

namespace frenetic::map {

struct FrenetPoint {
  double s = 0, d = 0;  // m
};

struct CartesianPose {
  double x = 0, y = 0;  // m
  double heading = 0;   // rad, counter-clockwise from +x, the road direction at s
  // 1/m, curvature of the offset curve at (s, d), positive turning left: kappa0 / (1 + kappa0 d)
  // with kappa0 the centre line's curvature (d is to the right, so on a left curve d > 0 is the
  // outer side with the larger radius). Kept finite (|1 + kappa0 d| >= 1e-6) past the centre of
  // curvature.
  double kappa = 0;
};

// The centre line's point at some s and the unit vector along it: ToCartesian's (s, d) is
// (x + d sin, y - d cos), with d = 0 when not finite (Offset).
struct CentrePoint {
  double x = 0, y = 0;  // m
  double cos = 0, sin = 0;
  double OffsetX(double d) const { return x + (std::isfinite(d) ? d : 0.0) * sin; }
  double OffsetY(double d) const { return y - (std::isfinite(d) ? d : 0.0) * cos; }
};

// One sample of the centre line (d = 0).
struct RefSample {
  double s = 0, x = 0, y = 0, heading = 0, kappa = 0, dkappa = 0;
};

class ReferenceLine {
 public:
  struct Options {
    double sample_step = 0.5;        // m between stored samples (≤ 1)
    double control_spacing = 10.0;   // m between the fitted curve's control points
    double smoothness_weight = 1.0;  // weight of the change-of-curvature penalty
    int max_iterations = 200;        // Ceres iterations
    Status Validate() const;         // a message naming the bad option
  };

  // Fits the line. Fails (with a message) only on an unusable track or options.
  static StatusOr<std::shared_ptr<const ReferenceLine>> Fit(const Track& track,
                                                            const Options& options);
  static StatusOr<std::shared_ptr<const ReferenceLine>> Fit(const Track& track) {
    return Fit(track, Options());
  }
  // Fits an open line through a polyline (m, map frame; at least 2 distinct points, in driving
  // order; repeated points are dropped). The polyline is resampled every ~2 m and extended
  // straight by a few control spacings at both ends before the fit, so that the fitted line
  // ends straight along the polyline's end directions. Fails (naming `source`) on fewer than
  // two distinct points, non-finite coordinates, or a degenerate fit.
  struct Point {
    double x = 0, y = 0;
  };
  static StatusOr<std::shared_ptr<const ReferenceLine>> FitOpen(std::span<const Point> polyline,
                                                                const Options& options,
                                                                std::string_view source);

  bool closed() const;  // a loop (Fit) or a line with two ends (FitOpen)

  double length() const;  // loop length (≈ track max_s), or the open line's, in its arc length
  // Closed: s modulo length(), in [0, length()). Open: s itself (0 when not finite).
  double WrapS(double s) const;
  // Closed: signed s_to − s_from in [−L/2, L/2). Open: s_to − s_from.
  double DiffS(double s_to, double s_from) const;

  // Pose of the point at (s, d): x, y, heading of the road there and curvature of the offset
  // curve. Any finite s is wrapped. Never fails.
  CartesianPose ToCartesian(double s, double d) const;
  // The centre line's point at s for ToCartesian's x and y at any d (the same arithmetic): for
  // many points that share s.
  CentrePoint Centre(double s) const;
  // Projection of (x, y) onto the line (Newton steps), robust at the seam and far from the road:
  // the nearest point of the line, s in [0, length()). Exact inverse of ToCartesian (same
  // interpolants). With a hint the search walks from s_hint (~1 us; falls back to the global
  // search, ~5 us, when the walk exceeds 200 m or the answer is more than 40 m off the road).
  // Non-finite x or y gives (0, 0).
  FrenetPoint ToFrenet(double x, double y) const;
  FrenetPoint ToFrenet(double x, double y, double s_hint) const;
  // The dense sample the hinted ToFrenet walks from (-1 for a non-finite hint: the global
  // search): ToFrenet(x, y, s_hint) depends on s_hint through this index only, so two hints
  // with the same one give the same projection of every point (a caller may keep projections).
  int HintSample(double s_hint) const;

  RefSample At(double s) const;  // interpolated centre-line sample at s (wrapped)
  // The dense samples, uniformly spaced (<= sample_step) from s = 0: closed, length() /
  // samples().size() apart, the sample at length() being samples()[0]; open, length() /
  // (samples().size() - 1) apart, the last one at length().
  const std::vector<RefSample>& samples() const;

  // The simulator measures every d from the chords between waypoints (udacity-sim.md §5.3), not
  // from this line: a point at (s, d) of the line reads d + offset, where the offset is the
  // chord's distance from the line (up to ~1.3 m outward mid-segment on the Udacity map's left
  // bends). Bounds of that offset for points at d with s in [s_from, s_to] (unwrapped,
  // s_to >= s_from; at most one loop), conservative where the simulator switches chords. An open
  // line has no such quirk: {0, 0}.
  struct OffsetRange {
    double lo = 0, hi = 0;  // m
  };
  OffsetRange ChordOffset(double s_from, double s_to, double d) const;

  // Diagnostics of the fit.
  double max_waypoint_distance() const;  // largest distance from a waypoint to the line, m
  double max_map_s_difference() const;   // largest |s_line − s_map| at the waypoints, m

  ~ReferenceLine();
  struct Impl;
  struct OpenRange {
    int first = 0, last = 0;  // the waypoints of an open line's own stretch
  };
  explicit ReferenceLine(std::unique_ptr<Impl> impl);

 private:
  static StatusOr<std::shared_ptr<const ReferenceLine>> FitLine(const Track& track,
                                                                const Options& options,
                                                                const OpenRange* open);
  std::unique_ptr<Impl> impl_;
};

}  // namespace frenetic::map

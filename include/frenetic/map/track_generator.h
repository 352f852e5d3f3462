// A deterministic generator of closed highway loops in the Udacity waypoint format, used to
// produce the bundled track config/tracks/frenetic_loop.csv (`frenetic track generate`).
//
// The centre line is a star-shaped polar curve around (centre_x, centre_y):
//   r(phi) = R0 (1 + alpha * sum_k a_k cos(k phi + b_k)),  k = 2..5, phi from -pi/2 (bottom),
// with seeded amplitudes a_k and phases b_k. alpha is chosen by bisection so that the tightest
// radius of curvature is close to (never below) min_radius, R0 so that the loop is `length` m
// long. Star-shaped means the loop never crosses itself and the centre is inside it (the
// simulator's d sign test uses (1000, 2000) as the inside point: keep the default centre).
// The loop runs counter-clockwise, so the right normal (dx, dy) points outward. Waypoints are
// spaced `spacing` m (+-12 %, seeded) along the curve; s is the cumulative chord length as in the
// Udacity file, max_s is the last s plus the closing chord.
#pragma once

#include <cstdint>

#include "frenetic/map/track.h"
#include "frenetic/status.h"

namespace frenetic::map {

struct TrackGeneratorOptions {
  double length = 7000.0;       // m, loop length (arc length of the centre line), 1000..100000
  double spacing = 35.0;        // m, mean waypoint spacing, 5..200
  double min_radius = 150.0;    // m, smallest radius of curvature allowed, 20..length/(2 pi)
  uint64_t seed = 1;            // seeds the harmonics and the spacing jitter
  double centre_x = 1000.0;     // m, centre of the star-shaped loop
  double centre_y = 2000.0;     // m
  double min_clearance = 80.0;  // m, least distance between parts of the loop > 300 m apart
  Status Validate() const;      // a message naming the bad option
};

// Generates the track (source "generated"). Deterministic for given options on any platform.
// Fails with a message only on invalid options or when no shape meets min_clearance.
StatusOr<Track> GenerateTrack(const TrackGeneratorOptions& options);

}  // namespace frenetic::map

// A track: the waypoint file of the Udacity format (x y s dx dy per line, space or comma
// separated, no header), validated. Waypoints lie on the road's centre line (d = 0); (dx, dy) is
// the unit normal pointing to the right of the driving direction.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/status.h"

namespace frenetic::map {

struct Waypoint {
  double x = 0, y = 0;    // m, map frame
  double s = 0;           // m along the road from waypoint 0
  double dx = 0, dy = 0;  // unit normal, to the right of the driving direction
};

struct Track {
  std::vector<Waypoint> waypoints;
  double max_s = 0;    // loop length, m: last s plus the closing segment back to waypoint 0
  std::string source;  // file name (or a label) used in messages
};

// Parses and validates track text. Errors name `source` and the 1-based line: malformed row,
// NaN/inf, non-increasing s, fewer than 4 rows, normal not of unit length (±1e-3), duplicate
// points. `max_s` overrides the loop length computed from the closing segment.
StatusOr<Track> ParseTrack(std::string_view text, std::string_view source,
                           std::optional<double> max_s = std::nullopt);

// Reads and parses a track file.
StatusOr<Track> LoadTrack(const std::string& path, std::optional<double> max_s = std::nullopt);

// Writes a track in the Udacity format (space separated, full precision).
std::string FormatTrack(const Track& track);

// The bundled track's path (config/tracks/frenetic_loop.csv in the source tree).
std::string DefaultTrackPath();

}  // namespace frenetic::map

// The static world the simulator runs on: the track, its smooth reference line (traffic moves
// along it) and the simulator's chord-based Frenet (every reported s, d). Immutable once built,
// so one World is shared by all episodes and threads.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "frenetic/map/chord_frenet.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/status.h"

namespace frenetic::sim {

struct World {
  std::string map_path;
  map::Track track;
  std::shared_ptr<const map::ReferenceLine> line;
  std::unique_ptr<map::ChordFrenet> chord;
  std::vector<double> waypoint_line_s;  // s on `line` of every waypoint
  bool is_udacity_map = false;  // the Udacity highway_map.csv (start pose, parked cars)
};

// Builds a world from a loaded track (fits the reference line).
StatusOr<std::shared_ptr<const World>> MakeWorld(map::Track track, std::string map_path);
// Loads the track file and builds the world; errors name the file.
StatusOr<std::shared_ptr<const World>> LoadWorld(const std::string& map_path);

}  // namespace frenetic::sim

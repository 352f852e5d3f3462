#include "frenetic/sim/world.h"

#include <cmath>

namespace frenetic::sim {

StatusOr<std::shared_ptr<const World>> MakeWorld(map::Track track, std::string map_path) {
  auto line = map::ReferenceLine::Fit(track);
  if (!line.ok()) return Status::Error(map_path + ": " + line.message());
  auto world = std::make_shared<World>();
  world->map_path = std::move(map_path);
  world->line = *line;
  world->chord = std::make_unique<map::ChordFrenet>(track);
  world->waypoint_line_s.reserve(track.waypoints.size());
  for (const auto& wp : track.waypoints) {
    world->waypoint_line_s.push_back(world->line->ToFrenet(wp.x, wp.y).s);
  }
  // The Udacity map is recognised by its size, first waypoint and loop length: the start pose
  // and the parked cars of the real simulator only make sense there.
  const auto& w0 = track.waypoints.front();
  world->is_udacity_map = track.waypoints.size() == 181 && std::abs(w0.x - 784.6001) < 0.01 &&
                          std::abs(w0.y - 1135.571) < 0.01 &&
                          std::abs(track.max_s - 6945.554) < 0.01;
  world->track = std::move(track);
  return std::shared_ptr<const World>(std::move(world));
}

StatusOr<std::shared_ptr<const World>> LoadWorld(const std::string& map_path) {
  auto track = map::LoadTrack(map_path);
  if (!track.ok()) return track.status();
  return MakeWorld(std::move(*track), map_path);
}

}  // namespace frenetic::sim

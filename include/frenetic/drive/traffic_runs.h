// The simulated side of the traffic comparison of `frenetic fidelity` (eval/fidelity.h): drives
// of the headless simulator, by a planner or by a scripted ego that replays the recordings,
// sampled as the recordings are.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frenetic/eval/fidelity.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"
#include "frenetic/status.h"

namespace frenetic::sim {

struct TrafficRunOptions {
  Scenario scenario;            // its timing is forced to the random (latency) mode
  std::string planner = "baseline";  // drives the ego when `ego_profiles` is empty
  double minutes = 30;          // simulated minutes in total
  double episode_seconds = 120; // planner episodes: each starts like the recordings, from the
                                // start pose
  // Non-empty: a scripted ego replays the recordings instead of a planner. Episode i replays
  // ego_profiles[i % n] from the start pose for that profile's duration: its speed as a cap
  // (lower behind a slower car in its lane, a time-gap law; above it, up to 22 m/s, while
  // making up distance lost behind slower cars) and its lane (changing only when the target
  // lane is free beside it). Episodes are added until `minutes` are covered.
  std::vector<EgoProfile> ego_profiles;
  std::uint64_t first_seed = 1;
  int jobs = 1;                 // threads; results do not depend on it
};
// Number of episodes SimulateTraffic runs for `options` (>= 1).
int TrafficEpisodes(const TrafficRunOptions& options);
// Drives the scenario with the replayed profiles or the named planner (config from
// plan::PlannerConfig::LoadDefault or `planner_config_path` when not empty) and collects the
// statistics from the telemetry of every exchange. Fails on a bad scenario, planner,
// configuration or an empty / non-increasing profile.
StatusOr<TrafficFigures> SimulateTraffic(std::shared_ptr<const World> world,
                                         const TrafficRunOptions& options,
                                         const std::string& planner_config_path);

}  // namespace frenetic::sim

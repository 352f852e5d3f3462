// Shared helpers of the drive tests (and sim/sim_test_util.h's world and planner).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>

#include "frenetic/drive/episode.h"
#include "frenetic/sim/scenario.h"
#include "sim/sim_test_util.h"

namespace frenetic::sim::testing {

// Seed `seed` of the default scenario driven by `planner` for `seconds` s of simulated time, with
// timing off, once with `extra` applied to the options and once without: {plain, extra}.
template <typename Extra>
std::pair<StatusOr<DriveReport>, StatusOr<DriveReport>> DriveWithAndWithout(
    std::shared_ptr<const World> world, plan::Planner& planner, std::uint64_t seed, double seconds,
    Extra extra) {
  const EpisodeLimits limits{0, 0, seconds, 60};
  RunOptions off;
  off.timing = false;
  RunOptions on = off;
  extra(on);
  auto plain = RunEpisode(world, Scenario(), seed, limits, planner, off);
  auto with = RunEpisode(world, Scenario(), seed, limits, planner, on);
  return {std::move(plain), std::move(with)};
}

}  // namespace frenetic::sim::testing

// `frenetic drive --connect URL`: the headless simulator plays the Unity simulator's side over a
// real WebSocket against any Udacity-compatible planner server.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "frenetic/drive/drive_report.h"
#include "frenetic/drive/episode.h"
#include "frenetic/drive/record.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/world.h"
#include "frenetic/status.h"

namespace frenetic::apps {

struct ConnectOptions {
  std::string url;        // ws://HOST:PORT/PATH
  bool realtime = false;  // pace frames at simulated time (as the Unity simulator does)
  double timeout = 10.0;  // s for connecting and for each reply
  bool timing = true;     // false: round-trip times are reported and recorded as 0
  // When set, the drive is recorded as an in-process one is (drive/record.h), with the planner's
  // internals absent: header, one line per exchange, footer.
  sim::RecordWriter* record = nullptr;
  // Judge every incident (sim::JudgeObserver, drive/evaluators.h); unset: off.
  std::optional<sim::JudgeOptions> judge;
};

// Drives one episode over the network. The report's planning times are round-trip times per
// exchange (telemetry sent to reply received), measured on this side; its planner is "remote"
// and its plan_fallbacks the manual replies.
StatusOr<sim::DriveReport> DriveOverNetwork(std::shared_ptr<const sim::World> world,
                                            const sim::Scenario& scenario, std::uint64_t seed,
                                            const sim::EpisodeLimits& limits,
                                            const ConnectOptions& options);

}  // namespace frenetic::apps

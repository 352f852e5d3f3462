// What looks on at a drive without changing it: the record writer (drive/record.h), the incident
// judge and the oracle search (drive/evaluators.h) attach to an Episode (drive/episode.h) as
// observers, and see its start, every tick (if they ask), every exchange and its end.
#pragma once

#include <cstddef>
#include <span>
#include <string_view>

#include "frenetic/plan/planner.h"
#include "frenetic/status.h"

namespace frenetic::sim {

class Episode;
class Simulator;
struct DriveReport;

// How the path of one exchange was made, as the one who made it tells the observers
// (Episode::Submit); the episode itself only applies the path.
struct ExchangeReply {
  // In process: the planner's result (its path as planned, before the wire's rounding) and the
  // trace of its candidates (null when not traced). Over the network: null.
  const plan::PlanResult* plan = nullptr;
  const plan::CycleTrace* trace = nullptr;
  // Over the network: the path received (m, map frame; empty for a manual reply) and the
  // reply's kind, "control" or "manual".
  std::span<const double> path_x, path_y;
  std::string_view kind;
  double ms = 0;  // planning time (in process) or round trip (network), ms
};

// One exchange, as the observers see it once Episode::Submit has run its ticks.
struct Exchange {
  int index = 0;                   // 0-based: Episode::exchanges() before it
  double t_sent = 0;               // s, simulated time of the telemetry it answered
  std::size_t first_incident = 0;  // its incidents: the monitor's log from this index on
  const ExchangeReply* reply = nullptr;  // never null
};

// The hooks are called in the order the observers were attached (Episode::Attach); each has a
// default that does nothing. An observer only reads the episode: the drive is the same with or
// without it.
class EpisodeObserver {
 public:
  virtual ~EpisodeObserver() = default;

  // Once, when attached, before the first exchange: episode.telemetry() is the first one sent.
  virtual void OnStart(const Episode& /*episode*/) {}
  // True: OnTick after every physics tick (the episode then advances one tick at a time).
  // Asked once, when attached.
  virtual bool wants_ticks() const { return false; }
  virtual void OnTick(const Simulator& /*sim*/) {}
  // After every exchange: the episode holds the next telemetry, last_l_old() / last_l_new() and
  // done() of this one.
  virtual void OnExchange(const Episode& /*episode*/, const Exchange& /*exchange*/) {}
  // Once, when the drive's report is made (Episode::Finish): adds what the observer found to
  // `report` (observers attached later see it) and returns its own failure, e.g. a record that
  // could not be written.
  virtual Status OnEnd(const Episode& /*episode*/, DriveReport* /*report*/) {
    return Status::Ok();
  }
};

}  // namespace frenetic::sim

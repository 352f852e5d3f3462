// Which cycles' candidates a report keeps (internal to record): a bounded, evenly spread set,
// chosen while the record streams by, plus the cycles that explain an incident or a lane change.
#pragma once

#include <deque>
#include <map>
#include <set>
#include <vector>

#include "frenetic/record/reader.h"

namespace frenetic::record {

// Cycles before an incident whose candidates are kept with it: the decision that led to an
// incident is usually made a few cycles earlier.
inline constexpr int kCyclesBeforeIncident = 5;

// Keeps every stride-th cycle (the stride doubles whenever more than `max_cycles` cycles are
// kept besides the pinned ones, so the kept cycles stay evenly spread whatever the run's
// length), and pins on top of these, each kind with its own budget of `max_cycles` (so a run
// full of lane changes cannot crowd out the cycles that explain an incident): a cycle with an
// incident and the kCyclesBeforeIncident cycles before it, newest first; a cycle where the
// winner's lane changes. Cycles are offered in exchange order.
class CandidateSampler {
 public:
  explicit CandidateSampler(int max_cycles) : max_cycles_(max_cycles) {}

  // A cycle whose plan listed candidates (cycle.exchange is its exchange). `incident`: an
  // incident was recorded at this exchange; `lane_change`: the winner's lane differs from the
  // previous exchange's.
  void Add(CycleCandidates cycle, bool incident, bool lane_change);
  // A cycle that listed none: with an incident, the cycles before it are pinned all the same.
  void AddWithoutCandidates(bool incident);

  // The kept cycles in exchange order; the sampler is left empty.
  std::vector<CycleCandidates> Take();

 private:
  void PinRecent();
  void Thin();

  int max_cycles_;
  int stride_ = 1;
  int lane_pins_ = 0, incident_pins_ = 0;
  std::map<int, CycleCandidates> kept_;
  std::set<int> pinned_;
  std::deque<CycleCandidates> recent_;
};

}  // namespace frenetic::record

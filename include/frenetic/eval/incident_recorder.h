// Keeps, during a drive, what the incident judge needs and judges every incident once its margin
// has been driven: a ring of the last window + 0.2 s of ticks (the ego as measured, every
// spawned car's box and Frenet, whether a flag was up) and of the monitor at every 0.2 s block;
// an incident opens a case with the ring's copy and keeps adding ticks to it for the margin (the
// drive goes on after an incident). It only reads the simulator, so the drive is unchanged.
#pragma once

#include <cstdint>
#include <vector>

#include "frenetic/eval/incident_judge.h"
#include "frenetic/sim/simulator.h"

namespace frenetic::sim {

class IncidentRecorder {
 public:
  // `sim` is the drive's simulator; it must outlive the recorder. timing false: judging times
  // are reported as 0 (byte-stable reports).
  IncidentRecorder(const Simulator& sim, const JudgeOptions& options, bool timing);

  // After every physics tick of `sim` (Simulator::Advance(1)).
  void AfterTick();
  // The drive ended: judges the cases still open with the ticks driven (a shorter margin).
  void Finish();

  // One per incident of the monitor's log judged so far, in log order.
  const std::vector<IncidentJudgement>& judgements() const { return judgements_; }
  // Keep every judged case (cases(), in the same order) instead of dropping it once judged.
  void set_keep_cases(bool keep) { keep_cases_ = keep; }
  const std::vector<IncidentCase>& cases() const { return kept_; }

 private:
  void Judge(IncidentCase& c);

  const Simulator& sim_;
  JudgeOptions options_;
  bool timing_;
  int ring_ticks_;                // ticks kept: the window, one block of history, the start tick
  int cars_per_tick_;             // the traffic's car count
  std::int64_t first_tick_ = -1;  // the first tick recorded
  std::vector<RecordedEgo> ego_ring_;
  std::vector<RecordedCar> car_ring_;  // ring_ticks_ x cars_per_tick_
  std::vector<int> car_count_;
  std::vector<IncidentMonitor> monitor_ring_;  // one per block tick in the ring
  std::vector<std::int64_t> monitor_tick_;
  std::vector<int> last_spawns_;  // per car id: its spawn count on the last tick
  std::vector<RecordedCar> tick_cars_;
  std::size_t incidents_seen_ = 0;
  std::vector<IncidentCase> open_;  // incidents whose margin is still being driven
  std::vector<IncidentJudgement> judgements_;
  bool keep_cases_ = false;
  std::vector<IncidentCase> kept_;
};

}  // namespace frenetic::sim

// The offline evaluators (eval/) attached to a drive as episode observers (episode_observer.h):
// the incident judge and the oracle search. Neither changes the drive; each adds its findings to
// the drive's report. RunOptions::judge / ::oracle attach them to RunEpisode's drives.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "frenetic/drive/episode_observer.h"
#include "frenetic/eval/incident_judge.h"
#include "frenetic/eval/oracle.h"
#include "frenetic/plan/telemetry.h"

namespace frenetic::sim {

class IncidentRecorder;  // eval/incident_recorder.h

// Keeps the traffic's history from the start and judges every incident (eval/incident_judge.h)
// once its margin is driven, or when the drive ends (the open cases then with a shorter margin);
// the report gets every judgement (DriveReport::judged, ::judgements).
class JudgeObserver final : public EpisodeObserver {
 public:
  // `options` must be valid (JudgeOptions::Validate). timing false: judging times are reported
  // as 0 (byte-stable reports).
  JudgeObserver(const JudgeOptions& options, bool timing);
  ~JudgeObserver() override;

  void OnStart(const Episode& episode) override;
  bool wants_ticks() const override { return true; }
  void OnTick(const Simulator& sim) override;
  void OnExchange(const Episode& episode, const Exchange& exchange) override;
  Status OnEnd(const Episode& episode, DriveReport* report) override;

 private:
  JudgeOptions options_;
  bool timing_;
  std::unique_ptr<IncidentRecorder> recorder_;  // from OnStart
};

// Samples the ego and the traffic at the start and after every exchange, and after the drive
// searches how far any planner could have driven against that traffic (eval/oracle.h;
// DriveReport::oracle_run, ::oracle).
class OracleObserver final : public EpisodeObserver {
 public:
  explicit OracleObserver(const OracleOptions& options);  // valid (OracleOptions::Validate)

  void OnStart(const Episode& episode) override;
  void OnExchange(const Episode& episode, const Exchange& exchange) override;
  Status OnEnd(const Episode& episode, DriveReport* report) override;

 private:
  void Sample(const Episode& episode);

  OracleOptions options_;
  std::optional<OracleTrace> trace_;  // from OnStart
  std::vector<plan::SensorCar> cars_;
};

}  // namespace frenetic::sim

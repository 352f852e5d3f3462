#include "frenetic/drive/evaluators.h"

#include "frenetic/drive/drive_report.h"
#include "frenetic/drive/episode.h"
#include "frenetic/eval/incident_recorder.h"

namespace frenetic::sim {

JudgeObserver::JudgeObserver(const JudgeOptions& options, bool timing)
    : options_(options), timing_(timing) {}

JudgeObserver::~JudgeObserver() = default;

void JudgeObserver::OnStart(const Episode& episode) {
  recorder_ = std::make_unique<IncidentRecorder>(episode.sim(), options_, timing_);
}

void JudgeObserver::OnTick(const Simulator& /*sim*/) { recorder_->AfterTick(); }

void JudgeObserver::OnExchange(const Episode& episode, const Exchange& /*exchange*/) {
  if (episode.done()) recorder_->Finish();
}

Status JudgeObserver::OnEnd(const Episode& /*episode*/, DriveReport* report) {
  report->judged = true;
  report->judgements = recorder_->judgements();
  return Status::Ok();
}

OracleObserver::OracleObserver(const OracleOptions& options) : options_(options) {}

void OracleObserver::OnStart(const Episode& episode) {
  trace_.emplace(episode.sim().world().track.max_s);
  Sample(episode);
}

void OracleObserver::OnExchange(const Episode& episode, const Exchange& /*exchange*/) {
  Sample(episode);
}

Status OracleObserver::OnEnd(const Episode& /*episode*/, DriveReport* report) {
  report->oracle_run = true;
  report->oracle = SearchOracle(*trace_, options_);
  return Status::Ok();
}

void OracleObserver::Sample(const Episode& episode) {
  const plan::Telemetry& t = episode.telemetry();
  // A row at the seam may read s = d = 0 (udacity-sim.md §8.6): its Frenet from x, y instead.
  cars_.assign(t.sensor_fusion.begin(), t.sensor_fusion.end());
  for (plan::SensorCar& c : cars_) {
    if (c.s != 0 || c.d != 0) continue;
    const map::FrenetPoint f = episode.sim().world().line->ToFrenet(c.x, c.y, t.s);
    c.s = f.s;
    c.d = f.d;
  }
  trace_->Add(episode.sim().time(), t.s, t.d, t.speed, cars_);
}

}  // namespace frenetic::sim

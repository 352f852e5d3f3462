// The drive record (`frenetic drive --record run.jsonl.gz`, the format of record/schema.h): the
// header from the simulator, one exchange line per exchange with the simulator's measures after
// it, the footer from the drive's report, written by a record::Writer (its own thread, gzip
// when the name ends in ".gz") as an observer of the episode (episode_observer.h). With timing
// off every time field is 0, so the same seed gives byte-identical files.
//
// The path sent (path.x/y) keeps 0.1 mm. Tracing the candidates costs the planner ~13% of its
// time; with TraceByReplay a replica of the planner traces them on the writer's thread instead
// (record/replica.h), and the planner that drives does not trace at all.
//
// A drive over the network (`frenetic drive --connect URL --record run.jsonl.gz`) is recorded the
// same way, with what only an in-process planner knows left out: the header's planner is
// "remote" (config null, the URL in "connect"), and each exchange's plan holds only "status" (the
// reply's kind: "control" or "manual") and "ms_total" (the round trip); candidate counts, cost
// terms, rejections and traces are absent, which `frenetic report` shows as unknown.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/drive/drive_report.h"
#include "frenetic/drive/episode_observer.h"
#include "frenetic/plan/planner.h"
#include "frenetic/record/replica.h"
#include "frenetic/record/writer.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/status.h"

namespace frenetic::sim {

class RecordWriter final : public EpisodeObserver {
 public:
  // Opens (truncates) the file, gzip-compressed when `path` ends in ".gz"; an error names it.
  static StatusOr<std::unique_ptr<RecordWriter>> Open(const std::string& path);
  // Writes what is queued, ends the stream and closes the file.
  ~RecordWriter() override;
  RecordWriter(const RecordWriter&) = delete;
  RecordWriter& operator=(const RecordWriter&) = delete;

  // Candidates (and the candidate counts) are traced by `replica`, a planner made as the one
  // that drives (record::Replica): the driving planner then needs no trace
  // (sim::RunOptions::trace_candidates = 0) and only its timings are written. Call before
  // attaching.
  void TraceByReplay(std::unique_ptr<plan::Planner> replica, int max_candidates);
  // What the header names: the planner, its configuration (JSON object, or its text as a
  // string) and `connect_url`, the planner server of a drive over the network (written when not
  // empty). Call before attaching.
  void set_planner(std::string name, nlohmann::json config, std::string connect_url = {});
  // Waits until everything queued is in the file; Ok unless a write failed (the message names
  // the file and why).
  Status status() { return writer_->status(); }
  void set_timing(bool timing) { timing_ = timing; }

  // As an observer (Episode::Attach): the header at the start, a line per exchange (the
  // in-process kind when the reply has a plan, else the remote kind), the footer from the report
  // at the end (attach it after the observers that add to the report); OnEnd returns status().
  void OnStart(const Episode& episode) override;
  void OnExchange(const Episode& episode, const Exchange& exchange) override;
  Status OnEnd(const Episode& episode, DriveReport* report) override;

 private:
  explicit RecordWriter(std::unique_ptr<record::Writer> writer);

  void WriteHeader(const Simulator& sim, const std::string& planner_name,
                   const nlohmann::json& config, std::string_view connect_url);
  // One exchange: the telemetry sent, the reply and how it was made, the metrics after it and
  // the incidents that started since the previous exchange (log indices [first, end)).
  // `telemetry_json` is wire::TelemetryToJson of the telemetry sent at simulated time t;
  // l_old / l_new are the ticks run before and after the path was applied.
  void WriteExchange(int index, double t, const std::string& telemetry_json,
                     const plan::PlanResult& result, const plan::CycleTrace* trace,
                     double plan_ms, const Simulator& sim, std::size_t first_incident,
                     int l_old, int l_new);
  // One exchange with a remote planner: the path received (m, map frame; empty for a manual
  // reply), `reply` "control" or "manual", the round trip in ms; the rest as WriteExchange.
  void WriteRemoteExchange(int index, double t, const std::string& telemetry_json,
                           std::span<const double> path_x, std::span<const double> path_y,
                           std::string_view reply, double round_trip_ms, const Simulator& sim,
                           std::size_t first_incident, int l_old, int l_new);
  // The last line: the stream is ended after it (later writes are ignored).
  void WriteFooter(const DriveReport& report);

  std::unique_ptr<record::Writer> writer_;
  // Used on the writer's thread only, by the exchange lines (null: the planner traces).
  std::shared_ptr<record::Replica> replica_;
  bool timing_ = true;
  std::string planner_name_, connect_url_;
  nlohmann::json planner_config_;
  std::string telemetry_json_;  // wire::TelemetryToJson of the telemetry being answered
};

}  // namespace frenetic::sim

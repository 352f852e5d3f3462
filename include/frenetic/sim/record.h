// The drive record (`frenetic drive --record run.jsonl.gz`): JSON lines, enough to replay and
// explain a run. First line {"type":"header",...}, then one {"type":"exchange",...} per
// exchange, last line {"type":"footer","report":{...}}. With timing off every time field is 0,
// so the same seed gives byte-identical files. A path ending in ".gz" is written as one gzip
// stream of those lines (zlib; `zcat` shows the text; ~11 MB for a lap instead of ~95 MB),
// any other path as plain text; `frenetic report` reads both.
//
// Candidate paths (plan.candidates[].x/y, a point every ~0.25 s, for drawing) are written at
// 0.1 m, as `frenetic report` draws them: their digits beyond that were most of the file. The
// path sent (path.x/y) keeps 0.1 mm.
//
// Writing costs the planning thread a copy of the exchange's values: the lines are formatted,
// compressed and written by a thread of the writer's own, at low priority, in order. A status()
// call waits for everything queued to be written. Tracing the candidates costs the planner ~13%
// of its time; with TraceByReplay a replica of the planner traces them on the writer's thread
// instead, and the planner that drives does not trace at all.
//
// A drive over the network (`frenetic drive --connect URL --record run.jsonl.gz`) is recorded the
// same way, with what only an in-process planner knows left out: the header's planner is
// "remote" (config null, the URL in "connect"), and each exchange's plan holds only "status" (the
// reply's kind: "control" or "manual") and "ms_total" (the round trip); candidate counts, cost
// terms, rejections and traces are absent, which `frenetic report` shows as unknown.
#pragma once

#include <condition_variable>
#include <cstdio>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "frenetic/plan/planner.h"
#include "frenetic/sim/drive_report.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/status.h"

namespace frenetic::sim {

class RecordWriter {
 public:
  // Opens (truncates) the file, gzip-compressed when `path` ends in ".gz"; an error names it.
  static StatusOr<std::unique_ptr<RecordWriter>> Open(const std::string& path);
  // Writes what is queued, ends the stream and closes the file.
  ~RecordWriter();
  RecordWriter(const RecordWriter&) = delete;
  RecordWriter& operator=(const RecordWriter&) = delete;

  // Candidates (and the candidate counts) are traced by `replica`, a planner made as the one
  // that drives and Reset(), on the writer's thread: it plans every exchange's telemetry again,
  // with a trace of up to `max_candidates`, and its path is checked against the one the planner
  // sent. The driving planner then needs no trace (sim::RunOptions::trace_candidates = 0) and
  // only its timings are written. Needs a deterministic planner (wall-clock deadlines pinned);
  // should the replica ever plan otherwise, a warning is logged and candidates are left out from
  // there on. Call before WriteHeader.
  void TraceByReplay(std::unique_ptr<plan::Planner> replica, int max_candidates);
  // `config` is the planner configuration (JSON object, or its text as a string).
  // `connect_url` (the planner server of a drive over the network) is written when not empty.
  void WriteHeader(const Simulator& sim, const std::string& planner_name,
                   const nlohmann::json& config, std::string_view connect_url = {});
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
  // A line of a record of another kind of run (`frenetic commonroad --record`,
  // commonroad/record.h): `format` appends the line (one JSON object, no newline) on the
  // writer's thread, so it should hold copies, not references to what the caller changes next.
  // `last` ends the stream after it, as WriteFooter does.
  void WriteLine(std::function<void(std::string* line)> format, bool last = false);
  // Waits until everything queued is in the file; Ok unless a write failed (the message names
  // the file and why).
  Status status();
  void set_timing(bool timing) { timing_ = timing; }

  class Sink;  // the file, plain or gzip (record.cc)

 private:
  // Formats one line (without its newline) on the writer's thread.
  using Line = std::function<void(std::string* line)>;

  explicit RecordWriter(std::unique_ptr<Sink> sink);
  void Queue(Line line, bool last = false);
  void Loop();
  // On the writer's thread: replans exchange `index` with the replica; true (with *summary's
  // counts and *candidates from the replica) when it sent the same path.
  bool Replay(int index, const std::string& telemetry_json, const std::vector<double>& path_x,
              const std::vector<double>& path_y, plan::PlanSummary* summary,
              std::vector<plan::CandidateTrace>* candidates);

  std::unique_ptr<Sink> sink_;
  std::unique_ptr<plan::Planner> replica_;  // used on the writer's thread only
  plan::CycleTrace replica_trace_;
  bool timing_ = true;
  bool finished_ = false;  // the footer was queued (producer side)

  std::mutex mutex_;
  std::condition_variable work_;  // for the writer's thread: lines to write, or stop
  std::condition_variable room_;  // for producers: room in the queue, or all written
  std::deque<Line> queue_;        // guarded by mutex_
  bool busy_ = false;             // a line is being written (guarded)
  bool last_ = false;             // the footer is queued: end the stream after it (guarded)
  bool stop_ = false;             // guarded
  int drain_ = 0;                 // status() calls waiting for everything to be written
  std::thread thread_;
};

// An exchange line's "plan" object as WriteExchange writes it: the status ("ok", "fallback",
// ...), the counts, rejections by reason and the winner's costs of `summary`, and the traced
// `candidates` (best first). Every time (plan_ms, the summary's stage times) is multiplied by
// `time_scale`: 0 with timing off.
nlohmann::json PlanJson(plan::PlanStatus status, const plan::PlanSummary& summary, double plan_ms,
                        double time_scale, const std::vector<plan::CandidateTrace>& candidates);

// The planner YAML as JSON (numbers, booleans, strings, maps, lists); the text itself on error.
nlohmann::json YamlToJson(const std::string& yaml_text);

}  // namespace frenetic::sim

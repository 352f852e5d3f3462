// The drive record (`frenetic drive --record run.jsonl`): JSON lines, enough to replay and
// explain a run. First line {"type":"header",...}, then one {"type":"exchange",...} per
// exchange, last line {"type":"footer","report":{...}}. With timing off every time field is 0,
// so the same seed gives byte-identical files.
//
// A drive over the network (`frenetic drive --connect URL --record run.jsonl`) is recorded the
// same way, with what only an in-process planner knows left out: the header's planner is
// "remote" (config null, the URL in "connect"), and each exchange's plan holds only "status" (the
// reply's kind: "control" or "manual") and "ms_total" (the round trip); candidate counts, cost
// terms, rejections and traces are absent, which `frenetic report` shows as unknown.
#pragma once

#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/plan/planner.h"
#include "frenetic/sim/drive_report.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/status.h"

namespace frenetic::sim {

class RecordWriter {
 public:
  // Opens (truncates) the file; an error names it.
  static StatusOr<std::unique_ptr<RecordWriter>> Open(const std::string& path);
  ~RecordWriter();

  // `config` is the planner configuration (JSON object, or its text as a string).
  // `connect_url` (the planner server of a drive over the network) is written when not empty.
  void WriteHeader(const Simulator& sim, const std::string& planner_name,
                   const nlohmann::json& config, std::string_view connect_url = {});
  // One exchange: the telemetry sent, the reply and how it was made, the metrics after it and
  // the incidents that started since the previous exchange (log indices [first, end)).
  // `telemetry_json` is net::TelemetryToJson of the telemetry sent at simulated time t;
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
  void WriteFooter(const DriveReport& report);
  // Ok unless a write failed (the message names the file).
  Status status() const;
  void set_timing(bool timing) { timing_ = timing; }

 private:
  explicit RecordWriter(std::FILE* file, std::string path);
  void WriteLine(const std::string& line);
  // The exchange line: the fields every exchange has around the given path and plan objects.
  void WriteExchangeLine(int index, double t, const std::string& telemetry_json,
                         std::span<const double> path_x, std::span<const double> path_y,
                         const nlohmann::json& plan, const Simulator& sim,
                         std::size_t first_incident, int l_old, int l_new);

  std::FILE* file_;
  std::string path_;
  bool failed_ = false;
  bool timing_ = true;
  std::string line_;
};

// The planner YAML as JSON (numbers, booleans, strings, maps, lists); the text itself on error.
nlohmann::json YamlToJson(const std::string& yaml_text);

}  // namespace frenetic::sim

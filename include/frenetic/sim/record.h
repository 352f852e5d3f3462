// The drive record (`frenetic drive --record run.jsonl`): JSON lines, enough to replay and
// explain a run. First line {"type":"header",...}, then one {"type":"exchange",...} per
// exchange, last line {"type":"footer","report":{...}}. With timing off every time field is 0,
// so the same seed gives byte-identical files.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
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
  void WriteHeader(const Simulator& sim, const std::string& planner_name,
                   const nlohmann::json& config);
  // One exchange: the telemetry sent, the reply and how it was made, the metrics after it and
  // the incidents that started since the previous exchange (log indices [first, end)).
  // `telemetry_json` is net::TelemetryToJson of the telemetry sent at simulated time t;
  // l_old / l_new are the ticks run before and after the path was applied.
  void WriteExchange(int index, double t, const std::string& telemetry_json,
                     const plan::PlanResult& result, const plan::CycleTrace* trace,
                     double plan_ms, const Simulator& sim, std::size_t first_incident,
                     int l_old, int l_new);
  void WriteFooter(const DriveReport& report);
  // Ok unless a write failed (the message names the file).
  Status status() const;
  void set_timing(bool timing) { timing_ = timing; }

 private:
  explicit RecordWriter(std::FILE* file, std::string path);
  void WriteLine(const std::string& line);

  std::FILE* file_;
  std::string path_;
  bool failed_ = false;
  bool timing_ = true;
  std::string line_;
};

// The planner YAML as JSON (numbers, booleans, strings, maps, lists); the text itself on error.
nlohmann::json YamlToJson(const std::string& yaml_text);

}  // namespace frenetic::sim

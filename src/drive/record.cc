// The lines are formatted on the record::Writer's thread from copies of the exchange's values
// (the planning thread only copies).
#include "frenetic/drive/record.h"

#include <algorithm>
#include <cmath>

#include "frenetic/drive/episode.h"
#include "frenetic/json_text.h"
#include "frenetic/record/plan_json.h"
#include "frenetic/record/schema.h"
#include "frenetic/units.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::sim {
namespace {

namespace key = record::key;

// `"key":`, as JSON text.
void AppendKey(const char* key, std::string* line) {
  *line += '"';
  *line += key;
  *line += "\":";
}

// What an exchange line needs from the simulator, copied when the exchange is written.
struct Metrics {
  double speed_mph, acc, acc_t, acc_n, jerk, gap, headway, distance_m, curr_miles, best_miles;
  int lane, leader, l_old, l_new;
};

Metrics MetricsOf(const Simulator& sim, int l_old, int l_new) {
  const IncidentMonitor& m = sim.monitor();
  const LeaderGap lead = sim.leader();
  return {sim.ego().speed() * units::kSimMpsToMph,
          m.last_acc(),
          m.last_acc_t(),
          m.last_acc_n(),
          m.last_jerk(),
          lead.gap,
          lead.headway,
          m.distance(),
          m.current_miles(),
          m.best_miles(),
          sim.lane(),
          lead.id,
          l_old,
          l_new};
}

std::vector<Incident> IncidentsSince(const Simulator& sim, std::size_t first) {
  const std::vector<Incident>& log = sim.monitor().log();
  return {log.begin() + static_cast<std::ptrdiff_t>(std::min(first, log.size())), log.end()};
}

// The exchange line: the fields every exchange has around the given path and plan objects.
void FormatExchange(int index, double t, const std::string& telemetry_json,
                    const std::vector<double>& path_x, const std::vector<double>& path_y,
                    const nlohmann::json& plan, const Metrics& mt,
                    const std::vector<Incident>& new_incidents, std::string* line) {
  const bool has_leader = mt.leader >= 0;
  nlohmann::json metrics = {{"speed_mph", mt.speed_mph},
                            {"acc", mt.acc},
                            {"acc_t", mt.acc_t},
                            {"acc_n", mt.acc_n},
                            {"jerk", mt.jerk},
                            {"lane", mt.lane},
                            {"gap", has_leader ? FiniteOrNull(mt.gap) : nlohmann::json()},
                            {"headway", has_leader ? FiniteOrNull(mt.headway) : nlohmann::json()},
                            {"leader", mt.leader},
                            {"distance_m", mt.distance_m},
                            {"curr_miles", mt.curr_miles},
                            {"best_miles", mt.best_miles},
                            {"l_old", mt.l_old},
                            {"l_new", mt.l_new}};
  nlohmann::json incidents = nlohmann::json::array();
  for (const Incident& inc : new_incidents) {
    incidents.push_back({{"t", inc.t},
                         {"s", inc.s},
                         {"d", inc.d},
                         {"lane", inc.lane},
                         {"kind", ToString(inc.kind)},
                         {"value", inc.value}});
  }
  // 0.1 mm is far below the float32 resolution the simulator parses to; it halves the file.
  auto rounded = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double e : v) a.push_back(std::isfinite(e) ? std::round(e * 1e4) / 1e4 : 0.0);
    return a;
  };
  nlohmann::json rest = {{key::kPath, {{"x", rounded(path_x)}, {"y", rounded(path_y)}}},
                         {key::kPlan, plan},
                         {key::kMetrics, metrics},
                         {key::kIncidents, incidents}};
  // The telemetry is spliced in as the simulator's own text (wire::TelemetryToJson), after the
  // type, the cycle and the time.
  *line += '{';
  AppendKey(key::kType, line);
  *line += nlohmann::json(key::kExchange).dump();
  *line += ',';
  AppendKey(key::kCycle, line);
  *line += std::to_string(index);
  *line += ',';
  AppendKey(key::kTime, line);
  *line += nlohmann::json(t).dump();
  *line += ',';
  AppendKey(key::kTelemetry, line);
  *line += telemetry_json.empty() ? "null" : telemetry_json;
  *line += ",";
  *line += JsonText(rest).substr(1);
}

}  // namespace

StatusOr<std::unique_ptr<RecordWriter>> RecordWriter::Open(const std::string& path) {
  auto writer = record::Writer::Open(path);
  if (!writer.ok()) return writer.status();
  return std::unique_ptr<RecordWriter>(new RecordWriter(std::move(writer).value()));
}

RecordWriter::RecordWriter(std::unique_ptr<record::Writer> writer) : writer_(std::move(writer)) {}

RecordWriter::~RecordWriter() = default;

void RecordWriter::TraceByReplay(std::unique_ptr<plan::Planner> replica, int max_candidates) {
  replica_ = replica ? std::make_shared<record::Replica>(std::move(replica), max_candidates,
                                                         writer_->path())
                     : nullptr;
}

void RecordWriter::set_planner(std::string name, nlohmann::json config,
                               std::string connect_url) {
  planner_name_ = std::move(name);
  planner_config_ = std::move(config);
  connect_url_ = std::move(connect_url);
}

void RecordWriter::OnStart(const Episode& episode) {
  WriteHeader(episode.sim(), planner_name_, planner_config_, connect_url_);
  telemetry_json_ = wire::TelemetryToJson(episode.telemetry());
}

void RecordWriter::OnExchange(const Episode& episode, const Exchange& exchange) {
  const ExchangeReply& reply = *exchange.reply;
  if (reply.plan != nullptr) {
    WriteExchange(exchange.index, exchange.t_sent, telemetry_json_, *reply.plan, reply.trace,
                  reply.ms, episode.sim(), exchange.first_incident, episode.last_l_old(),
                  episode.last_l_new());
  } else {
    WriteRemoteExchange(exchange.index, exchange.t_sent, telemetry_json_, reply.path_x,
                        reply.path_y, reply.kind, reply.ms, episode.sim(),
                        exchange.first_incident, episode.last_l_old(), episode.last_l_new());
  }
  // The next exchange's telemetry, as the text sent.
  if (!episode.done()) telemetry_json_ = wire::TelemetryToJson(episode.telemetry());
}

Status RecordWriter::OnEnd(const Episode& /*episode*/, DriveReport* report) {
  WriteFooter(*report);
  return status();
}

void RecordWriter::WriteHeader(const Simulator& sim, const std::string& planner_name,
                               const nlohmann::json& config, std::string_view connect_url) {
  const World& w = sim.world();
  nlohmann::json centre = nlohmann::json::array();
  const double length = w.line->length();
  const int n = std::max(4, static_cast<int>(std::ceil(length / 2.0)));
  auto round3 = [](double v) { return std::round(v * 1000.0) / 1000.0; };
  for (int i = 0; i < n; ++i) {
    const map::CartesianPose p = w.line->ToCartesian(length * i / n, 0.0);
    centre.push_back({round3(p.x), round3(p.y)});
  }
  const Scenario& sc = sim.scenario();
  nlohmann::json h = {{key::kType, key::kHeader},
                      {key::kVersion, record::kVersion},
                      {key::kMap, w.map_path},
                      {key::kMaxS, w.track.max_s},
                      {key::kLaneWidth, 4},
                      {key::kLanes, 3},
                      {key::kScenario, sc.name},
                      {key::kSeed, sim.seed()},
                      {key::kPlanner, planner_name},
                      {key::kConfig, config},
                      {key::kTiming, ToString(sc.timing.mode)},
                      {key::kCars, sc.traffic.cars},
                      {key::kCenterline, centre},
                      {key::kCarLength, sc.car_length},
                      {key::kCarWidth, sc.car_width}};
  if (!connect_url.empty()) h[key::kConnect] = connect_url;
  writer_->WriteText(JsonText(h));
}

void RecordWriter::WriteExchange(int index, double t, const std::string& telemetry_json,
                                 const plan::PlanResult& result, const plan::CycleTrace* trace,
                                 double plan_ms, const Simulator& sim,
                                 std::size_t first_incident, int l_old, int l_new) {
  const double k = timing_ ? 1.0 : 0.0;  // timing off: every time field is 0 (byte-stable)
  writer_->Write(
      [replica = replica_, index, t, telemetry_json, status = result.status, k, plan_ms,
       summary = result.summary,
       candidates = trace != nullptr ? trace->candidates : std::vector<plan::CandidateTrace>(),
       path_x = result.x, path_y = result.y, metrics = MetricsOf(sim, l_old, l_new),
       incidents = IncidentsSince(sim, first_incident)](std::string* line) mutable {
        if (replica != nullptr && replica->active()) {
          candidates.clear();
          // The telemetry as the planner received it: what ParseFrame makes of the text sent
          // (wire::TelemetryAsReceived), whatever its size.
          wire::FrameLimits unlimited;
          unlimited.max_sensor_rows = 100000;
          unlimited.max_path_points = 1000000;
          const wire::ParsedFrame frame =
              wire::ParseFrame("42[\"telemetry\"," + telemetry_json + "]", unlimited);
          replica->Trace(frame.kind == wire::FrameKind::kTelemetry ? &frame.telemetry : nullptr,
                         path_x, path_y, index, &summary, &candidates);
        }
        const nlohmann::json plan = record::PlanJson(status, summary, plan_ms, k, candidates);
        FormatExchange(index, t, telemetry_json, path_x, path_y, plan, metrics, incidents, line);
      });
}

void RecordWriter::WriteRemoteExchange(int index, double t, const std::string& telemetry_json,
                                       std::span<const double> path_x,
                                       std::span<const double> path_y, std::string_view reply,
                                       double round_trip_ms, const Simulator& sim,
                                       std::size_t first_incident, int l_old, int l_new) {
  const double k = timing_ ? 1.0 : 0.0;
  writer_->Write([index, t, telemetry_json, reply = std::string(reply), ms = k * round_trip_ms,
                  path_x = std::vector<double>(path_x.begin(), path_x.end()),
                  path_y = std::vector<double>(path_y.begin(), path_y.end()),
                  metrics = MetricsOf(sim, l_old, l_new),
                  incidents = IncidentsSince(sim, first_incident)](std::string* line) {
    const nlohmann::json plan = {{"status", reply}, {"ms_total", ms}};
    FormatExchange(index, t, telemetry_json, path_x, path_y, plan, metrics, incidents, line);
  });
}

void RecordWriter::WriteFooter(const DriveReport& report) {
  nlohmann::json f = {{key::kType, key::kFooter}, {key::kReport, report.ToJson()}};
  if (!timing_) f[key::kReport]["plan_ms"] = {{"p50", 0}, {"p99", 0}, {"max", 0}};
  writer_->WriteText(JsonText(f), /*last=*/true);
}

}  // namespace frenetic::sim

#include "frenetic/sim/record.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace frenetic::sim {
namespace {

const char* StatusName(plan::PlanStatus s) {
  switch (s) {
    case plan::PlanStatus::kOk: return "ok";
    case plan::PlanStatus::kFallbackUsed: return "fallback";
    case plan::PlanStatus::kInvalidInput: return "invalid_input";
    case plan::PlanStatus::kOverBudget: return "over_budget";
  }
  return "?";
}

nlohmann::json Finite(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json Costs(const std::vector<plan::CostTermValue>& terms) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& t : terms) {
    a.push_back({{"name", t.name}, {"weight", Finite(t.weight)}, {"value", Finite(t.value)}});
  }
  return a;
}

nlohmann::json Node(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: {
      nlohmann::json o = nlohmann::json::object();
      for (const auto& kv : n) o[kv.first.as<std::string>()] = Node(kv.second);
      return o;
    }
    case YAML::NodeType::Sequence: {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& e : n) a.push_back(Node(e));
      return a;
    }
    case YAML::NodeType::Scalar: {
      const std::string v = n.Scalar();
      if (n.Tag() != "!") {  // unquoted: a number or a boolean when it parses as one
        if (v == "true" || v == "True") return true;
        if (v == "false" || v == "False") return false;
        char* end = nullptr;
        errno = 0;
        const double d = std::strtod(v.c_str(), &end);
        if (!v.empty() && end == v.c_str() + v.size() && errno == 0 && std::isfinite(d)) {
          if (d == std::floor(d) && std::abs(d) < 1e15 && v.find_first_of(".eE") == v.npos) {
            return static_cast<long long>(d);
          }
          return d;
        }
      }
      return v;
    }
    default: return nullptr;
  }
}

}  // namespace

nlohmann::json YamlToJson(const std::string& yaml_text) {
  try {
    return Node(YAML::Load(yaml_text));
  } catch (const YAML::Exception&) {
    return yaml_text;
  }
}

StatusOr<std::unique_ptr<RecordWriter>> RecordWriter::Open(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    return Status::Error(path + ": cannot write record: " + std::strerror(errno));
  }
  return std::unique_ptr<RecordWriter>(new RecordWriter(f, path));
}

RecordWriter::RecordWriter(std::FILE* file, std::string path)
    : file_(file), path_(std::move(path)) {}

RecordWriter::~RecordWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

Status RecordWriter::status() const {
  if (failed_) return Status::Error(path_ + ": write failed");
  if (file_ != nullptr && std::fflush(file_) != 0) return Status::Error(path_ + ": write failed");
  return Status::Ok();
}

void RecordWriter::WriteLine(const std::string& line) {
  if (failed_) return;
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size() ||
      std::fputc('\n', file_) == EOF) {
    failed_ = true;
  }
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
  nlohmann::json h = {{"type", "header"},
                      {"version", 1},
                      {"map", w.map_path},
                      {"max_s", w.track.max_s},
                      {"lane_width", 4},
                      {"lanes", 3},
                      {"scenario", sc.name},
                      {"seed", sim.seed()},
                      {"planner", planner_name},
                      {"config", config},
                      {"timing", ToString(sc.timing.mode)},
                      {"cars", sc.traffic.cars},
                      {"centerline", centre},
                      {"car_length", sc.car_length},
                      {"car_width", sc.car_width}};
  if (!connect_url.empty()) h["connect"] = connect_url;
  WriteLine(h.dump());
}

void RecordWriter::WriteExchange(int index, double t, const std::string& telemetry_json,
                                 const plan::PlanResult& result, const plan::CycleTrace* trace,
                                 double plan_ms, const Simulator& sim,
                                 std::size_t first_incident, int l_old, int l_new) {
  const plan::PlanSummary& s = result.summary;
  nlohmann::json rejections = nlohmann::json::object();
  for (int k = 0; k < static_cast<int>(plan::Reject::kCount); ++k) {
    rejections[plan::ToString(static_cast<plan::Reject>(k))] = s.rejections[k];
  }
  nlohmann::json candidates = nlohmann::json::array();
  if (trace != nullptr) {
    for (const plan::CandidateTrace& c : trace->candidates) {
      nlohmann::json reject = nullptr;
      if (c.reject >= 0 && c.reject < static_cast<int>(plan::Reject::kCount)) {
        reject = plan::ToString(static_cast<plan::Reject>(c.reject));
      }
      candidates.push_back({{"lane", c.lane},
                            {"end_speed", Finite(c.end_speed)},
                            {"duration", Finite(c.duration)},
                            {"total_cost", Finite(c.total_cost)},
                            {"checked", c.checked},
                            {"winner", c.winner},
                            {"reject", reject},
                            {"reject_car", c.reject_car >= 0 ? nlohmann::json(c.reject_car)
                                                             : nlohmann::json(nullptr)},
                            {"reject_t", Finite(c.reject_time)},
                            {"x", c.x},
                            {"y", c.y},
                            {"costs", Costs(c.costs)}});
    }
  }
  const double k = timing_ ? 1.0 : 0.0;  // timing off: every time field is 0 (byte-stable)
  nlohmann::json plan = {
      {"status", StatusName(result.status)},
      {"ms_total", k * plan_ms},
      {"ms_planner", k * s.ms_total},
      {"ms_stages",
       {{"prepare", k * s.ms_prepare}, {"generate", k * s.ms_generate}, {"score", k * s.ms_score},
        {"check", k * s.ms_check}, {"refine", k * s.ms_refine}, {"output", k * s.ms_output}}},
      {"candidates_generated", s.candidates_generated},
      {"candidates_scored", s.candidates_scored},
      {"candidates_checked", s.candidates_checked},
      {"candidates_feasible", s.candidates_feasible},
      {"rejections", rejections},
      {"winner_costs", Costs(s.winner_costs)},
      {"winner_total_cost", Finite(s.winner_total_cost)},
      {"winner_lane", s.winner_lane},
      {"winner_end_speed", Finite(s.winner_end_speed)},
      {"winner_duration", Finite(s.winner_duration)},
      {"refine_iterations", s.refine_iterations},
      {"deadline_stage", plan::ToString(s.deadline_stage)},
      {"refine_cost_before", Finite(s.refine_cost_before)},
      {"refine_cost_after", Finite(s.refine_cost_after)},
      {"points_kept", s.points_kept},
      {"candidates", candidates}};
  WriteExchangeLine(index, t, telemetry_json, result.x, result.y, plan, sim, first_incident,
                    l_old, l_new);
}

void RecordWriter::WriteRemoteExchange(int index, double t, const std::string& telemetry_json,
                                       std::span<const double> path_x,
                                       std::span<const double> path_y, std::string_view reply,
                                       double round_trip_ms, const Simulator& sim,
                                       std::size_t first_incident, int l_old, int l_new) {
  const double k = timing_ ? 1.0 : 0.0;
  const nlohmann::json plan = {{"status", reply}, {"ms_total", k * round_trip_ms}};
  WriteExchangeLine(index, t, telemetry_json, path_x, path_y, plan, sim, first_incident, l_old,
                    l_new);
}

void RecordWriter::WriteExchangeLine(int index, double t, const std::string& telemetry_json,
                                     std::span<const double> path_x,
                                     std::span<const double> path_y, const nlohmann::json& plan,
                                     const Simulator& sim, std::size_t first_incident, int l_old,
                                     int l_new) {
  const IncidentMonitor& m = sim.monitor();
  const LeaderGap lead = sim.leader();
  nlohmann::json metrics = {
      {"speed_mph", sim.ego().speed() * kMpsToMph},
      {"acc", m.last_acc()},
      {"acc_t", m.last_acc_t()},
      {"acc_n", m.last_acc_n()},
      {"jerk", m.last_jerk()},
      {"lane", sim.lane()},
      {"gap", lead.id >= 0 ? Finite(lead.gap) : nlohmann::json()},
      {"headway", lead.id >= 0 ? Finite(lead.headway) : nlohmann::json()},
      {"leader", lead.id},
      {"distance_m", m.distance()},
      {"curr_miles", m.current_miles()},
      {"best_miles", m.best_miles()},
      {"l_old", l_old},
      {"l_new", l_new}};
  nlohmann::json incidents = nlohmann::json::array();
  for (std::size_t i = first_incident; i < m.log().size(); ++i) {
    const Incident& inc = m.log()[i];
    incidents.push_back({{"t", inc.t}, {"s", inc.s}, {"d", inc.d}, {"lane", inc.lane},
                         {"kind", ToString(inc.kind)}, {"value", inc.value}});
  }
  // 0.1 mm is far below the float32 resolution the simulator parses to; it halves the file.
  auto rounded = [](std::span<const double> v) {
    nlohmann::json a = nlohmann::json::array();
    for (double e : v) a.push_back(std::isfinite(e) ? std::round(e * 1e4) / 1e4 : 0.0);
    return a;
  };
  nlohmann::json rest = {{"path", {{"x", rounded(path_x)}, {"y", rounded(path_y)}}},
                         {"plan", plan},
                         {"metrics", metrics},
                         {"incidents", incidents}};
  // The telemetry is spliced in as the simulator's own text (net::TelemetryToJson).
  line_.clear();
  line_ += "{\"type\":\"exchange\",\"i\":";
  line_ += std::to_string(index);
  line_ += ",\"t\":";
  line_ += nlohmann::json(t).dump();
  line_ += ",\"telemetry\":";
  line_ += telemetry_json.empty() ? "null" : telemetry_json;
  line_ += ",";
  line_ += rest.dump().substr(1);
  WriteLine(line_);
}

void RecordWriter::WriteFooter(const DriveReport& report) {
  nlohmann::json f = {{"type", "footer"}, {"report", report.ToJson()}};
  if (!timing_) f["report"]["plan_ms"] = {{"p50", 0}, {"p99", 0}, {"max", 0}};
  WriteLine(f.dump());
}

}  // namespace frenetic::sim

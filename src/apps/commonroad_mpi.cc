#include "apps/commonroad_mpi.h"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "frenetic/json_text.h"

namespace frenetic::apps::commonroad_cli {

using nlohmann::json;

bool RunsHere(int index, const tune::Cluster& cluster) {
  return index % cluster.size() == cluster.rank();
}

namespace {

// nlohmann writes the shortest text that reads back to the same double; it writes non-finite
// numbers as null, so they travel as text.
json Num(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
}

double NumFrom(const json& j) {
  if (j.is_number()) return j.get<double>();
  const std::string s = j.get<std::string>();
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  return s == "inf" ? std::numeric_limits<double>::infinity()
                    : -std::numeric_limits<double>::infinity();
}

json Nums(const std::vector<double>& v) {
  json out = json::array();
  for (double x : v) out.push_back(Num(x));
  return out;
}

json Costs(const std::map<std::string, double>& costs) {
  json out = json::object();
  for (const auto& [id, v] : costs) out[id] = Num(v);
  return out;
}

std::map<std::string, double> CostsFrom(const json& j) {
  std::map<std::string, double> out;
  for (const auto& [id, v] : j.items()) out[id] = NumFrom(v);
  return out;
}

json OptionalInt(const std::optional<int>& v) { return v ? json(*v) : json(nullptr); }
std::optional<int> OptionalIntFrom(const json& j) {
  return j.is_null() ? std::nullopt : std::optional<int>(j.get<int>());
}

json FailureWire(const cr::Failure& f) {
  return {{"kind", static_cast<int>(f.kind)},
          {"step", f.step},
          {"detail", f.detail},
          {"obstacle", OptionalInt(f.obstacle_id)},
          {"entered_s", f.entered_s ? Num(*f.entered_s) : json(nullptr)}};
}

cr::Failure FailureFrom(const json& j) {
  cr::Failure f;
  f.kind = static_cast<cr::FailureKind>(j.at("kind").get<int>());
  f.step = j.at("step").get<int>();
  f.detail = j.at("detail").get<std::string>();
  f.obstacle_id = OptionalIntFrom(j.at("obstacle"));
  if (const json& e = j.at("entered_s"); !e.is_null()) f.entered_s = NumFrom(e);
  return f;
}

json VerdictWire(const cr::Verdict& v) {
  json failures = json::array();
  for (const cr::Failure& f : v.failures) failures.push_back(FailureWire(f));
  return {{"problem_id", v.problem_id},
          {"solved", v.solved},
          {"goal_step", OptionalInt(v.goal_step)},
          {"failures", failures},
          {"infeasible_at_start",
           v.infeasible_at_start ? FailureWire(*v.infeasible_at_start) : json(nullptr)}};
}

cr::Verdict VerdictFrom(const json& j) {
  cr::Verdict v;
  v.problem_id = j.at("problem_id").get<int>();
  v.solved = j.at("solved").get<bool>();
  v.goal_step = OptionalIntFrom(j.at("goal_step"));
  for (const json& f : j.at("failures")) v.failures.push_back(FailureFrom(f));
  if (!j.at("infeasible_at_start").is_null()) {
    v.infeasible_at_start = FailureFrom(j.at("infeasible_at_start"));
  }
  return v;
}

json ReferenceWire(const ReferenceReport& r) {
  return {{"file", r.file},
          {"vehicle_type", r.vehicle_type},
          {"cost_function", r.cost_function},
          {"first_step", r.first_step},
          {"last_step", r.last_step},
          {"states", r.states},
          {"costs", Costs(r.costs)},
          {"goal_step", OptionalInt(r.goal_step)},
          {"distance_ratio", Num(r.distance_ratio)},
          {"verdict", r.verdict}};
}

ReferenceReport ReferenceFrom(const json& j) {
  ReferenceReport r;
  r.file = j.at("file").get<std::string>();
  r.vehicle_type = j.at("vehicle_type").get<int>();
  r.cost_function = j.at("cost_function").get<std::string>();
  r.first_step = j.at("first_step").get<int>();
  r.last_step = j.at("last_step").get<int>();
  r.states = j.at("states").get<int>();
  r.costs = CostsFrom(j.at("costs"));
  r.goal_step = OptionalIntFrom(j.at("goal_step"));
  r.distance_ratio = NumFrom(j.at("distance_ratio"));
  r.verdict = j.at("verdict").get<std::string>();
  return r;
}

json WayThroughWire(const cr::WayThrough& w) {
  return {{"found", w.found},
          {"last_step", w.last_step},
          {"survived_to", w.survived_to},
          {"exhaustive", w.exhaustive},
          {"goal_step", w.goal_step},
          {"goal_searched_to", w.goal_searched_to},
          {"checked", w.checked}};
}

cr::WayThrough WayThroughFrom(const json& j) {
  cr::WayThrough w;
  w.found = j.at("found").get<bool>();
  w.last_step = j.at("last_step").get<int>();
  w.survived_to = j.at("survived_to").get<int>();
  w.exhaustive = j.at("exhaustive").get<bool>();
  w.goal_step = j.at("goal_step").get<int>();
  w.goal_searched_to = j.at("goal_searched_to").get<int>();
  w.checked = j.at("checked").get<std::int64_t>();
  return w;
}

json ProblemWire(const ProblemReport& p) {
  return {{"problem_id", p.problem_id},
          {"road_error", p.road_error},
          {"verdict", VerdictWire(p.verdict)},
          {"stop", p.stop},
          {"initial_step", p.initial_step},
          {"lanes", p.lanes},
          {"road_length_m", Num(p.road_length_m)},
          {"route", p.route},
          {"plan_ms", Nums(p.plan_ms)},
          {"rescue_ms", Nums(p.rescue_ms)},
          {"candidates", Num(p.candidates)},
          {"not_ok_cycles", p.not_ok_cycles},
          {"rescued_cycles", p.rescued_cycles},
          {"tracking_error_max_m", Num(p.tracking_error_max_m)},
          {"computation_s", Num(p.computation_s)},
          {"costs", Costs(p.costs)},
          {"reference", p.reference ? ReferenceWire(*p.reference) : json(nullptr)},
          {"way_through", p.way_through ? WayThroughWire(*p.way_through) : json(nullptr)}};
}

ProblemReport ProblemFrom(const json& j) {
  ProblemReport p;
  p.problem_id = j.at("problem_id").get<int>();
  p.road_error = j.at("road_error").get<std::string>();
  p.verdict = VerdictFrom(j.at("verdict"));
  p.stop = j.at("stop").get<std::string>();
  p.initial_step = j.at("initial_step").get<int>();
  p.lanes = j.at("lanes").get<int>();
  p.road_length_m = NumFrom(j.at("road_length_m"));
  p.route = j.at("route").get<std::vector<int>>();
  for (const json& v : j.at("plan_ms")) p.plan_ms.push_back(NumFrom(v));
  for (const json& v : j.at("rescue_ms")) p.rescue_ms.push_back(NumFrom(v));
  p.candidates = NumFrom(j.at("candidates"));
  p.not_ok_cycles = j.at("not_ok_cycles").get<int>();
  p.rescued_cycles = j.at("rescued_cycles").get<int>();
  p.tracking_error_max_m = NumFrom(j.at("tracking_error_max_m"));
  p.computation_s = NumFrom(j.at("computation_s"));
  p.costs = CostsFrom(j.at("costs"));
  if (!j.at("reference").is_null()) p.reference = ReferenceFrom(j.at("reference"));
  if (!j.at("way_through").is_null()) p.way_through = WayThroughFrom(j.at("way_through"));
  return p;
}

json FileWire(const FileReport& f) {
  json problems = json::array();
  for (const ProblemReport& p : f.problems) problems.push_back(ProblemWire(p));
  return {{"path", f.path},
          {"error", f.error},
          {"benchmark_id", f.benchmark_id},
          {"origin", {Num(f.origin.x), Num(f.origin.y)}},
          {"dt", Num(f.dt)},
          {"problems", problems},
          {"solution_file", f.solution_file},
          {"solution_error", f.solution_error},
          {"record_error", f.record_error}};
}

FileReport FileFrom(const json& j) {
  FileReport f;
  f.path = j.at("path").get<std::string>();
  f.error = j.at("error").get<std::string>();
  f.benchmark_id = j.at("benchmark_id").get<std::string>();
  f.origin = {NumFrom(j.at("origin").at(0)), NumFrom(j.at("origin").at(1))};
  f.dt = NumFrom(j.at("dt"));
  for (const json& p : j.at("problems")) f.problems.push_back(ProblemFrom(p));
  f.solution_file = j.at("solution_file").get<std::string>();
  f.solution_error = j.at("solution_error").get<std::string>();
  f.record_error = j.at("record_error").get<std::string>();
  return f;
}

}  // namespace

std::string Serialise(const std::vector<FileReport>& reports, const std::vector<int>& indices) {
  json out = json::array();
  for (int i : indices) out.push_back({{"index", i}, {"report", FileWire(reports.at(i))}});
  return JsonText(out);
}

Status Deserialise(std::string_view text, std::vector<FileReport>* reports) {
  try {
    const json in = json::parse(text);
    for (const json& entry : in) {
      const int i = entry.at("index").get<int>();
      if (i < 0 || i >= static_cast<int>(reports->size())) {
        return Status::Error("a report for file " + std::to_string(i) + " of " +
                             std::to_string(reports->size()));
      }
      (*reports)[i] = FileFrom(entry.at("report"));
    }
  } catch (const json::exception& e) {
    return Status::Error(std::string("a rank's reports do not read back: ") + e.what());
  }
  return Status::Ok();
}

Status GatherReports(const tune::Cluster& cluster, std::vector<FileReport>* reports) {
  if (!cluster.distributed()) return Status::Ok();
  std::vector<int> mine;
  for (int i = 0; i < static_cast<int>(reports->size()); ++i) {
    if (RunsHere(i, cluster)) mine.push_back(i);
  }
  const std::vector<std::string> all = cluster.GatherToRoot(Serialise(*reports, mine));
  for (size_t r = 1; r < all.size(); ++r) {  // rank 0's own are in place
    if (Status st = Deserialise(all[r], reports); !st.ok()) {
      return Status::Error("rank " + std::to_string(r) + ": " + st.message());
    }
  }
  return Status::Ok();
}

}  // namespace frenetic::apps::commonroad_cli

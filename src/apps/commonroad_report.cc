#include "apps/commonroad_report.h"

#include <algorithm>
#include <cstdio>

namespace frenetic::apps::commonroad_cli {

using nlohmann::json;

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t i =
      std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1) + 0.5));
  return values[i];
}

namespace {

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

std::string VerdictLine(const ProblemReport& p) {
  if (p.verdict.infeasible_at_start) return p.verdict.Summary();
  if (!p.road_error.empty()) return "no road: " + p.road_error;
  if (p.verdict.solved) return "solved, goal at step " + std::to_string(*p.verdict.goal_step);
  std::string line = "FAILED: ";
  for (size_t k = 0; k < p.verdict.failures.size(); ++k) {
    const cr::Failure& fl = p.verdict.failures[k];
    if (k > 0) line += "; ";
    line += std::string(cr::ToString(fl.kind)) + " at step " + std::to_string(fl.step) +
            (fl.detail.empty() ? "" : " (" + fl.detail + ")");
  }
  return line;
}

std::string ProblemText(const FileReport& f, const ProblemReport& p) {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "%-24s #%-5d %d lanes %5.0f m  %3zu steps  plan p50 %.2f p99 %.2f ms",
                f.benchmark_id.c_str(), p.problem_id, p.lanes, p.road_length_m, p.plan_ms.size(),
                Percentile(p.plan_ms, 0.5), Percentile(p.plan_ms, 0.99));
  std::string text = buf;
  if (p.costs.count("WX1")) {
    std::snprintf(buf, sizeof(buf), "  WX1 %.1f  JB1 %.1f", p.costs.at("WX1"),
                  p.costs.count("JB1") ? p.costs.at("JB1") : 0.0);
    text += buf;
  }
  return text + "\n    " + VerdictLine(p) + "\n";
}

}  // namespace

json ProblemJson(const ProblemReport& p) {
  json j;
  j["problem"] = p.problem_id;
  j["solved"] = p.verdict.solved;
  if (!p.road_error.empty()) j["road_error"] = p.road_error;
  j["goal_step"] = p.verdict.goal_step ? json(*p.verdict.goal_step) : json(nullptr);
  json failures = json::array();
  for (const cr::Failure& fl : p.verdict.failures) {
    json e = {{"kind", cr::ToString(fl.kind)}, {"step", fl.step}, {"detail", fl.detail}};
    if (fl.obstacle_id) e["obstacle"] = *fl.obstacle_id;
    failures.push_back(e);
  }
  j["failures"] = failures;
  if (p.verdict.infeasible_at_start) {
    j["infeasible_at_start"] = p.verdict.infeasible_at_start->detail;
  }
  j["stop"] = p.stop;
  j["steps"] = static_cast<int>(p.plan_ms.size());
  j["lanes"] = p.lanes;
  j["road_length_m"] = p.road_length_m;
  j["route"] = p.route;
  j["plan_ms"] = {{"p50", Percentile(p.plan_ms, 0.5)},
                  {"p99", Percentile(p.plan_ms, 0.99)},
                  {"max", Max(p.plan_ms)}};
  j["candidates_mean"] = p.plan_ms.empty() ? 0.0 : p.candidates / p.plan_ms.size();
  j["not_ok_cycles"] = p.not_ok_cycles;
  j["tracking_error_max_m"] = p.tracking_error_max_m;
  j["computation_s"] = p.computation_s;
  j["costs"] = p.costs;
  return j;
}

json FileJson(const FileReport& f) {
  json j = {{"path", f.path}};
  if (!f.error.empty()) {
    j["error"] = f.error;
    return j;
  }
  j["benchmark_id"] = f.benchmark_id;
  // Read into a local frame (Scenario::origin): positions in failures are relative to it.
  if (!(f.origin == cr::Vec2{})) j["frame_origin"] = {f.origin.x, f.origin.y};
  json problems = json::array();
  for (const ProblemReport& p : f.problems) problems.push_back(ProblemJson(p));
  j["problems"] = problems;
  if (!f.solution_file.empty()) j["solution_file"] = f.solution_file;
  if (!f.solution_error.empty()) j["solution_error"] = f.solution_error;
  return j;
}

std::string FileText(const FileReport& f) {
  if (!f.error.empty()) return f.path + "\n    UNREADABLE: " + f.error + "\n";
  std::string text;
  for (const ProblemReport& p : f.problems) text += ProblemText(f, p);
  if (!f.solution_error.empty()) text += "    solution: " + f.solution_error + "\n";
  return text;
}

}  // namespace frenetic::apps::commonroad_cli

#include "apps/commonroad_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "commonroad/xml_source.h"
#include "frenetic/percentile.h"

namespace frenetic::apps::commonroad_cli {

using nlohmann::json;

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

json TimesJson(const std::vector<double>& ms) {
  return {{"p50", Percentile(ms, 0.5)}, {"p99", Percentile(ms, 0.99)}, {"max", Max(ms)}};
}

Outcome CompareOutcome(const ProblemReport& p) {
  if (p.verdict.infeasible_at_start) return Outcome::kInfeasibleAtStart;
  const bool ours = p.verdict.solved;
  const bool reference = p.reference && p.reference->goal_step.has_value();
  if (ours && reference) return Outcome::kBothReachGoal;
  if (ours) return Outcome::kOnlyOurs;
  return reference ? Outcome::kOnlyReference : Outcome::kNeither;
}

const char* ToString(Outcome outcome) {
  switch (outcome) {
    case Outcome::kInfeasibleAtStart: return "infeasible_at_start";
    case Outcome::kBothReachGoal: return "both_reach_goal";
    case Outcome::kOnlyOurs: return "only_ours";
    case Outcome::kOnlyReference: return "only_human";
    case Outcome::kNeither: return "neither";
  }
  return "?";
}

std::optional<bool> OursCheaper(const ProblemReport& p, const std::string& id) {
  if (!p.reference || CompareOutcome(p) != Outcome::kBothReachGoal) return std::nullopt;
  const auto ours = p.costs.find(id), theirs = p.reference->costs.find(id);
  if (ours == p.costs.end() || theirs == p.reference->costs.end()) return std::nullopt;
  return ours->second < theirs->second;
}

std::optional<int> StepsToGoal(int first_step, const std::optional<int>& goal_step) {
  if (!goal_step) return std::nullopt;
  return *goal_step - first_step;
}

double Seconds(int steps, double dt) {
  return std::round(steps * dt * 1e6) / 1e6;  // 31 steps of 0.1 s print as 3.1
}

namespace {

json Nullable(const std::optional<int>& v) { return v ? json(*v) : json(nullptr); }

json ReferenceJson(const ProblemReport& p, double dt) {
  const ReferenceReport& r = *p.reference;
  const std::optional<int> human = StepsToGoal(r.first_step, r.goal_step);
  const std::optional<int> ours = StepsToGoal(p.initial_step, p.verdict.goal_step);
  const std::optional<bool> cheaper = OursCheaper(p, "WX1");
  return {{"file", r.file},
          {"vehicle", "KS" + std::to_string(r.vehicle_type)},
          {"cost_function", r.cost_function},
          {"first_step", r.first_step},
          {"last_step", r.last_step},
          {"states", r.states},
          {"costs", r.costs},
          {"goal_step", Nullable(r.goal_step)},
          {"time_to_goal_steps", Nullable(human)},
          {"time_to_goal_s", human ? json(Seconds(*human, dt)) : json(nullptr)},
          {"human_verdict", r.verdict},
          {"distance_ratio", r.distance_ratio},
          {"ours_time_to_goal_steps", Nullable(ours)},
          {"ours_time_to_goal_s", ours ? json(Seconds(*ours, dt)) : json(nullptr)},
          {"outcome", ToString(CompareOutcome(p))},
          {"ours_cheaper_wx1", cheaper ? json(*cheaper) : json(nullptr)}};
}

std::string ToGoal(const std::optional<int>& steps, double dt) {
  if (!steps) return "none";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%d steps / %g s", *steps, Seconds(*steps, dt));
  return buf;
}

std::string ReferenceLine(const ProblemReport& p, double dt) {
  const ReferenceReport& r = *p.reference;
  char buf[256];
  std::snprintf(buf, sizeof(buf), "    human (KS%d, steps %d-%d):", r.vehicle_type, r.first_step,
                r.last_step);
  std::string line = buf;
  for (const char* id : {"WX1", "JB1"}) {
    if (!r.costs.count(id)) continue;
    std::snprintf(buf, sizeof(buf), "  %s %.1f", id, r.costs.at(id));
    line += buf;
  }
  line += "  to goal " + ToGoal(StepsToGoal(r.first_step, r.goal_step), dt) + " (ours " +
          ToGoal(StepsToGoal(p.initial_step, p.verdict.goal_step), dt) + ")";
  std::snprintf(buf, sizeof(buf), "  moves %.2fx its speed", r.distance_ratio);
  line += buf;
  line += "  human_verdict " + r.verdict + "  -> ";
  switch (CompareOutcome(p)) {
    case Outcome::kInfeasibleAtStart: line += "not compared (infeasible at start)"; break;
    case Outcome::kBothReachGoal: {
      const std::optional<bool> cheaper = OursCheaper(p, "WX1");
      line += !cheaper ? "both reach the goal" : *cheaper ? "ours cheaper" : "human cheaper";
      break;
    }
    case Outcome::kOnlyOurs: line += "only ours reaches the goal"; break;
    case Outcome::kOnlyReference: line += "only the human reaches the goal"; break;
    case Outcome::kNeither: line += "neither reaches the goal"; break;
  }
  return line + "\n";
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
                commonroad::Printable(f.benchmark_id).c_str(), p.problem_id, p.lanes,
                p.road_length_m, p.plan_ms.size(),
                Percentile(p.plan_ms, 0.5), Percentile(p.plan_ms, 0.99));
  std::string text = buf;
  if (p.costs.count("WX1")) {
    std::snprintf(buf, sizeof(buf), "  WX1 %.1f  JB1 %.1f", p.costs.at("WX1"),
                  p.costs.count("JB1") ? p.costs.at("JB1") : 0.0);
    text += buf;
  }
  if (p.rescued_cycles > 0) {
    text += "  rescue drove " + std::to_string(p.rescued_cycles) +
            (p.rescued_cycles == 1 ? " step" : " steps");
  }
  text += "\n    " + VerdictLine(p) + "\n";
  if (p.reference) text += ReferenceLine(p, f.dt);
  if (p.way_through) {
    const cr::WayThrough& w = *p.way_through;
    std::snprintf(buf, sizeof(buf),
                  w.found ? "    way through: found (to step %d, the traffic's last)\n"
                          : "    way through: none found, no state past step %d of %d%s\n",
                  w.found ? w.last_step : w.survived_to, w.last_step,
                  w.found || w.exhaustive ? "" : " (capped)");
    text += buf;
    std::snprintf(buf, sizeof(buf),
                  w.goal_step >= 0 ? "    way to the goal: found (a state meets it at step %d)\n"
                                   : "    way to the goal: none found to step %d\n",
                  w.goal_step >= 0 ? w.goal_step : w.goal_searched_to);
    text += buf;
  }
  return text;
}

}  // namespace

json ProblemJson(const ProblemReport& p, double dt) {
  json j;
  j["problem"] = p.problem_id;
  j["solved"] = p.verdict.solved;
  if (!p.road_error.empty()) j["road_error"] = p.road_error;
  j["goal_step"] = p.verdict.goal_step ? json(*p.verdict.goal_step) : json(nullptr);
  json failures = json::array();
  for (const cr::Failure& fl : p.verdict.failures) {
    json e = {{"kind", cr::ToString(fl.kind)}, {"step", fl.step}, {"detail", fl.detail}};
    if (fl.obstacle_id) e["obstacle"] = *fl.obstacle_id;
    if (fl.entered_s) e["obstacle_entered_s"] = *fl.entered_s;
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
  j["plan_ms"] = TimesJson(p.plan_ms);
  j["rescue_ms"] = TimesJson(p.rescue_ms);
  j["candidates_mean"] = p.plan_ms.empty() ? 0.0 : p.candidates / p.plan_ms.size();
  j["not_ok_cycles"] = p.not_ok_cycles;
  j["rescued_cycles"] = p.rescued_cycles;
  j["tracking_error_max_m"] = p.tracking_error_max_m;
  j["computation_s"] = p.computation_s;
  j["costs"] = p.costs;
  if (p.reference) j["reference"] = ReferenceJson(p, dt);
  if (p.way_through) {
    const cr::WayThrough& w = *p.way_through;
    j["way_through"] = {{"found", w.found},
                        {"last_step", w.last_step},
                        {"survived_to", w.survived_to},
                        {"exhaustive", w.exhaustive},
                        {"goal_step", w.goal_step >= 0 ? json(w.goal_step) : json(nullptr)},
                        {"goal_searched_to", w.goal_searched_to},
                        {"states_checked", w.checked}};
  }
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
  for (const ProblemReport& p : f.problems) problems.push_back(ProblemJson(p, f.dt));
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

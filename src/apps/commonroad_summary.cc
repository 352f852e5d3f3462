#include "apps/commonroad_summary.h"

#include <algorithm>
#include <cstdio>
#include <set>

namespace frenetic::apps::commonroad_cli {

using nlohmann::json;

namespace {

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

std::string Format(const char* format, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), format, args...);
  return buf;
}

}  // namespace

namespace {

void Count(const ProblemReport& p, Comparison* c) {
  if (!p.reference) return;
  ++c->with_reference;
  switch (CompareOutcome(p)) {
    case Outcome::kInfeasibleAtStart: ++c->infeasible_at_start; break;
    case Outcome::kBothReachGoal: ++c->both_reach_goal; break;
    case Outcome::kOnlyOurs: ++c->only_ours; break;
    case Outcome::kOnlyReference: ++c->only_reference; break;
    case Outcome::kNeither: ++c->neither; break;
  }
  c->ours_cheaper_wx1 += OursCheaper(p, "WX1").value_or(false);
  c->ours_cheaper_jb1 += OursCheaper(p, "JB1").value_or(false);
}

}  // namespace

Summary Summarise(const std::vector<FileReport>& files,
                  const std::map<std::string, std::string>& solution_files) {
  Summary s;
  s.comparison.solution_files = static_cast<int>(solution_files.size());
  std::set<std::string> scenarios;
  for (const FileReport& f : files) {
    if (!f.error.empty()) {
      ++s.unreadable_files;
      continue;
    }
    scenarios.insert(f.benchmark_id);
    for (const ProblemReport& p : f.problems) {
      Count(p, &s.comparison);
      ++s.problems;
      s.solved += p.verdict.solved;
      if (!p.road_error.empty()) ++s.failures["road"];
      std::set<std::string> kinds;
      for (const cr::Failure& fl : p.verdict.failures) kinds.insert(cr::ToString(fl.kind));
      for (const std::string& k : kinds) ++s.failures[k];
      s.plan_ms.insert(s.plan_ms.end(), p.plan_ms.begin(), p.plan_ms.end());
      s.candidates += p.candidates;
    }
  }
  for (const auto& [id, path] : solution_files) {
    if (!scenarios.count(id)) s.comparison.unpaired.push_back(path);
  }
  return s;
}

namespace {

double Share(int part, int whole) { return whole > 0 ? static_cast<double>(part) / whole : 0.0; }

json ComparisonJson(const Comparison& c) {
  return {{"solution_files", c.solution_files},
          {"unpaired_solution_files", c.unpaired},
          {"with_reference", c.with_reference},
          {"infeasible_at_start", c.infeasible_at_start},
          {"compared", c.with_reference - c.infeasible_at_start},
          {"both_reach_goal", c.both_reach_goal},
          {"ours_cheaper_wx1", c.ours_cheaper_wx1},
          {"ours_cheaper_wx1_share", Share(c.ours_cheaper_wx1, c.both_reach_goal)},
          {"ours_cheaper_jb1", c.ours_cheaper_jb1},
          {"only_ours", c.only_ours},
          {"only_human", c.only_reference},
          {"neither", c.neither}};
}

std::string ComparisonText(const Comparison& c) {
  std::string text = Format(
      "vs the reference (human) trajectories: %d problem(s) with one, %d infeasible at start "
      "(not compared)\n",
      c.with_reference, c.infeasible_at_start);
  text += Format("  both reach the goal %d: ours cheaper (WX1 lower) in %d = %.0f%%, JB1 lower in "
                 "%d\n",
                 c.both_reach_goal, c.ours_cheaper_wx1,
                 100 * Share(c.ours_cheaper_wx1, c.both_reach_goal), c.ours_cheaper_jb1);
  text += Format("  only ours reaches the goal %d, only the human %d, neither %d\n", c.only_ours,
                 c.only_reference, c.neither);
  return text;
}

}  // namespace

json SummaryJson(const Summary& s, const SummarySettings& settings) {
  const size_t cycles = s.plan_ms.size();
  json j = {{"prediction", settings.prediction},
          {"vehicle", "KS" + std::to_string(settings.vehicle_type)},
          {"problems", s.problems},
          {"solved", s.solved},
          {"unreadable_files", s.unreadable_files},
          {"failures", s.failures},
          {"cycles", static_cast<int>(cycles)},
          {"plan_ms",
           {{"p50", Percentile(s.plan_ms, 0.5)},
            {"p99", Percentile(s.plan_ms, 0.99)},
            {"max", Max(s.plan_ms)}}},
          {"candidates_mean", cycles ? s.candidates / cycles : 0.0}};
  if (s.comparison.solution_files > 0) j["comparison"] = ComparisonJson(s.comparison);
  return j;
}

std::string SummaryText(const Summary& s, const SummarySettings& settings) {
  const size_t cycles = s.plan_ms.size();
  std::string text = Format("\nsolved %d / %d problems (%s predictions, KS%d)", s.solved,
                            s.problems, settings.prediction.c_str(), settings.vehicle_type);
  if (s.unreadable_files > 0) text += Format(", %d file(s) unreadable", s.unreadable_files);
  text += "\n";
  if (!s.failures.empty()) {
    text += "failures:";
    for (const auto& [k, v] : s.failures) text += Format(" %s %d", k.c_str(), v);
    text += "\n";
  }
  text += Format("planning per cycle: p50 %.2f ms, p99 %.2f ms, max %.2f ms over %d cycles\n",
                 Percentile(s.plan_ms, 0.5), Percentile(s.plan_ms, 0.99), Max(s.plan_ms),
                 static_cast<int>(cycles));
  text += Format("candidates per cycle: mean %.0f\n", cycles ? s.candidates / cycles : 0.0);
  if (s.comparison.solution_files > 0) text += ComparisonText(s.comparison);
  return text;
}

}  // namespace frenetic::apps::commonroad_cli

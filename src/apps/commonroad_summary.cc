#include "apps/commonroad_summary.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <set>

#include "commonroad/xml_source.h"
#include "frenetic/percentile.h"

namespace frenetic::apps::commonroad_cli {

using nlohmann::json;

std::string Family(std::string_view benchmark_id) {
  std::string_view map = benchmark_id.substr(0, benchmark_id.find('-'));
  size_t digits = map.size();
  while (digits > 0 && std::isdigit(static_cast<unsigned char>(map[digits - 1]))) --digits;
  if (digits > 0 && digits < map.size() &&
      std::islower(static_cast<unsigned char>(map[digits - 1]))) {
    map = map.substr(0, digits);
  }
  return std::string(map);
}

std::string FirstFailure(const ProblemReport& p) {
  if (!p.road_error.empty()) return "road";
  // The goal is judged at the trajectory's last state: a miss there is the reason only when
  // nothing else failed (a run ends at its first collision or departure from the road).
  const cr::Failure* first = nullptr;
  for (const cr::Failure& f : p.verdict.failures) {
    if (f.kind == cr::FailureKind::kGoal) continue;
    if (first == nullptr || f.step < first->step) first = &f;
  }
  if (first == nullptr) first = p.verdict.Find(cr::FailureKind::kGoal);
  return first != nullptr ? cr::ToString(first->kind) : "unknown";
}

namespace {

std::string Format(const char* format, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), format, args...);
  return buf;
}

void Count(const ProblemReport& p, Counts* c) {
  ++c->problems;
  c->plan_ms.insert(c->plan_ms.end(), p.plan_ms.begin(), p.plan_ms.end());
  c->rescue_ms.insert(c->rescue_ms.end(), p.rescue_ms.begin(), p.rescue_ms.end());
  if (p.verdict.infeasible_at_start) {
    ++c->infeasible_at_start;
  } else if (p.verdict.solved) {
    ++c->solved;
  } else {
    const std::string first = FirstFailure(p);
    ++c->unsolved[first];
    const cr::Failure* hit = p.verdict.Find(cr::FailureKind::kCollision);
    if (first == "collision" && hit != nullptr && hit->entered_s &&
        *hit->entered_s <= kEnteringSeconds + 1e-9) {
      ++c->collisions_entering;
    }
  }
}

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
    Counts& family = s.families[Family(f.benchmark_id)];
    for (const ProblemReport& p : f.problems) {
      Count(p, &s.all);
      Count(p, &family);
      Count(p, &s.comparison);
      s.candidates += p.candidates;
      if (p.way_through) {
        ++s.way_searched;
        s.way_found += p.way_through->found;
        s.way_none_exhaustive += !p.way_through->found && p.way_through->exhaustive;
        s.way_to_goal += p.way_through->goal_step >= 0;
      }
      if (p.verdict.solved || p.verdict.infeasible_at_start) continue;
      if (!p.road_error.empty()) ++s.failures["road"];
      std::set<std::string> kinds;
      for (const cr::Failure& fl : p.verdict.failures) kinds.insert(cr::ToString(fl.kind));
      for (const std::string& k : kinds) ++s.failures[k];
    }
  }
  for (const auto& [id, path] : solution_files) {
    if (!scenarios.count(id)) s.comparison.unpaired.push_back(path);
  }
  return s;
}

namespace {

double Share(int part, int whole) { return whole > 0 ? static_cast<double>(part) / whole : 0.0; }

json CountsJson(const Counts& c) {
  return {{"problems", c.problems},
          {"infeasible_at_start", c.infeasible_at_start},
          {"solved", c.solved},
          {"solved_share", Share(c.solved, c.problems - c.infeasible_at_start)},
          {"unsolved", c.unsolved},
          {"collisions_entering", c.collisions_entering},
          {"cycles", static_cast<int>(c.plan_ms.size())},
          {"plan_ms", TimesJson(c.plan_ms)},
          {"rescue_ms", TimesJson(c.rescue_ms)}};
}

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

std::string Reasons(const std::map<std::string, int>& reasons) {
  std::string text;
  for (const auto& [k, v] : reasons) text += Format("%s%s %d", text.empty() ? "" : ", ", k.c_str(), v);
  return text.empty() ? "-" : text;
}

std::string FamilyTable(const Summary& s) {
  size_t width = 3;
  for (const auto& [name, c] : s.families) {
    width = std::max(width, commonroad::Printable(name).size());
  }
  const int w = static_cast<int>(width);
  std::string text =
      Format("by family (solved of the problems feasible at start; planning time per cycle; "
             "unsolved by first failure):\n  %-*s  problems  infeasible     solved    p50 ms    "
             "p99 ms    max ms  unsolved\n",
             w, "family");
  auto row = [&](const std::string& name, const Counts& c) {
    text += Format("  %-*s  %8d  %10d  %9s  %8.2f  %8.2f  %8.2f  %s\n", w,
                   commonroad::Printable(name).c_str(),
                   c.problems, c.infeasible_at_start,
                   Format("%d / %d", c.solved, c.problems - c.infeasible_at_start).c_str(),
                   Percentile(c.plan_ms, 0.5), Percentile(c.plan_ms, 0.99), Max(c.plan_ms),
                   Reasons(c.unsolved).c_str());
  };
  for (const auto& [name, c] : s.families) row(name, c);
  row("all", s.all);
  return text;
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
  const Counts& a = s.all;
  const size_t cycles = a.plan_ms.size();
  json families = json::object();
  for (const auto& [name, c] : s.families) families[name] = CountsJson(c);
  json j = {{"prediction", settings.prediction},
            {"vehicle", "KS" + std::to_string(settings.vehicle_type)},
            {"problems", a.problems},
            {"infeasible_at_start", a.infeasible_at_start},
            {"solved", a.solved},
            {"solved_share", Share(a.solved, a.problems - a.infeasible_at_start)},
            {"unsolved", a.unsolved},
            {"collisions_entering", a.collisions_entering},
            {"unreadable_files", s.unreadable_files},
            {"failures", s.failures},
            {"cycles", static_cast<int>(cycles)},
            {"plan_ms", TimesJson(a.plan_ms)},
            {"rescue_ms", TimesJson(a.rescue_ms)},
            {"candidates_mean", cycles ? s.candidates / cycles : 0.0},
            {"families", families}};
  if (s.comparison.solution_files > 0) j["comparison"] = ComparisonJson(s.comparison);
  if (s.way_searched > 0) {
    j["way_through"] = {{"searched", s.way_searched},
                        {"found", s.way_found},
                        {"none_found", s.way_searched - s.way_found},
                        {"none_found_exhaustive", s.way_none_exhaustive},
                        {"to_the_goal", s.way_to_goal}};
  }
  return j;
}

std::string SummaryText(const Summary& s, const SummarySettings& settings) {
  const Counts& a = s.all;
  const size_t cycles = a.plan_ms.size();
  std::string text = Format(
      "\nsolved %d / %d problems feasible at start (%d infeasible at start, %d in all; %s "
      "predictions, KS%d)",
      a.solved, a.problems - a.infeasible_at_start, a.infeasible_at_start, a.problems,
      settings.prediction.c_str(), settings.vehicle_type);
  if (s.unreadable_files > 0) text += Format(", %d file(s) unreadable", s.unreadable_files);
  text += "\n";
  if (!s.failures.empty()) {
    text += "failures:";
    for (const auto& [k, v] : s.failures) text += Format(" %s %d", k.c_str(), v);
    text += "\n";
  }
  text += Format("planning per cycle: p50 %.2f ms, p99 %.2f ms, max %.2f ms over %d cycles\n",
                 Percentile(a.plan_ms, 0.5), Percentile(a.plan_ms, 0.99), Max(a.plan_ms),
                 static_cast<int>(cycles));
  text += Format("  of it the rescue's checks and searches: p50 %.2f ms, p99 %.2f ms, max %.2f ms\n",
                 Percentile(a.rescue_ms, 0.5), Percentile(a.rescue_ms, 0.99), Max(a.rescue_ms));
  text += Format("candidates per cycle: mean %.0f\n", cycles ? s.candidates / cycles : 0.0);
  text += FamilyTable(s);
  if (a.unsolved.count("collision") > 0) {
    std::string by_family;
    for (const auto& [name, c] : s.families) {
      if (c.collisions_entering > 0) {
        by_family += Format("%s%s %d", by_family.empty() ? "" : ", ",
                            commonroad::Printable(name).c_str(), c.collisions_entering);
      }
    }
    text += Format(
        "collisions with a car that came into the scene at most %.0f s before it hit "
        "(after the start): %d of %d",
        kEnteringSeconds, a.collisions_entering, a.unsolved.at("collision"));
    text += by_family.empty() ? "\n" : " (" + by_family + ")\n";
  }
  if (s.comparison.solution_files > 0) text += ComparisonText(s.comparison);
  if (s.way_searched > 0) {
    text += Format(
        "way through the traffic (--way-through) of the %d unsolved problems: found for %d, none "
        "found for %d (%d with no step capped); a way to a goal state found for %d\n",
        s.way_searched, s.way_found, s.way_searched - s.way_found, s.way_none_exhaustive,
        s.way_to_goal);
  }
  return text;
}

}  // namespace frenetic::apps::commonroad_cli

#include "apps/commonroad_reference.h"

#include <cmath>
#include <filesystem>
#include <set>

#include "frenetic/commonroad/cost.h"
#include "frenetic/commonroad/setup.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/commonroad/verdict.h"

namespace frenetic::apps::commonroad_cli {

bool IsSolutionFile(const std::string& path) {
  return cr::PeekRootElement(path) == "CommonRoadSolution";
}

StatusOr<std::vector<std::string>> CompareFiles(const std::vector<std::string>& paths) {
  std::string named;
  for (const std::string& p : paths) named += (named.empty() ? "" : ", ") + p;
  auto files = cr::ScenarioFiles(paths);
  if (!files.ok()) {
    // Its only other error names no path: there is no *.xml at all.
    if (files.message().rfind("no scenario files", 0) == 0) {
      return Status::Error("--compare " + named + ": no CommonRoad solution files (*.xml)");
    }
    return Status::Error("--compare: " + files.message());
  }
  std::vector<std::string> out;
  for (const std::string& f : *files) {
    if (IsSolutionFile(f)) out.push_back(f);
  }
  if (out.empty()) {
    return Status::Error("--compare " + named + ": no CommonRoad solution files (*.xml)");
  }
  return out;
}

ReferenceSet LoadReferences(const std::vector<std::string>& files) {
  ReferenceSet set;
  std::set<std::string> seen;
  for (const std::string& path : files) {
    std::error_code ec;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
    if (!seen.insert(ec ? path : canonical.string()).second) continue;
    auto solution = cr::LoadSolution(path);
    if (!solution.ok()) {
      set.unreadable.push_back({path, solution.message()});
      continue;
    }
    const std::string id = solution->scenario_id;
    const auto [at, inserted] = set.by_scenario.emplace(id, Reference{path, std::move(*solution)});
    if (!inserted) {
      set.notes.push_back(path + ": ignored, " + at->second.path + " is already the solution for " +
                          id);
    }
  }
  return set;
}

StatusOr<Inputs> SortInputs(const std::vector<std::string>& files,
                            const std::vector<std::string>& compare) {
  std::vector<std::string> solution_files;
  std::vector<bool> is_solution;
  for (const std::string& f : files) {
    is_solution.push_back(IsSolutionFile(f));
    if (is_solution.back()) solution_files.push_back(f);
  }
  if (solution_files.size() == files.size()) {
    return Status::Error("no scenario files among the paths (" +
                         std::to_string(solution_files.size()) + " solution file(s))");
  }
  if (!compare.empty()) {
    auto more = CompareFiles(compare);
    if (!more.ok()) return more.status();
    solution_files.insert(solution_files.end(), more->begin(), more->end());
  }
  Inputs in;
  in.references = LoadReferences(solution_files);
  std::map<std::string, std::string> unreadable;
  for (const ReferenceSet::Unreadable& u : in.references.unreadable) unreadable[u.path] = u.message;
  for (size_t i = 0; i < files.size(); ++i) {
    if (!is_solution[i]) {
      in.files.push_back({files[i], ""});
    } else if (const auto u = unreadable.find(files[i]); u != unreadable.end()) {
      in.files.push_back({files[i], u->second});
      unreadable.erase(u);
    }
  }
  for (const ReferenceSet::Unreadable& u : in.references.unreadable) {
    if (unreadable.count(u.path)) in.files.push_back({u.path, u.message});
  }
  return in;
}

ReferenceReport EvaluateReference(const cr::Scenario& scenario, const cr::PlanningProblem& problem,
                                  const std::string& file, const cr::SolutionTrajectory& t) {
  ReferenceReport r;
  r.file = file;
  r.vehicle_type = t.vehicle_type;
  r.cost_function = t.cost_function;
  std::vector<cr::KsState> states = t.states;  // never empty: ParseSolution rejects that
  for (cr::KsState& s : states) {              // into the scenario's local frame
    s.x -= scenario.origin.x;
    s.y -= scenario.origin.y;
  }
  r.first_step = states.front().time_step;
  r.last_step = states.back().time_step;
  r.states = static_cast<int>(states.size());
  double moved = 0, driven = 0;
  for (size_t k = 1; k < states.size(); ++k) {
    const cr::KsState &a = states[k - 1], &b = states[k];
    moved += std::hypot(b.x - a.x, b.y - a.y);
    driven += 0.5 * (a.velocity + b.velocity) * (b.time_step - a.time_step) * scenario.dt;
  }
  r.distance_ratio = driven > 0 ? moved / driven : 0.0;
  // ParseSolution accepts KS1..KS3 only.
  const cr::VehicleParams vehicle = *cr::VehicleParamsForType(t.vehicle_type);
  for (const char* id : {"WX1", "JB1"}) {
    auto c = cr::EvaluateCost(id, scenario, problem, vehicle, states);
    if (c.ok()) r.costs[id] = c->total;
  }
  const cr::GoalTest goal(scenario, problem.goals);
  for (const cr::KsState& s : states) {
    if (goal.MeetsAny(s)) {
      r.goal_step = s.time_step;
      break;
    }
  }
  const cr::Verdict verdict = cr::CheckTrajectory(scenario, problem, vehicle, states);
  if (verdict.solved) {
    r.verdict = "solved";
  } else {
    r.verdict = "failed:";
    for (size_t k = 0; k < verdict.failures.size(); ++k) {
      r.verdict += std::string(k ? ", " : " ") + cr::ToString(verdict.failures[k].kind);
    }
  }
  return r;
}

}  // namespace frenetic::apps::commonroad_cli

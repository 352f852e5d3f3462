// frenetic commonroad: closed-loop planning through CommonRoad scenarios (runner.h), each problem
// judged by the verdict (verdict.h), with a summary over all of them.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "frenetic/commonroad/cost.h"
#include "frenetic/commonroad/record.h"
#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/setup.h"
#include "frenetic/commonroad/solution.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::apps {
namespace {

namespace cr = commonroad;
using nlohmann::json;

struct Args {
  std::vector<std::string> paths;
  std::string prediction = "recorded";
  int vehicle = 2;
  std::string config_path;
  std::string overlay_path;
  std::string solution_dir;
  std::string record_dir;
  bool json = false;
  int jobs = 0;
  bool progress = false;
  bool no_timing = false;
};

int Fail(const std::string& message) {
  std::fprintf(stderr, "frenetic commonroad: %s\n", message.c_str());
  return 1;
}

// One file's outcome.
struct FileResult {
  std::string path;
  Status read;  // the scenario's parse
  cr::ScenarioRun run;
  // Per problem: the costs (when the trajectory has states) and the solution file written.
  std::vector<std::map<std::string, double>> costs;
  std::string solution_file;
  Status solution_status;
  Status record_status;  // the records' (--record)
  cr::Vec2 origin;       // the scenario's local frame (Scenario::origin)
};

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  return v[i];
}

// --record DIR: created when missing; an error names it when it is no writable directory.
Status RecordDirWritable(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::Error("--record " + dir + ": " + ec.message());
  if (!std::filesystem::is_directory(dir, ec)) {
    return Status::Error("--record " + dir + ": not a directory");
  }
  const std::filesystem::path probe =
      std::filesystem::path(dir) / (".frenetic-record-" + std::to_string(::getpid()));
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (f == nullptr) return Status::Error("--record " + dir + ": " + std::strerror(errno));
  std::fclose(f);
  std::filesystem::remove(probe, ec);
  return Status::Ok();
}

FileResult RunFile(const std::string& path, const plan::PlannerConfig& config,
                   const cr::RunOptions& options, const std::string& solution_dir,
                   const std::string& record_dir) {
  FileResult r;
  r.path = path;
  auto scenario = cr::LoadScenario(path);
  if (!scenario.ok()) {
    r.read = scenario.status();
    return r;
  }
  r.origin = scenario->origin;
  if (record_dir.empty()) {
    r.run = cr::RunScenario(*scenario, config, options);
  } else {
    cr::RunRecorder recorder(*scenario, record_dir, options.vehicle_type, options.prediction,
                             options.timing);
    cr::RunOptions recorded = options;
    recorder.Attach(&recorded);
    r.run = cr::RunScenario(*scenario, config, recorded);
    r.record_status = recorder.status();
  }
  const cr::VehicleParams vehicle = *cr::VehicleParamsForType(options.vehicle_type);
  cr::Solution solution;
  solution.scenario_id = scenario->benchmark_id;
  solution.date = cr::CurrentDate();
  solution.processor_name = cr::ProcessorName();
  double computation = 0;
  for (size_t i = 0; i < r.run.problems.size(); ++i) {
    const cr::ProblemRun& p = r.run.problems[i];
    std::map<std::string, double> costs;
    const cr::PlanningProblem* problem = scenario->FindProblem(p.problem_id);
    if (problem != nullptr && !p.trajectory.empty()) {
      for (const char* id : {"WX1", "JB1"}) {
        auto c = cr::EvaluateCost(id, *scenario, *problem, vehicle, p.trajectory);
        if (c.ok()) costs[id] = c->total;
      }
    }
    r.costs.push_back(costs);
    computation += p.computation_s;
    if (!p.trajectory.empty()) {
      cr::SolutionTrajectory t;
      t.problem_id = p.problem_id;
      t.vehicle_type = options.vehicle_type;
      t.cost_function = "WX1";
      t.states = p.trajectory;
      for (cr::KsState& st : t.states) {  // in the file's frame
        st.x += scenario->origin.x;
        st.y += scenario->origin.y;
      }
      solution.trajectories.push_back(std::move(t));
    }
  }
  if (options.timing) solution.computation_time = computation;
  if (!solution_dir.empty() && !solution.trajectories.empty()) {
    r.solution_status = cr::SaveSolution(solution, solution_dir);
    if (r.solution_status.ok()) r.solution_file = solution.FileName();
  }
  return r;
}

json ProblemJson(const FileResult& f, size_t i) {
  const cr::ProblemRun& p = f.run.problems[i];
  json j;
  j["problem"] = p.problem_id;
  j["solved"] = p.verdict.solved;
  if (!p.road.ok()) j["road_error"] = p.road.message();
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
  j["stop"] = p.stop_reason;
  j["steps"] = static_cast<int>(p.cycles.size());
  j["lanes"] = p.lanes;
  j["road_length_m"] = p.road_length;
  j["route"] = p.route;
  std::vector<double> ms;
  double cands = 0, track = 0;
  int fallbacks = 0;
  for (const cr::RunCycle& c : p.cycles) {
    ms.push_back(c.plan_ms);
    cands += c.candidates;
    track = std::max(track, c.tracking_error);
    fallbacks += c.status != plan::PlanStatus::kOk;
  }
  j["plan_ms"] = {{"p50", Percentile(ms, 0.5)}, {"p99", Percentile(ms, 0.99)},
                  {"max", ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end())}};
  j["candidates_mean"] = p.cycles.empty() ? 0.0 : cands / p.cycles.size();
  j["not_ok_cycles"] = fallbacks;
  j["tracking_error_max_m"] = track;
  j["computation_s"] = p.computation_s;
  j["costs"] = f.costs.size() > i ? json(f.costs[i]) : json::object();
  return j;
}

std::string ProblemLine(const FileResult& f, size_t i) {
  const cr::ProblemRun& p = f.run.problems[i];
  char buf[512];
  std::string verdict;
  if (p.verdict.infeasible_at_start) {
    verdict = p.verdict.Summary();
  } else if (!p.road.ok()) {
    verdict = "no road: " + p.road.message();
  } else if (p.verdict.solved) {
    verdict = "solved, goal at step " + std::to_string(*p.verdict.goal_step);
  } else {
    verdict = "FAILED: ";
    for (size_t k = 0; k < p.verdict.failures.size(); ++k) {
      const cr::Failure& fl = p.verdict.failures[k];
      if (k > 0) verdict += "; ";
      verdict += std::string(cr::ToString(fl.kind)) + " at step " + std::to_string(fl.step) +
                 (fl.detail.empty() ? "" : " (" + fl.detail + ")");
    }
  }
  std::vector<double> ms;
  for (const cr::RunCycle& c : p.cycles) ms.push_back(c.plan_ms);
  std::snprintf(buf, sizeof(buf), "%-24s #%-5d %d lanes %5.0f m  %3zu steps  plan p50 %.2f p99 %.2f ms",
                f.run.benchmark_id.c_str(), p.problem_id, p.lanes, p.road_length, p.cycles.size(),
                Percentile(ms, 0.5), Percentile(ms, 0.99));
  std::string line = buf;
  if (f.costs.size() > i && f.costs[i].count("WX1")) {
    std::snprintf(buf, sizeof(buf), "  WX1 %.1f  JB1 %.1f", f.costs[i].at("WX1"),
                  f.costs[i].count("JB1") ? f.costs[i].at("JB1") : 0.0);
    line += buf;
  }
  return line + "\n    " + verdict + "\n";
}

int Run(const Args& a) {
  auto prediction = cr::ParsePredictionMode(a.prediction);
  if (!prediction.ok()) return Fail("--prediction: " + prediction.message());
  cr::RunOptions options;
  options.prediction = *prediction;
  options.vehicle_type = a.vehicle;
  options.timing = !a.no_timing;
  if (Status st = options.Validate(); !st.ok()) return Fail("--vehicle: " + st.message());
  auto files = cr::ScenarioFiles(a.paths);
  if (!files.ok()) return Fail(files.message());
  if (!a.solution_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.solution_dir, ec);
    if (ec) return Fail("--solution-dir " + a.solution_dir + ": " + ec.message());
  }
  if (!a.record_dir.empty()) {
    if (Status st = RecordDirWritable(a.record_dir); !st.ok()) return Fail(st.message());
  }
  const std::string config_path =
      a.config_path.empty() ? plan::PlannerConfig::DefaultPath() : a.config_path;
  auto base = cr::LoadBaseConfig(config_path, a.overlay_path);
  if (!base.ok()) return Fail(base.message());
  auto config = cr::CommonRoadConfig(*base, *cr::VehicleParamsForType(a.vehicle), *prediction);
  if (!config.ok()) return Fail(config_path + ": " + config.message());

  const int n = static_cast<int>(files->size());
  std::vector<FileResult> results(n);
  const int jobs = std::clamp(a.jobs > 0 ? a.jobs : static_cast<int>(std::thread::hardware_concurrency()), 1, n);
  std::atomic<int> next{0}, done{0}, solved{0}, problems{0};
  std::mutex progress_mutex;
  const bool show = a.progress || isatty(fileno(stderr)) != 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      results[i] = RunFile((*files)[i], *config, options, a.solution_dir, a.record_dir);
      for (const cr::ProblemRun& p : results[i].run.problems) {
        ++problems;
        solved += p.verdict.solved;
      }
      const int d = ++done;
      if (!show) continue;
      std::lock_guard<std::mutex> lock(progress_mutex);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "%sscenarios %d/%d  solved %d/%d  elapsed %.1f s%s",
                   isatty(fileno(stderr)) ? "\r" : "", d, n, solved.load(), problems.load(), s,
                   isatty(fileno(stderr)) && d < n ? "   " : "\n");
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();

  // Summary.
  int total = 0, ok = 0, unreadable = 0;
  std::map<std::string, int> reasons;
  std::vector<double> ms;
  double cands = 0;
  int cycles = 0;
  for (const FileResult& f : results) {
    if (!f.read.ok()) {
      ++unreadable;
      continue;
    }
    for (const cr::ProblemRun& p : f.run.problems) {
      ++total;
      ok += p.verdict.solved;
      if (!p.road.ok()) ++reasons["road"];
      std::set<std::string> kinds;
      for (const cr::Failure& fl : p.verdict.failures) kinds.insert(cr::ToString(fl.kind));
      for (const std::string& k : kinds) ++reasons[k];
      for (const cr::RunCycle& c : p.cycles) {
        ms.push_back(c.plan_ms);
        cands += c.candidates;
        ++cycles;
      }
    }
  }
  const double max_ms = ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end());
  if (a.json) {
    json out;
    json files_json = json::array();
    for (const FileResult& f : results) {
      json fj = {{"path", f.path}};
      if (!f.read.ok()) {
        fj["error"] = f.read.message();
      } else {
        fj["benchmark_id"] = f.run.benchmark_id;
        // Read into a local frame (Scenario::origin): positions in failures are relative to it.
        if (!(f.origin == cr::Vec2{})) fj["frame_origin"] = {f.origin.x, f.origin.y};
        json probs = json::array();
        for (size_t i = 0; i < f.run.problems.size(); ++i) probs.push_back(ProblemJson(f, i));
        fj["problems"] = probs;
        if (!f.solution_file.empty()) fj["solution_file"] = f.solution_file;
        if (!f.solution_status.ok()) fj["solution_error"] = f.solution_status.message();
      }
      files_json.push_back(fj);
    }
    out["scenarios"] = files_json;
    out["summary"] = {{"prediction", cr::ToString(*prediction)},
                      {"vehicle", "KS" + std::to_string(a.vehicle)},
                      {"problems", total},
                      {"solved", ok},
                      {"unreadable_files", unreadable},
                      {"failures", reasons},
                      {"cycles", cycles},
                      {"plan_ms", {{"p50", Percentile(ms, 0.5)}, {"p99", Percentile(ms, 0.99)}, {"max", max_ms}}},
                      {"candidates_mean", cycles ? cands / cycles : 0.0}};
    std::printf("%s\n", out.dump().c_str());
  } else {
    for (const FileResult& f : results) {
      if (!f.read.ok()) {
        std::printf("%s\n    UNREADABLE: %s\n", f.path.c_str(), f.read.message().c_str());
        continue;
      }
      for (size_t i = 0; i < f.run.problems.size(); ++i) std::printf("%s", ProblemLine(f, i).c_str());
      if (!f.solution_status.ok()) std::printf("    solution: %s\n", f.solution_status.message().c_str());
    }
    std::printf("\nsolved %d / %d problems (%s predictions, KS%d)", ok, total,
                cr::ToString(*prediction), a.vehicle);
    if (unreadable > 0) std::printf(", %d file(s) unreadable", unreadable);
    std::printf("\n");
    if (!reasons.empty()) {
      std::printf("failures:");
      for (const auto& [k, v] : reasons) std::printf(" %s %d", k.c_str(), v);
      std::printf("\n");
    }
    std::printf("planning per cycle: p50 %.2f ms, p99 %.2f ms, max %.2f ms over %d cycles\n",
                Percentile(ms, 0.5), Percentile(ms, 0.99), max_ms, cycles);
    std::printf("candidates per cycle: mean %.0f\n", cycles ? cands / cycles : 0.0);
  }
  // Records do not change the results above: a failure to write one is told on stderr.
  int record_errors = 0;
  for (const FileResult& f : results) {
    if (f.record_status.ok()) continue;
    ++record_errors;
    std::fprintf(stderr, "frenetic commonroad: --record: %s\n", f.record_status.message().c_str());
  }
  return unreadable > 0 || record_errors > 0 ? 1 : 0;
}

}  // namespace

void RegisterCommonRoad(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand(
      "commonroad",
      "Plan closed-loop through CommonRoad scenarios (format 2020a): every planning problem of "
      "every file, the other traffic following its recording, each step replanned; each "
      "problem's KS trajectory is judged like CommonRoad's solution checker (goal, collision, "
      "road, kinematic limits, KS dynamics). Unsolved problems are results: the exit status is "
      "0 unless a file could not be read (1).");
  sub->add_option("paths", args->paths, "Scenario files (.xml) or directories of them")
      ->required();
  sub->add_option("--prediction", args->prediction,
                  "recorded (the other cars' recorded trajectories, the benchmark's convention "
                  "for T scenarios) or constant-velocity (the planner's own prediction from the "
                  "present only). Default: recorded");
  sub->add_option("--vehicle", args->vehicle,
                  "CommonRoad vehicle type: 1 Ford Escort, 2 BMW 320i, 3 VW Vanagon (KS model). "
                  "Default: 2")
      ->check(CLI::Range(1, 3));
  sub->add_option("--config", args->config_path,
                  "Planner configuration YAML (the ego's footprint and kinematic limits are set "
                  "from the vehicle). Default: config/planner.yaml");
  sub->add_option("--commonroad-config", args->overlay_path,
                  "What differs from --config on CommonRoad scenarios (any planner.yaml keys). "
                  "Default: config/commonroad.yaml");
  sub->add_option("--solution-dir", args->solution_dir,
                  "Write a CommonRoad solution file per scenario into DIR "
                  "(solution_KS2:WX1:<scenario id>:2020a.xml). Default: none");
  sub->add_option("--record", args->record_dir,
                  "Write a record of each planning problem's run into DIR (created if missing): "
                  "<scenario id>_<problem id>.jsonl.gz, the drive record's format with the "
                  "road's lane borders, the goal regions, the obstacles with their sizes, the "
                  "ego, its planned path and up to 40 candidates per cycle; `frenetic report "
                  "FILE` replays it. The results do not change (the candidates are traced by a "
                  "replica of the planner, off the planning thread). Default: none");
  sub->add_flag("--json", args->json, "Print the results as one JSON object on stdout");
  sub->add_option("--jobs", args->jobs,
                  "Scenario files planned in parallel (0 = all cores). Results do not depend on "
                  "it. Default: 0")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--progress", args->progress,
                "Show the progress line on stderr even when it is not a terminal");
  sub->add_flag("--no-timing", args->no_timing,
                "Report planning times as 0 (byte-stable output for the same files)");
  sub->callback([args] { ExitWith(Run(*args)); });
}

}  // namespace frenetic::apps

// frenetic commonroad: closed-loop planning through CommonRoad scenarios (runner.h), each problem
// judged by the verdict (verdict.h), with a summary over all of them. Here: the options, set-up,
// running this process's share of the files; the reports and their output live in
// commonroad_report.h, the summary in commonroad_summary.h, the reference trajectories in
// commonroad_reference.h, the split across MPI ranks in commonroad_mpi.h.
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
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "apps/commonroad_mpi.h"
#include "apps/commonroad_reference.h"
#include "apps/commonroad_report.h"
#include "apps/commonroad_summary.h"
#include "frenetic/commonroad/cost.h"
#include "frenetic/commonroad/record.h"
#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/setup.h"
#include "frenetic/commonroad/solution.h"
#include "frenetic/cores.h"
#include "frenetic/json_text.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/tune/cluster.h"

namespace frenetic::apps {
namespace {

namespace cr = commonroad;
using nlohmann::json;
using commonroad_cli::FileJson;
using commonroad_cli::FileReport;
using commonroad_cli::FileText;
using commonroad_cli::InputFile;
using commonroad_cli::ProblemReport;
using commonroad_cli::ReferenceSet;
using commonroad_cli::Summarise;
using commonroad_cli::Summary;
using commonroad_cli::SummaryJson;
using commonroad_cli::SummarySettings;
using commonroad_cli::SummaryText;

struct Args {
  std::vector<std::string> paths;
  std::string prediction = "recorded";
  int vehicle = 2;
  std::string config_path;
  std::string overlay_path;
  std::string solution_dir;
  std::string record_dir;
  std::vector<std::string> compare;
  bool json = false;
  int jobs = 0;
  bool progress = false;
  bool no_timing = false;
  bool no_rescue = false;
  int rescue_retry = commonroad::RescueOptions().retry_states;
  bool way_through = false;
};

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

// What the output needs of one problem's run.
ProblemReport ReportProblem(const cr::ProblemRun& run, const cr::PlanningProblem* problem) {
  ProblemReport p;
  p.problem_id = run.problem_id;
  if (!run.road.ok()) p.road_error = run.road.message();
  p.verdict = run.verdict;
  p.stop = run.stop_reason;
  if (problem != nullptr) p.initial_step = problem->initial.time_step;
  p.lanes = run.lanes;
  p.road_length_m = run.road_length;
  p.route = run.route;
  for (const cr::RunCycle& c : run.cycles) {
    p.plan_ms.push_back(c.plan_ms);
    p.rescue_ms.push_back(c.rescue_ms);
    p.candidates += c.candidates;
    p.tracking_error_max_m = std::max(p.tracking_error_max_m, c.tracking_error);
    p.not_ok_cycles += c.status != plan::PlanStatus::kOk;
    p.rescued_cycles += c.rescued;
  }
  p.computation_s = run.computation_s;
  return p;
}

FileReport RunFile(const InputFile& item, const plan::PlannerConfig& config,
                   const cr::RunOptions& options, const ReferenceSet& references,
                   const std::string& solution_dir, const std::string& record_dir,
                   bool way_through) {
  FileReport r;
  r.path = item.path;
  if (!item.error.empty()) {
    r.error = item.error;
    return r;
  }
  const std::string& path = item.path;
  auto scenario = cr::LoadScenario(path);
  if (!scenario.ok()) {
    r.error = scenario.message();
    return r;
  }
  r.origin = scenario->origin;
  r.dt = scenario->dt;
  cr::ScenarioRun run;
  if (record_dir.empty()) {
    run = cr::RunScenario(*scenario, config, options);
  } else {
    cr::RunRecorder recorder(*scenario, record_dir, options.vehicle_type, options.prediction,
                             options.timing);
    cr::RunOptions recorded = options;
    recorder.Attach(&recorded);
    run = cr::RunScenario(*scenario, config, recorded);
    if (!recorder.status().ok()) r.record_error = recorder.status().message();
  }
  r.benchmark_id = run.benchmark_id;
  const auto reference = references.by_scenario.find(scenario->benchmark_id);
  const cr::VehicleParams vehicle = *cr::VehicleParamsForType(options.vehicle_type);
  cr::Solution solution;
  solution.scenario_id = scenario->benchmark_id;
  solution.date = cr::CurrentDate();
  solution.processor_name = cr::ProcessorName();
  double computation = 0;
  std::optional<cr::VerdictChecker> checker;  // --way-through's, built for the first search
  for (const cr::ProblemRun& p : run.problems) {
    const cr::PlanningProblem* problem = scenario->FindProblem(p.problem_id);
    ProblemReport& report = r.problems.emplace_back(ReportProblem(p, problem));
    // A problem infeasible at start planned nothing: its one state has no costs to speak of.
    if (problem != nullptr && !p.trajectory.empty() && !p.verdict.infeasible_at_start) {
      for (const char* id : {"WX1", "JB1"}) {
        auto c = cr::EvaluateCost(id, *scenario, *problem, vehicle, p.trajectory);
        if (c.ok()) report.costs[id] = c->total;
      }
    }
    if (problem != nullptr && reference != references.by_scenario.end()) {
      for (const cr::SolutionTrajectory& t : reference->second.solution.trajectories) {
        if (t.problem_id != p.problem_id) continue;
        report.reference =
            commonroad_cli::EvaluateReference(*scenario, *problem, reference->second.path, t);
        break;
      }
    }
    if (way_through && problem != nullptr && p.road.ok() && !p.verdict.solved &&
        !p.verdict.infeasible_at_start) {
      if (!checker) checker.emplace(*scenario, vehicle);
      report.way_through = cr::SearchWayThrough(*scenario, *problem, *checker, vehicle);
    }
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
  // commonroad-io's reader asserts a computation time above 0: none is written when no cycle ran
  // (every problem infeasible at start) or the clock read 0.
  if (options.timing && computation > 0) solution.computation_time = computation;
  if (!solution_dir.empty() && !solution.trajectories.empty()) {
    const Status saved = cr::SaveSolution(solution, solution_dir);
    if (saved.ok()) {
      r.solution_file = solution.FileName();
    } else {
      r.solution_error = saved.message();
    }
  }
  return r;
}

// Everything a run needs, made from the arguments alone (the same on every rank).
struct Setup {
  cr::PredictionMode prediction = cr::PredictionMode::kRecorded;
  cr::RunOptions options;
  plan::PlannerConfig config;
  commonroad_cli::Inputs inputs;
};

StatusOr<Setup> Prepare(const Args& a) {
  Setup setup;
  auto prediction = cr::ParsePredictionMode(a.prediction);
  if (!prediction.ok()) return Status::Error("--prediction: " + prediction.message());
  setup.prediction = *prediction;
  setup.options.prediction = *prediction;
  setup.options.vehicle_type = a.vehicle;
  setup.options.timing = !a.no_timing;
  setup.options.rescue = !a.no_rescue;
  setup.options.rescue_retry_states = a.rescue_retry;
  if (Status st = setup.options.Validate(); !st.ok()) {
    return Status::Error("--vehicle: " + st.message());
  }
  auto files = cr::ScenarioFiles(a.paths);
  if (!files.ok()) return files.status();
  // Solution files among the paths are references, not scenarios; --compare adds more.
  auto inputs = commonroad_cli::SortInputs(*files, a.compare);
  if (!inputs.ok()) return inputs.status();
  setup.inputs = std::move(*inputs);
  if (!a.solution_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.solution_dir, ec);
    if (ec) return Status::Error("--solution-dir " + a.solution_dir + ": " + ec.message());
  }
  if (!a.record_dir.empty()) {
    if (Status st = RecordDirWritable(a.record_dir); !st.ok()) return st;
  }
  const std::string config_path =
      a.config_path.empty() ? plan::PlannerConfig::DefaultPath() : a.config_path;
  auto base = cr::LoadBaseConfig(config_path, a.overlay_path);
  if (!base.ok()) return base.status();
  auto config = cr::CommonRoadConfig(*base, *cr::VehicleParamsForType(a.vehicle), *prediction);
  if (!config.ok()) return Status::Error(config_path + ": " + config.message());
  setup.config = std::move(*config);
  return setup;
}

// Runs this rank's files (all of them on a single process) on --jobs threads; the other slots
// stay empty.
std::vector<FileReport> RunShare(const Args& a, const Setup& setup, const tune::Cluster& cluster) {
  const std::vector<InputFile>& files = setup.inputs.files;
  const int n = static_cast<int>(files.size());
  std::vector<int> mine;
  for (int i = 0; i < n; ++i) {
    if (commonroad_cli::RunsHere(i, cluster)) mine.push_back(i);
  }
  const int share = static_cast<int>(mine.size());
  std::vector<FileReport> results(n);
  const int cores = UsableCores();
  const int jobs = std::max(1, std::min(a.jobs > 0 ? a.jobs : cores, share));
  std::atomic<int> next{0}, done{0}, solved{0}, problems{0};
  std::mutex progress_mutex;
  const bool tty = isatty(fileno(stderr)) != 0;
  const bool show = a.progress || tty;
  const std::string rank =
      cluster.distributed() ? "rank " + std::to_string(cluster.rank()) + ": " : "";
  const auto t0 = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (int k = next++; k < share; k = next++) {
      const int i = mine[k];
      results[i] = RunFile(files[i], setup.config, setup.options, setup.inputs.references,
                           a.solution_dir, a.record_dir, a.way_through);
      for (const ProblemReport& p : results[i].problems) {
        ++problems;
        solved += p.verdict.solved;
      }
      const int d = ++done;
      if (!show) continue;
      std::lock_guard<std::mutex> lock(progress_mutex);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "%s%sscenarios %d/%d  solved %d/%d  elapsed %.1f s%s", tty ? "\r" : "",
                   rank.c_str(), d, share, solved.load(), problems.load(), s,
                   tty && d < share ? "   " : "\n");
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  return results;
}

// Rank 0's output from every file's report.
int Print(const Args& a, const Setup& setup, const std::vector<FileReport>& results) {
  const ReferenceSet& references = setup.inputs.references;
  std::map<std::string, std::string> solution_paths;
  for (const auto& [id, ref] : references.by_scenario) solution_paths[id] = ref.path;
  const Summary summary = Summarise(results, solution_paths);
  const SummarySettings settings{cr::ToString(setup.prediction), a.vehicle};
  if (a.json) {
    json scenarios = json::array();
    for (const FileReport& f : results) scenarios.push_back(FileJson(f));
    const json out = {{"scenarios", scenarios}, {"summary", SummaryJson(summary, settings)}};
    std::printf("%s\n", JsonText(out).c_str());
  } else {
    for (const FileReport& f : results) std::printf("%s", FileText(f).c_str());
    std::printf("%s", SummaryText(summary, settings).c_str());
  }
  for (const std::string& note : references.notes) {
    std::fprintf(stderr, "frenetic commonroad: %s\n", note.c_str());
  }
  if (!summary.comparison.unpaired.empty()) {
    std::string list;
    for (const std::string& u : summary.comparison.unpaired) list += (list.empty() ? "" : ", ") + u;
    std::fprintf(stderr,
                 "frenetic commonroad: %zu solution file(s) without their scenario among the "
                 "paths: %s\n",
                 summary.comparison.unpaired.size(), list.c_str());
  }
  // Records do not change the results above: a failure to write one is told on stderr.
  int record_errors = 0;
  for (const FileReport& f : results) {
    if (f.record_error.empty()) continue;
    ++record_errors;
    std::fprintf(stderr, "frenetic commonroad: --record: %s\n", f.record_error.c_str());
  }
  return summary.unreadable_files > 0 || record_errors > 0 ? 1 : 0;
}

int Run(const Args& a) {
  // MPI starts only under mpirun; a plain run is one process.
  tune::Cluster cluster;
  const bool root = cluster.rank() == 0;
  auto fail = [&](const std::string& message) {
    std::fprintf(stderr, "frenetic commonroad%s: %s\n",
                 root ? "" : (" (rank " + std::to_string(cluster.rank()) + ")").c_str(),
                 message.c_str());
    return 1;
  };
  const StatusOr<Setup> setup = Prepare(a);
  // Every rank must agree that set-up worked before any waits for another. Rank 0 tells its
  // error; another rank tells its own only when rank 0 had none (the same arguments fail alike).
  std::vector<double> failed = {root && !setup.ok() ? 1.0 : 0.0, setup.ok() ? 0.0 : 1.0};
  cluster.SumToRoot(&failed);
  cluster.Broadcast(&failed);
  if (!setup.ok()) return root || failed[0] == 0 ? fail(setup.message()) : 1;
  if (failed[1] > 0) return 1;

  std::vector<FileReport> results = RunShare(a, *setup, cluster);
  if (Status st = commonroad_cli::GatherReports(cluster, &results); !st.ok()) {
    return fail(st.message());
  }
  return root ? Print(a, *setup, results) : 0;
}

}  // namespace

void RegisterCommonRoad(CLI::App& app) {
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand(
      "commonroad",
      "Plan closed-loop through CommonRoad scenarios (format 2020a): every planning problem of "
      "every file, the other traffic following its recording, each step replanned; each "
      "problem's KS trajectory is judged like CommonRoad's solution checker (goal, collision, "
      "road, kinematic limits, KS dynamics). The summary counts problems infeasible at start "
      "(the initial state collides or is off the road) apart from the solved and the unsolved, "
      "and gives per family of scenarios (country and map, the map's trailing site number "
      "dropped: DEU_LocationALower26 -> DEU_LocationALower; a road's number kept: USA_US101) the "
      "problems, solved, unsolved by their first failure (the earliest by step, a missed goal "
      "only when nothing else failed; of the collisions, those with a car that came into the "
      "scene, as into a recording's view, at most 1 s before it hit: collisions_entering) and "
      "planning time per cycle (ms; with --json also the rescue's part of it, rescue_ms, per "
      "problem and family). Under `mpirun -n N` the files are split across the ranks (file i on "
      "rank i mod N, each with --jobs threads) and rank 0 prints what a single process prints. "
      "Unsolved problems are results: the exit status is 0 unless a file could not be read (1).");
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
  sub->add_option("--compare", args->compare,
                  "CommonRoad solution files, or directories of them, to compare with (each "
                  "paired with its scenario by the scenario id in its benchmark id, e.g. "
                  "KS1:TR2:<scenario id>:2020a; other files there are skipped). Solution files "
                  "among the paths are used too. Per problem with one: its WX1 and JB1 costs "
                  "(with its own vehicle), its time to the goal (steps and s from its first "
                  "state) beside ours, and its verdict in one field; the summary counts the "
                  "problems both reach the goal (ours: solved; its: a state meets a goal) and "
                  "among them those where ours is cheaper (WX1 strictly lower), and those only "
                  "one reaches. Problems infeasible at start are not compared. Repeatable or a "
                  "comma-separated list. Default: none")
      ->allow_extra_args(false)
      ->delimiter(',');
  sub->add_flag("--json", args->json, "Print the results as one JSON object on stdout");
  sub->add_option("--jobs", args->jobs,
                  "Scenario files planned in parallel per process (under mpirun, per rank; 0 = "
                  "every core this process may use, its CPU affinity: taskset). Results do not "
                  "depend on it. Default: 0")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--progress", args->progress,
                "Show the progress line on stderr even when it is not a terminal");
  sub->add_flag("--no-timing", args->no_timing,
                "Report planning times as 0 (byte-stable output for the same files)");
  sub->add_flag("--no-rescue", args->no_rescue,
                "Drive the planner's path even when it would hit a predicted car, leave the road "
                "or miss the goal. By default the path is checked against the predictions (the "
                "cars' boxes every step, 4 s ahead) and the road's edges (up to where it meets a "
                "goal region) and, when it hits one, a search of the vehicle's own KS inputs "
                "(five accelerations and five steering rates a step, within 97% of its limits and "
                "the friction circle, the ego's box 0.05 m wider, on the road between its edges, "
                "at most 150 states a step; a file's step shorter than 0.1 s holds each input for "
                "about 0.1 s, checked at every step) looks for a way that meets a goal region or "
                "lasts the 4 s; when the path meets no goal region while every one closes within "
                "it or lies behind its end, or the planner's whole plan misses every one while "
                "each closes within 6 s and the path ends outside it, the search looks for a way "
                "that meets one (in the last case up to 6 s ahead, to the windows' close, and "
                "after such a search found none the next waits a cycle or two). The ego drives "
                "its first step, and the rest of it while it stays clear (and still meets the "
                "goal). Its time counts as planning time. Default: off (the rescue runs)");
  sub->add_option("--rescue-retry", args->rescue_retry,
                  "States a step (count) of a second rescue search when the first (150 a step) "
                  "finds no way (the ego would otherwise drive into a predicted car, or miss the "
                  "goal); 0 = none. A narrow way through a box-in may need thousands; each "
                  "costs time in the cycle it runs (2000 states a step: up to 0.4 s). Default: "
                  "300 (twice the first)")
      ->check(CLI::Range(0, 100000));
  sub->add_flag("--way-through", args->way_through,
                "For each problem left unsolved (not infeasible at start), search whether any way "
                "through its traffic exists, to tell a planner's miss from a problem with no "
                "solution: the states the vehicle reaches step by step with the KS model's limits "
                "(five forward accelerations up to the limit at its speed, five changes of its "
                "path's curvature up to what the steering rate allows, within the friction "
                "circle), kept while the verdict's collision and road checks pass, on a grid "
                "(0.25 m, 0.25 m/s, 0.01 rad, 0.002 1/m), at most 10000 per step, to the "
                "traffic's last step, then on (static obstacles and the road still checked) "
                "until a kept state meets a goal state or every goal's window has closed (at "
                "most 20 s in all: 200 steps at 0.1 s). Evidence, "
                "not proof: per problem 'found', or the last step any state reached (and whether "
                "a step was capped), and the step a state met the goal (a way to the goal: the "
                "problem has a solution); the summary counts them. Takes seconds per problem. "
                "Default: off");
  sub->callback([args] { ExitWith(Run(*args)); });
}

}  // namespace frenetic::apps

// The full planning cycle, Plan(), on recorded scenes (bench/scenes/*.jsonl): per scene, over
// the whole scene set (p50/p99), swept over the candidate grid size and the number of vehicles,
// and under a tiny per-cycle deadline. Also main() of frenetic_bench and the malloc counter.
//
// What one iteration measures: ONE warm Plan() call. Before it, untimed, the Replay
// (bench_util.h) rebuilds the message's previous_path from the planner's own last output, so the
// cycle is in sync (points kept, history for the jerk windows, decision memory), like cycle N of
// a drive; at the start of each pass over a scene the planner is Reset() and plans the first
// message cold, also untimed.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench_util.h"
#include "frenetic/commonroad/rescue.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::bench {
namespace {

using Clock = std::chrono::steady_clock;

// Sums over the measured cycles of one benchmark run, turned into counters at the end.
struct CycleStats {
  std::vector<double> us;      // wall time of each measured Plan(), microseconds
  std::vector<double> cpu_us;  // the thread's CPU time in it (not inflated by other processes)
  double generated = 0, scored = 0, checked = 0, feasible = 0, seconds = 0;
  double score_ms = 0, generate_ms = 0, check_ms = 0, refine_ms = 0, output_ms = 0;
  double best_cost = 0;
  int found = 0, over_budget = 0, fallback = 0, invalid = 0, synced = 0, reused = 0, cycles = 0;
  double rejections[static_cast<int>(plan::Reject::kCount)] = {};
  std::int64_t allocations = 0;

  void Add(const plan::PlanResult& r, double seconds_wall, double seconds_cpu,
           std::int64_t allocs) {
    const plan::PlanSummary& s = r.summary;
    us.push_back(seconds_wall * 1e6);
    cpu_us.push_back(seconds_cpu * 1e6);
    seconds += seconds_wall;
    generated += s.candidates_generated;
    scored += s.candidates_scored;
    checked += s.candidates_checked;
    feasible += s.candidates_feasible;
    generate_ms += s.ms_generate;
    score_ms += s.ms_score;
    check_ms += s.ms_check;
    refine_ms += s.ms_refine;
    output_ms += s.ms_output;
    if (s.candidates_feasible > 0) {
      ++found;
      best_cost += s.winner_total_cost;
    }
    over_budget += r.status == plan::PlanStatus::kOverBudget;
    fallback += r.status == plan::PlanStatus::kFallbackUsed;
    invalid += r.status == plan::PlanStatus::kInvalidInput;
    synced += s.points_kept > 0;
    // A cycle that re-sent the previous plan without searching (continuity.replan_min_ticks).
    reused += s.candidates_generated == 0 && r.status == plan::PlanStatus::kOk;
    for (int k = 0; k < static_cast<int>(plan::Reject::kCount); ++k) rejections[k] += s.rejections[k];
    allocations += allocs;
    ++cycles;
  }

  void Report(benchmark::State& state) {
    if (cycles == 0) return;
    const double n = cycles;
    auto& c = state.counters;
    c["cands"] = generated / n;
    c["cands_per_s"] = seconds > 0 ? scored / seconds : 0;
    c["score_ns_per_cand"] = scored > 0 ? score_ms * 1e6 / scored : 0;
    c["checked"] = checked / n;
    c["feasible_ratio"] = checked > 0 ? feasible / checked : 0;
    c["best_cost"] = found > 0 ? best_cost / found : 0;
    c["gen_us"] = generate_ms * 1e3 / n;
    c["score_us"] = score_ms * 1e3 / n;
    c["check_us"] = check_ms * 1e3 / n;
    c["refine_us"] = refine_ms * 1e3 / n;
    c["output_us"] = output_ms * 1e3 / n;
    c["allocs"] = static_cast<double>(allocations) / n;
    c["over_budget"] = over_budget / n;
    c["fallback"] = fallback / n;
    c["synced"] = synced / n;
    if (invalid > 0) c["invalid"] = invalid / n;
    if (reused > 0) c["reused"] = reused / n;
    for (int k = 0; k < static_cast<int>(plan::Reject::kCount); ++k) {
      if (rejections[k] > 0) {
        c[std::string("rej_") + plan::ToString(static_cast<plan::Reject>(k))] = rejections[k] / n;
      }
    }
    c["p50_us"] = SortAndPercentile(&us, 0.50);
    c["p99_us"] = SortAndPercentile(&us, 0.99);
    c["max_us"] = us.back();  // sorted by SortAndPercentile
    c["p50_cpu_us"] = SortAndPercentile(&cpu_us, 0.50);
    c["p99_cpu_us"] = SortAndPercentile(&cpu_us, 0.99);
  }
};

// One scene's planner and replay.
struct Rig {
  std::unique_ptr<plan::Planner> planner;
  std::unique_ptr<Replay> replay;
  const plan::PlanResult* last = nullptr;
};

StatusOr<Rig> MakeRig(const Scene& scene, const plan::PlannerConfig& config) {
  StatusOr<std::unique_ptr<plan::Planner>> planner = Status::Error("no planner");
  if (scene.road != nullptr) {
    planner = plan::MakePlanner("search", config, scene.road);
  } else {
    auto line = LineFor(scene.map_path);
    if (!line.ok()) return line.status();
    planner = plan::MakePlanner("search", config, *line);
  }
  if (!planner.ok()) return planner.status();
  Rig rig;
  rig.planner = std::move(planner).value();
  rig.replay = std::make_unique<Replay>(rig.planner.get(), &scene);
  return rig;
}

// The measured loop over one or more rigs, round robin (one cycle per iteration).
void RunCycles(benchmark::State& state, std::vector<Rig>& rigs, CycleStats* stats) {
  stats->us.reserve(1 << 16);
  stats->cpu_us.reserve(1 << 16);
  // FRENETIC_BENCH_TRACE=1 prints every measured cycle's summary and stage times to stderr
  // (diagnosis only).
  static const bool trace = std::getenv("FRENETIC_BENCH_TRACE") != nullptr;
  std::size_t k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Rig& rig = rigs[k];
    k = (k + 1) % rigs.size();
    rig.replay->Prepare();
    g_allocations.store(0, std::memory_order_relaxed);
    state.ResumeTiming();
    const double cpu0 = ThreadCpuSeconds();
    const auto t0 = Clock::now();
    g_count_allocations.store(true, std::memory_order_relaxed);
    const plan::PlanResult& r = rig.replay->Run();
    g_count_allocations.store(false, std::memory_order_relaxed);
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    const double cpu = ThreadCpuSeconds() - cpu0;
    state.PauseTiming();
    stats->Add(r, dt, cpu, g_allocations.load(std::memory_order_relaxed));
    if (trace) {
      const auto& rej = r.summary.rejections;
      std::fprintf(stderr,
                   "cycle: %s %.1f us, %d candidates, %d checked (rejected: speed %d accel %d "
                   "jerk %d off_road %d collision %d), %d kept; us: prepare %.0f generate %.0f "
                   "score %.0f check %.0f refine %.0f output %.0f\n",
                   plan::ToString(r.status), dt * 1e6, r.summary.candidates_generated,
                   r.summary.candidates_checked, rej[0], rej[1], rej[2], rej[3], rej[4],
                   r.summary.points_kept, 1e3 * r.summary.ms_prepare, 1e3 * r.summary.ms_generate,
                   1e3 * r.summary.ms_score, 1e3 * r.summary.ms_check, 1e3 * r.summary.ms_refine,
                   1e3 * r.summary.ms_output);
    }
    rig.replay->Finish(r);
    state.ResumeTiming();
  }
}

// config/planner.yaml with a full search in every cycle: continuity.replan_min_ticks = 1 turns
// off the re-sending of the previous plan (a cycle that reuses it costs a few microseconds and
// does not search), so every measured cycle is a search cycle, the case the budget is about.
// BM_PlanSceneSet/as_configured measures the configuration as it is, reuse included.
StatusOr<plan::PlannerConfig> DefaultConfig(bool search_every_cycle = true) {
  auto config = plan::PlannerConfig::LoadDefault();
  if (config.ok() && search_every_cycle && config->Get("continuity.replan_min_ticks").ok()) {
    if (Status s = config->Set("continuity.replan_min_ticks", 1); !s.ok()) return s;
  }
  return config;
}

// Plan() on one scene with an optional grid size (state.range(0) nominal candidates, 0 = the
// default grid), number of vehicles (0 = as recorded) and budget (0 = as configured).
void PlanScene(benchmark::State& state, const Scene* recorded, int nominal, int vehicles,
               double budget_ms) {
  auto config = DefaultConfig();
  if (!config.ok()) return state.SkipWithError(config.message().c_str());
  if (nominal > 0) {
    if (Status s = ApplyShape(ShapeFor(nominal), &*config); !s.ok()) {
      return state.SkipWithError(s.message().c_str());
    }
  }
  if (budget_ms > 0) {
    if (Status s = config->Set("budget_ms", budget_ms); !s.ok()) {
      return state.SkipWithError(s.message().c_str());
    }
  }
  Scene scene = *recorded;
  if (vehicles > 0) {
    auto line = LineFor(recorded->map_path);
    if (!line.ok()) return state.SkipWithError(line.message().c_str());
    scene = WithVehicles(*recorded, vehicles, **line);
  }
  auto rig = MakeRig(scene, *config);
  if (!rig.ok()) return state.SkipWithError(rig.message().c_str());
  std::vector<Rig> rigs;
  rigs.push_back(std::move(rig).value());
  CycleStats stats;
  RunCycles(state, rigs, &stats);
  stats.Report(state);
  state.counters["vehicles"] = static_cast<double>(scene.messages[0].sensor_fusion.size());
  if (nominal > 0) state.SetComplexityN(static_cast<std::int64_t>(stats.generated /
                                                                  std::max(1, stats.cycles)));
  if (budget_ms > 0) {
    state.counters["budget_ms"] = budget_ms;
    // How far past the deadline the cycle ran: mean and worst cycle over the budget.
    state.counters["mean_over_budget_x"] =
        stats.cycles > 0 ? stats.seconds * 1e3 / stats.cycles / budget_ms : 0;
    state.counters["max_over_budget_x"] = stats.us.empty() ? 0 : stats.us.back() / 1e3 / budget_ms;
  }
}

const Scene* Find(const std::vector<Scene>& scenes, const std::string& name) {
  for (const Scene& s : scenes) {
    if (s.name == name) return &s;
  }
  return scenes.empty() ? nullptr : &scenes.front();
}

// Plan() on CommonRoad scenes (captured on first use), round robin over several: every cycle
// of each closed-loop run, with the configuration the runner planned with (its deadlines
// pinned, so no cycle is cut short; every cycle searches: a step drives 5 ticks, more than
// continuity.replan_min_ticks).
void PlanCommonRoad(benchmark::State& state, const std::vector<std::string>& paths) {
  std::vector<Rig> rigs;
  double vehicles = 0, cycles = 0, lanes = 0;
  for (const std::string& path : paths) {
    auto scene = CommonRoadScene(path);
    if (!scene.ok()) return state.SkipWithError(scene.message().c_str());
    if ((*scene)->messages.size() < 2) continue;  // infeasible at start, or over at once
    auto rig = MakeRig(**scene, *(*scene)->config);
    if (!rig.ok()) return state.SkipWithError(rig.message().c_str());
    rigs.push_back(std::move(rig).value());
    for (const plan::Telemetry& m : (*scene)->messages) vehicles += m.sensor_fusion.size();
    cycles += (*scene)->messages.size();
    lanes = std::max(lanes, static_cast<double>((*scene)->road->num_lanes()));
  }
  if (rigs.empty()) return state.SkipWithError("no scene with 2 cycles or more");
  CycleStats stats;
  RunCycles(state, rigs, &stats);
  stats.Report(state);
  state.counters["vehicles"] = cycles > 0 ? vehicles / cycles : 0;  // mean sensor rows
  state.counters["scene_cycles"] = cycles;
  state.counters["lanes"] = lanes;
}

// The closed loop's rescue (commonroad::Rescue::Answer) on every cycle of CommonRoad scenes
// (captured on first use), scene after scene, each cycle in order with one rescue per problem as
// the runner keeps it: the time it adds to a cycle's Plan(). The same decisions as the run's (the
// vehicle's states are the run's, which drove them).
void RescueCommonRoad(benchmark::State& state, const std::vector<std::string>& paths) {
  std::vector<const Scene*> scenes;
  for (const std::string& path : paths) {
    auto scene = CommonRoadScene(path);
    if (!scene.ok()) return state.SkipWithError(scene.message().c_str());
    const Scene& sc = **scene;
    if (sc.ego.empty() || sc.ego.size() != sc.path_x.size()) continue;  // infeasible at start
    scenes.push_back(&sc);
  }
  if (scenes.empty()) return state.SkipWithError("no scene with a cycle");
  std::vector<double> us, cpu_us;
  us.reserve(1 << 16);
  cpu_us.reserve(1 << 16);
  double hits = 0, goals = 0, held = 0, driven = 0;
  int searches = 0;
  std::optional<commonroad::Rescue> rescue;
  std::size_t s = 0, i = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const Scene& scene = *scenes[s];
    if (i == 0) {
      if (rescue) searches += rescue->searches();
      rescue.emplace(*scene.road, scene.vehicle, scene.dt);
    }
    state.ResumeTiming();
    const double cpu0 = ThreadCpuSeconds();
    const auto t0 = Clock::now();
    // As the runner: a way to a goal that holds stands in for the planner's least harm.
    const plan::Telemetry& m = scene.messages[i];
    rescue->Predict(m);
    rescue->Holds(scene.ego[i], m.goals);
    const commonroad::RescueStep r =
        rescue->Answer(m, scene.path_x[i], scene.path_y[i], scene.ego[i], scene.fallback[i] != 0,
                       scene.plan_misses[i] != 0);
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    const double cpu = ThreadCpuSeconds() - cpu0;
    state.PauseTiming();
    us.push_back(dt * 1e6);
    cpu_us.push_back(cpu * 1e6);
    hits += r.why == commonroad::RescueStep::Why::kHit;
    goals += r.why == commonroad::RescueStep::Why::kGoal;
    held += r.why == commonroad::RescueStep::Why::kNoPath;
    driven += r.input.has_value();
    if (++i == scene.ego.size()) {
      i = 0;
      s = (s + 1) % scenes.size();
    }
    state.ResumeTiming();
  }
  if (rescue) searches += rescue->searches();
  const double n = static_cast<double>(us.size());
  if (n == 0) return;
  auto& c = state.counters;
  c["hit"] = hits / n;          // share of cycles whose path hits a predicted car
  c["goal"] = goals / n;        // ... that miss a closing goal
  c["held"] = held / n;         // ... where no candidate passed and a way to a goal held
  c["driven"] = driven / n;     // ... where the rescue's way is driven
  c["searches"] = searches / n; // new searches per cycle
  c["scenes"] = static_cast<double>(scenes.size());
  c["p50_us"] = SortAndPercentile(&us, 0.50);
  c["p99_us"] = SortAndPercentile(&us, 0.99);
  c["max_us"] = us.back();
  c["p50_cpu_us"] = SortAndPercentile(&cpu_us, 0.50);
  c["p99_cpu_us"] = SortAndPercentile(&cpu_us, 0.99);
}

}  // namespace

void RegisterCommonRoadBenchmarks() {
  const std::vector<std::string> files = CommonRoadSceneFiles();
  if (files.empty()) {
    std::fprintf(stderr,
                 "frenetic_bench: no US-101 scenario files under $FRENETIC_SHARED_DIR/commonroad: "
                 "BM_PlanCommonRoad is not registered\n");
    return;
  }
  for (const std::string& path : files) {
    const std::string id = std::filesystem::path(path).stem().string();
    benchmark::RegisterBenchmark(("BM_PlanCommonRoad/" + id).c_str(), [path](benchmark::State& st) {
      PlanCommonRoad(st, {path});
    })->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark("BM_PlanCommonRoadSet/US101", [files](benchmark::State& st) {
    PlanCommonRoad(st, files);
  })->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("BM_RescueCommonRoadSet/US101", [files](benchmark::State& st) {
    RescueCommonRoad(st, files);
  })->Unit(benchmark::kMicrosecond);
  // highD: recorded German motorway traffic (3 lanes, traffic at up to twice the ego's pace:
  // box-ins where every candidate collides), every problem feasible at start.
  const std::vector<std::string> highd = CommonRoadSceneFiles("highD");
  if (highd.empty()) return;
  benchmark::RegisterBenchmark("BM_PlanCommonRoadSet/highD", [highd](benchmark::State& st) {
    PlanCommonRoad(st, highd);
  })->Unit(benchmark::kMicrosecond);
  // The rescue's time on the same cycles: the closed loop's cycle is the two together.
  benchmark::RegisterBenchmark("BM_RescueCommonRoadSet/highD", [highd](benchmark::State& st) {
    RescueCommonRoad(st, highd);
  })->Unit(benchmark::kMicrosecond);
}

void RegisterPlanBenchmarks(const std::vector<Scene>& scenes) {
  if (scenes.empty()) return;
  // 1. Each recorded scene as recorded, default configuration.
  for (const Scene& scene : scenes) {
    benchmark::RegisterBenchmark(("BM_Plan/" + scene.name).c_str(),
                                 [&scene](benchmark::State& st) { PlanScene(st, &scene, 0, 0, 0); })
        ->Unit(benchmark::kMicrosecond);
  }
  // 2. The scene set round robin: p50 / p99 / max over every scene's warm cycles; searching
  // every cycle, and as configured (plan reuse on: most lockstep cycles then do not search).
  for (const bool as_configured : {false, true}) {
  benchmark::RegisterBenchmark(
      as_configured ? "BM_PlanSceneSet/as_configured" : "BM_PlanSceneSet/search_every_cycle",
      [&scenes, as_configured](benchmark::State& st) {
    auto config = DefaultConfig(!as_configured);
    if (!config.ok()) return st.SkipWithError(config.message().c_str());
    std::vector<Rig> rigs;
    for (const Scene& scene : scenes) {
      auto rig = MakeRig(scene, *config);
      if (!rig.ok()) return st.SkipWithError(rig.message().c_str());
      rigs.push_back(std::move(rig).value());
    }
    CycleStats stats;
    RunCycles(st, rigs, &stats);
    stats.Report(st);
    st.counters["scenes"] = static_cast<double>(rigs.size());
  })->Unit(benchmark::kMicrosecond);
  }
  // 3. Candidate grid x vehicles on the free-road scene (12 cars recorded, more added).
  const Scene* free_road = Find(scenes, "free_road");
  for (int vehicles : {12, 24, 48}) {
    auto* b = benchmark::RegisterBenchmark(
        ("BM_PlanGrid/" + free_road->name + "/vehicles:" + std::to_string(vehicles)).c_str(),
        [free_road, vehicles](benchmark::State& st) {
          PlanScene(st, free_road, static_cast<int>(st.range(0)), vehicles, 0);
        });
    b->ArgName("cands")->Unit(benchmark::kMicrosecond)->Complexity(benchmark::oN);
    for (int n = 64; n <= 4096; n *= 2) b->Arg(n);
  }
  // 4. Default grid, vehicles swept, on the dense scene.
  const Scene* dense = Find(scenes, "dense_traffic");
  auto* v = benchmark::RegisterBenchmark(
      ("BM_PlanVehicles/" + dense->name).c_str(),
      [dense](benchmark::State& st) { PlanScene(st, dense, 0, static_cast<int>(st.range(0)), 0); });
  v->ArgName("vehicles")->Unit(benchmark::kMicrosecond)->Arg(12)->Arg(24)->Arg(48);
  // 5. The deadline: a large grid under budgets from 1 ms (the smallest accepted) up.
  auto* bud = benchmark::RegisterBenchmark(
      ("BM_PlanBudget/" + dense->name + "/cands:4096").c_str(),
      [dense](benchmark::State& st) {
        PlanScene(st, dense, 4096, 0, static_cast<double>(st.range(0)));
      });
  bud->ArgName("budget_ms")->Unit(benchmark::kMicrosecond)->Arg(1)->Arg(2)->Arg(5)->Arg(15);
}

}  // namespace frenetic::bench

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  std::vector<frenetic::bench::Scene> scenes;
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(frenetic::bench::SceneDir(), ec)) {
    if (e.path().extension() == ".jsonl") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "frenetic_bench: no scenes in %s: only the stage benchmarks run\n",
                 frenetic::bench::SceneDir().c_str());
  }
  for (const std::string& f : files) {
    auto scene = frenetic::bench::LoadScene(f);
    if (!scene.ok()) {
      std::fprintf(stderr, "frenetic_bench: %s\n", scene.message().c_str());
      return 1;
    }
    scenes.push_back(std::move(scene).value());
  }
  frenetic::bench::RegisterPlanBenchmarks(scenes);
  frenetic::bench::RegisterCommonRoadBenchmarks();
  frenetic::bench::RegisterStageBenchmarks(scenes);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

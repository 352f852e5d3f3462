// CommonRoad scenes for frenetic_bench: the US-101 examples (NGSIM recorded traffic, 43-44 cars,
// 6 lanes), captured at run time from the shared files, which are not part of the tree. The
// runner (commonroad::RunScenario) drives each file's problem closed-loop as `frenetic commonroad`
// does, and hands out every cycle's planner input (RunOptions::on_cycle): the telemetry (ego,
// previous path, sensor rows, recorded futures, goals), the road built from the lanelets, and
// the problem's configuration; and after it (on_plan) the path the planner sent, which with the
// vehicle's state is what the loop's rescue checks. BM_PlanCommonRoad replays them like the
// Udacity scenes, BM_RescueCommonRoadSet replays the rescue.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/commonroad/setup.h"

namespace frenetic::bench {
namespace {

std::string SharedDir() {
  const char* env = std::getenv("FRENETIC_SHARED_DIR");
  return env != nullptr && *env != '\0' ? env : FRENETIC_SHARED_DIR;
}

StatusOr<Scene> Capture(const std::string& path) {
  auto scenario = commonroad::LoadScenario(path);
  if (!scenario.ok()) return scenario.status();
  if (scenario->problems.empty()) return Status::Error(path + ": no planning problem");
  auto base = commonroad::LoadBaseConfig();
  if (!base.ok()) return base.status();
  auto vehicle = commonroad::VehicleParamsForType(2);
  if (!vehicle.ok()) return vehicle.status();
  auto config =
      commonroad::CommonRoadConfig(*base, *vehicle, commonroad::PredictionMode::kRecorded);
  if (!config.ok()) return config.status();
  Scene scene;
  scene.name = scenario->benchmark_id;
  scene.map_path = path;
  const int problem = scenario->problems.front().id;
  commonroad::RunOptions options;
  options.timing = false;
  options.on_cycle = [&](const commonroad::CycleInput& in) {
    if (in.problem.id != problem) return;
    if (scene.road == nullptr) {
      scene.road = in.road;
      scene.config = std::make_shared<const plan::PlannerConfig>(in.config);
    }
    scene.t.push_back(in.step * scenario->dt);
    scene.messages.push_back(in.telemetry);
    scene.ego.push_back(in.ego);
    scene.least_harm.push_back(in.least_harm ? 1 : 0);
  };
  options.on_plan = [&](const commonroad::CycleInput& in, const plan::PlanResult& result) {
    if (in.problem.id != problem) return;
    scene.path_x.push_back(result.x);
    scene.path_y.push_back(result.y);
    scene.fallback.push_back(result.status == plan::PlanStatus::kFallbackUsed ? 1 : 0);
    scene.plan_misses.push_back(commonroad::PlanMissesGoal(result) ? 1 : 0);
  };
  scene.dt = scenario->dt;
  scene.vehicle = *vehicle;
  const commonroad::ScenarioRun run = commonroad::RunScenario(*scenario, *config, options);
  if (!run.problems.empty() && !run.problems[0].road.ok()) return run.problems[0].road;
  return scene;
}

}  // namespace

std::vector<std::string> CommonRoadSceneFiles(const std::string& family) {
  std::vector<std::string> out;
  std::error_code ec;
  if (family == "highD") {
    const std::filesystem::path dir = SharedDir() + "/commonroad/highD";
    if (!std::filesystem::is_directory(dir, ec)) return out;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      if (name.size() > 7 && name.ends_with(".cr.xml")) out.push_back(e.path().string());
    }
    std::sort(out.begin(), out.end());
    return out;
  }
  for (const char* id : {"USA_US101-10_1_T-1", "USA_US101-10_3_T-1", "USA_US101-10_4_T-1"}) {
    const std::string path = SharedDir() + "/commonroad/" + id + ".xml";
    if (std::filesystem::exists(path, ec)) out.push_back(path);
  }
  return out;
}

StatusOr<const Scene*> CommonRoadScene(const std::string& path) {
  // Benchmarks run one at a time on the main thread: no lock.
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  if (auto it = cache.find(path); it != cache.end()) return it->second.get();
  auto scene = Capture(path);
  if (!scene.ok()) return scene.status();
  auto& slot = cache[path];
  slot = std::make_unique<Scene>(std::move(*scene));
  return slot.get();
}

}  // namespace frenetic::bench

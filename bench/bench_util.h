// Shared helpers of the frenetic_bench executable: recorded scenes (bench/scenes/*.jsonl), the
// reference line they were recorded on, grid sizing for the candidate sweeps, synthetic traffic,
// a replay that keeps Plan()'s continuity state realistic, and an allocation counter.
//
// A scene file is JSON lines: a header {"type":"header","scene":NAME,"map":PATH,...} (PATH
// relative to the source tree) and then consecutive {"type":"exchange","t":SECONDS,
// "telemetry":{wire object}} lines cut from a `frenetic drive --record` file by
// bench/capture_scenes.py.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/commonroad/ks_model.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/road.h"
#include "frenetic/map/track.h"
#include "frenetic/percentile.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/status.h"
#include "frenetic/wire/protocol.h"
#include "../tests/common/malloc_counter.h"

namespace frenetic::bench {

// Process-wide count of the allocations passed to glibc while g_count_allocations is set (the
// planner library's interposed C heap counts them, C libraries' such as NLopt's included:
// frenetic/plan/scratch_heap.h). Stays 0 in sanitizer builds.
using testing_util::g_allocations;
using testing_util::g_count_allocations;

// One recorded scene: consecutive telemetry messages of one drive.
struct Scene {
  std::string name;
  std::string map_path;                // absolute
  std::vector<double> t;               // simulated time of each message, s
  std::vector<std::string> wire;       // each message's telemetry frame as the simulator sent it
  std::vector<plan::Telemetry> messages;
  // CommonRoad scenes (commonroad_scenes.cc): the road and the configuration the runner planned
  // with; the messages carry recorded futures and goals, and no wire frames. Null for Udacity
  // scenes, which are planned on map_path's line with the benchmark's configuration.
  std::shared_ptr<const map::Road> road;
  std::shared_ptr<const plan::PlannerConfig> config;
  // CommonRoad scenes, per message: the vehicle's state and the path the planner sent (what the
  // closed loop's rescue is given, commonroad::Rescue::Answer); the scenario's step (s) and the
  // vehicle.
  std::vector<commonroad::KsState> ego;
  std::vector<std::vector<double>> path_x, path_y;
  // CommonRoad scenes, per message: whether the planner's least-harm choice was on
  // (commonroad::CycleInput::least_harm; the replay sets it), and whether no candidate passed
  // (status fallback_used: with a way held, the rescue drove it, Rescue::Continue), and whether
  // the planner's plan missed every goal region (commonroad::PlanMissesGoal).
  std::vector<char> least_harm, fallback, plan_misses;
  double dt = 0;
  commonroad::VehicleParams vehicle;
};

inline std::string SceneDir() { return FRENETIC_SOURCE_DIR "/bench/scenes"; }

// Reads a scene file. Errors name the file and the line.
inline StatusOr<Scene> LoadScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  Scene scene;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    nlohmann::json j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object() || !j.contains("type") || !j["type"].is_string()) {
      return Status::Error(where + "not a JSON object with a \"type\"");
    }
    const std::string type = j["type"].get<std::string>();
    if (type == "header") {
      if (!j.contains("scene") || !j["scene"].is_string() || !j.contains("map") ||
          !j["map"].is_string()) {
        return Status::Error(where + "header needs string fields \"scene\" and \"map\"");
      }
      scene.name = j["scene"].get<std::string>();
      const std::string map = j["map"].get<std::string>();
      scene.map_path = map.starts_with("/") ? map : std::string(FRENETIC_SOURCE_DIR "/") + map;
    } else if (type == "exchange") {
      if (!j.contains("telemetry") || !j["telemetry"].is_object() || !j.contains("t") ||
          !j["t"].is_number()) {
        return Status::Error(where + "exchange needs \"t\" and a \"telemetry\" object");
      }
      std::string frame = "42[\"telemetry\"," + j["telemetry"].dump() + "]";
      wire::ParsedFrame parsed = wire::ParseFrame(frame);
      if (parsed.kind != wire::FrameKind::kTelemetry) {
        return Status::Error(where + "telemetry: " + parsed.error);
      }
      scene.t.push_back(j["t"].get<double>());
      scene.wire.push_back(std::move(frame));
      scene.messages.push_back(std::move(parsed.telemetry));
    } else {
      return Status::Error(where + "unknown type \"" + type + "\"");
    }
  }
  if (scene.name.empty()) return Status::Error(path + ": no header line");
  if (scene.messages.size() < 2) return Status::Error(path + ": needs at least 2 exchanges");
  return scene;
}

// The reference line of a map file, fitted once per path (the fit takes ~1 s).
inline StatusOr<std::shared_ptr<const map::ReferenceLine>> LineFor(const std::string& map_path) {
  static std::map<std::string, std::shared_ptr<const map::ReferenceLine>> cache;
  if (auto it = cache.find(map_path); it != cache.end()) return it->second;
  auto track = map::LoadTrack(map_path);
  if (!track.ok()) return track.status();
  auto line = map::ReferenceLine::Fit(*track);
  if (!line.ok()) return Status::Error(map_path + ": " + line.message());
  cache[map_path] = *line;
  return *line;
}

// Grid keys giving about `nominal` candidates when three lanes are reachable (the ego in the
// middle lane): (durations x (speeds + stop)) longitudinal x (3 lanes x lat_durations x
// lat_offsets) lateral, following candidates come on top. The declared ranges bound the smallest
// grid at 96. Picks the closest estimate, preferring shapes near the default (16 speeds, 6
// durations, 3 lateral durations, 1 offset). Returns the estimate.
struct GridShape {
  int speeds = 16, durations = 6, lat_durations = 3, lat_offsets = 1, stop = 1;
  int Estimate() const { return durations * (speeds + stop) * 3 * lat_durations * lat_offsets; }
};
inline GridShape ShapeFor(int nominal) {
  GridShape best;
  double best_score = 1e18;
  for (int stop = 0; stop <= 1; ++stop) {
    for (int lo = 1; lo <= 7; lo += 2) {
      for (int ld = 1; ld <= 8; ++ld) {
        for (int du = 4; du <= 16; ++du) {
          for (int sp = 8; sp <= 64; ++sp) {
            const GridShape g{sp, du, ld, lo, stop};
            const double miss = std::abs(std::log(static_cast<double>(g.Estimate()) / nominal));
            const double shape = 0.01 * (std::abs(sp - 16) / 16.0 + std::abs(du - 6) / 6.0 +
                                         std::abs(ld - 3) / 3.0 + (lo - 1) / 2.0 + (1 - stop));
            if (miss + shape < best_score) {
              best_score = miss + shape;
              best = g;
            }
          }
        }
      }
    }
  }
  return best;
}

inline Status ApplyShape(const GridShape& g, plan::PlannerConfig* config) {
  for (const auto& [key, value] : {std::pair<const char*, int>{"grid.speeds", g.speeds},
                                   {"grid.durations", g.durations},
                                   {"grid.lat_durations", g.lat_durations},
                                   {"grid.lat_offsets", g.lat_offsets},
                                   {"grid.stop", g.stop}}) {
    if (Status s = config->Set(key, value); !s.ok()) return s;
  }
  return Status::Ok();
}

// Returns the scene with its sensor_fusion set to `vehicles` rows in every message: the first
// rows as recorded, then synthetic cars (ids 1000+) at constant speed along lane centres, spread
// deterministically over -80 m ... +180 m around the ego's first position and kept 20 m clear of
// it along s, so that their tracks are consistent from message to message.
inline Scene WithVehicles(const Scene& in, int vehicles, const map::ReferenceLine& line) {
  Scene out = in;
  out.name = in.name + "/vehicles:" + std::to_string(vehicles);
  const plan::Telemetry& first = in.messages.front();
  const double ego_s = line.ToFrenet(first.x, first.y).s;
  const int recorded = static_cast<int>(first.sensor_fusion.size());
  struct Synthetic {
    double s0, d, v;
  };
  std::vector<Synthetic> cars;
  for (int j = 0; recorded + static_cast<int>(cars.size()) < vehicles; ++j) {
    // Golden-ratio sequence: well spread, deterministic, no generator state.
    const double u = std::fmod(0.5 + j * 0.6180339887498949, 1.0);
    const double ds = -80.0 + 260.0 * u;
    if (std::abs(ds) < 20.0) continue;
    const int lane = j % 3;
    cars.push_back({ego_s + ds, 2.0 + 4.0 * lane - (lane == 2 ? 0.2 : 0.0), 15.0 + (j % 7)});
  }
  for (std::size_t m = 0; m < out.messages.size(); ++m) {
    auto& rows = out.messages[m].sensor_fusion;
    if (static_cast<int>(rows.size()) > vehicles) rows.resize(vehicles);
    const double dt = in.t[m] - in.t[0];
    for (std::size_t j = 0; j < cars.size(); ++j) {
      const double s = cars[j].s0 + cars[j].v * dt;
      const map::CartesianPose p = line.ToCartesian(s, cars[j].d);
      rows.push_back({static_cast<int>(1000 + j), p.x, p.y, cars[j].v * std::cos(p.heading),
                      cars[j].v * std::sin(p.heading), line.WrapS(s), cars[j].d});
    }
    out.wire[m] = wire::FormatTelemetryFrame(out.messages[m]);
  }
  return out;
}

// Replays a scene's messages through a planner so that every measured cycle is a warm one with
// continuity: the first message of a pass is planned after Reset() (cold, not measured), and
// every later message gets, as previous_path, the unconsumed rest of the path the planner itself
// sent last (as float32, like the simulator; as double on a CommonRoad scene, like its runner),
// with as many points consumed as in the recording. So the planner stays in sync whatever its
// configuration; ego pose, traffic, futures and goals are as recorded.
class Replay {
 public:
  Replay(plan::Planner* planner, const Scene* scene) : planner_(planner), scene_(scene) {
    work_ = scene->messages.front();
    const std::size_t cap = 512;
    work_.previous_path_x.reserve(cap);
    work_.previous_path_y.reserve(cap);
    work_.sensor_fusion.reserve(128);
    last_x_.reserve(cap);
    last_y_.reserve(cap);
  }

  // Prepares the next measured message (not part of the measurement: may do the cold cycle).
  void Prepare() {
    if (next_ == 0) {
      planner_->Reset();
      LeastHarmAsRecorded(0);
      Remember(planner_->Plan(scene_->messages[0]));
      next_ = 1;
    }
    LeastHarmAsRecorded(next_);
    const plan::Telemetry& rec = scene_->messages[next_];
    const std::size_t n_prev = rec.previous_path_x.size();
    const std::size_t consumed =
        last_x_.size() > n_prev ? last_x_.size() - n_prev : std::size_t{0};
    work_.x = rec.x;
    work_.y = rec.y;
    work_.yaw = rec.yaw;
    work_.speed = rec.speed;
    work_.s = rec.s;
    work_.d = rec.d;
    work_.end_path_s = rec.end_path_s;
    work_.end_path_d = rec.end_path_d;
    work_.previous_path_x.assign(last_x_.begin() + consumed, last_x_.end());
    work_.previous_path_y.assign(last_y_.begin() + consumed, last_y_.end());
    work_.sensor_fusion.assign(rec.sensor_fusion.begin(), rec.sensor_fusion.end());
    work_.futures = rec.futures;
    work_.goals = rec.goals;
  }

  // The measured cycle.
  const plan::PlanResult& Run() { return planner_->Plan(work_); }

  // Book-keeping after the measured cycle (not measured).
  void Finish(const plan::PlanResult& r) {
    Remember(r);
    if (++next_ == static_cast<int>(scene_->messages.size())) next_ = 0;
  }

 private:
  // A CommonRoad scene's message i: the least-harm choice as the run had it.
  void LeastHarmAsRecorded(int i) {
    if (i < static_cast<int>(scene_->least_harm.size())) {
      planner_->set_least_harm(scene_->least_harm[i] != 0);
    }
  }
  void Remember(const plan::PlanResult& r) {
    last_x_.clear();
    last_y_.clear();
    const bool wire = scene_->road == nullptr;
    for (std::size_t i = 0; i < r.x.size(); ++i) {
      last_x_.push_back(wire ? static_cast<float>(r.x[i]) : r.x[i]);
      last_y_.push_back(wire ? static_cast<float>(r.y[i]) : r.y[i]);
    }
  }

  plan::Planner* planner_;
  const Scene* scene_;
  plan::Telemetry work_;
  std::vector<double> last_x_, last_y_;
  int next_ = 0;
};

// Registration of the two benchmark files (called from main() in plan_bench.cc once the scenes
// are loaded; `scenes` outlives the run).
void RegisterPlanBenchmarks(const std::vector<Scene>& scenes);
void RegisterStageBenchmarks(const std::vector<Scene>& scenes);
// BM_PlanCommonRoad/<scenario id> per US-101 file, BM_PlanCommonRoadSet/US101 over all of them
// and BM_PlanCommonRoadSet/highD over the highD problems (plan_bench.cc); nothing, with a note on
// stderr, without the shared files.
void RegisterCommonRoadBenchmarks();

// CommonRoad scenes (commonroad_scenes.cc). The scenario files of a family present in the shared
// directory ($FRENETIC_SHARED_DIR, else the build's FRENETIC_SHARED_DIR) under commonroad/:
// "US101", the three US-101 examples; "highD", every highD/*.cr.xml (sorted). None when absent.
std::vector<std::string> CommonRoadSceneFiles(const std::string& family = "US101");
// The scene of one such file: every cycle of its first planning problem's closed-loop run
// (commonroad::RunScenario as `frenetic commonroad` runs it: config/planner.yaml +
// config/commonroad.yaml, KS2, recorded predictions, the deadlines pinned), as the planner was
// given it. Captured on first use and kept (the run takes a few seconds). A problem infeasible
// at start, or one whose run ends at its first step, gives a scene with fewer than 2 messages.
StatusOr<const Scene*> CommonRoadScene(const std::string& path);

// CPU time of the calling thread, s (what a cycle costs whatever else the machine runs).
inline double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The percentile p in [0, 1] of a sample, frenetic::Percentile's nearest rank; sorts it (the
// callers read its largest last).
inline double SortAndPercentile(std::vector<double>* v, double p) {
  if (v->empty()) return 0;
  std::sort(v->begin(), v->end());
  return (*v)[NearestRankIndex(v->size(), p)];
}

}  // namespace frenetic::bench

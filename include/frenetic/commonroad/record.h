// Records of CommonRoad runs (`frenetic commonroad --record DIR`): one file per planning problem,
// "<scenario id>_<problem id>.jsonl.gz", in the record format of record/schema.h (JSON lines,
// gzip, written by a record::Writer on a thread of its own) so that `frenetic report` replays it.
//
// The header line carries, besides the drive header's fields ("scenario": the benchmark id,
// "map": the scenario file, "planner", "config", "lanes", "lane_width", "max_s", "car_length"
// and "car_width": the ego's footprint), "world": "commonroad", "problem" (its id), "dt" (s per
// time step), "prediction", "vehicle" ("KS2"), "road": {"lanes": [{"left": {"x", "y"},
// "right": {"x", "y"}}]} (each lane's borders of the road the ego plans on, left to right, as
// polylines in the scenario frame, m, a point every ~2 m) and "goals": [{"x", "y", "steps"}]
// (each goal region's outline, closed implicitly, and its time window in steps, or null).
//
// One exchange line per planning cycle, as the drive's: "i" (the cycle), "t" (the step times
// dt, s), "step", "telemetry" (the ego's x, y, yaw in degrees, speed in mph, s and d on the
// road's reference line, and "sensor_fusion": the obstacles present at the step, each
// [id, x, y, vx, vy, s, d, length, width, heading in degrees], the centre of its footprint's
// bounding box), "path" (the plan's 0.02 s points, m), "plan" (record::PlanJson, with up to
// kRecordCandidates traced candidates; times 0 with timing off) and "metrics" (speed_mph, lane).
// The footer's report holds the verdict: "solved", "goal_step", "stop_reason", "failures"
// ([{kind, step, detail, obstacle, obstacle_entered_s}]: see schema.h), and the run's "steps",
// "distance_m", "sim_seconds", "avg_speed_mph", "max_speed_mph", "plan_ms" {p50, p99, max} and
// "plan_fallbacks".
//
// Recording does not change the run, nor its planning times: the candidates are traced by a
// replica of the planner that plans every cycle again on the writer's thread (checked to send
// the same path; should it ever not, a warning is logged and candidates are left out from there
// on), and the lines are formatted there too, while the planning thread waits between cycles
// (every 32 cycles and at the problem's end), not while it plans.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "frenetic/commonroad/runner.h"
#include "frenetic/commonroad/scenario.h"
#include "frenetic/status.h"

namespace frenetic::record {
class Replica;
class Writer;
}  // namespace frenetic::record

namespace frenetic::commonroad {

// Candidates traced and recorded per cycle, best first.
inline constexpr int kRecordCandidates = 40;

// "<benchmark id>_<problem id>.jsonl.gz", characters other than letters, digits, '-', '_', '.'
// and ':' replaced by '_'.
std::string RecordFileName(std::string_view benchmark_id, int problem_id);

class RunRecorder {
 public:
  // Records the runs of `scenario`'s problems into the existing directory `dir`; both must
  // outlive the recorder. `vehicle_type` and `prediction` are the run's (RunOptions).
  RunRecorder(const Scenario& scenario, std::string dir, int vehicle_type,
              PredictionMode prediction, bool timing);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  // Sets options->on_plan and on_problem_end to record through this recorder (which must
  // outlive the run).
  void Attach(RunOptions* options);
  // The first error opening or writing a record (naming its path); Ok when none.
  const Status& status() const { return status_; }
  // The records written, complete, in problem order (paths).
  const std::vector<std::string>& files() const { return files_; }

 private:
  void OnPlan(const CycleInput& in, const plan::PlanResult& result);
  void OnProblemEnd(const PlanningProblem& problem, const ProblemRun& run);

  const Scenario& scenario_;
  std::string dir_;
  int vehicle_type_;
  PredictionMode prediction_;
  bool timing_;
  Status status_;
  std::vector<std::string> files_;
  std::unique_ptr<record::Writer> writer_;     // the current problem's
  std::string path_;                           // its file
  int problem_ = 0;                            // its id
  int index_ = 0;                              // the next exchange's "i"
  bool failed_ = false;                        // the current problem's record could not open
  // The current problem's planner that traces the candidates, handed to its lines.
  std::shared_ptr<record::Replica> replica_;
};

}  // namespace frenetic::commonroad

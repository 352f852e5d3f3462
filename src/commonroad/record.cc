#include "frenetic/commonroad/record.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <utility>

#include "frenetic/commonroad/solution.h"
#include "frenetic/commonroad/vehicle_params.h"
#include "frenetic/json_text.h"
#include "frenetic/percentile.h"
#include "frenetic/record/plan_json.h"
#include "frenetic/record/replica.h"
#include "frenetic/record/schema.h"
#include "frenetic/record/writer.h"
#include "frenetic/units.h"

namespace frenetic::commonroad {
namespace {

using nlohmann::json;
namespace key = record::key;

constexpr double kBorderStep = 2.0;  // m between the points of a lane border
constexpr int kCirclePoints = 24;    // a goal circle's outline
// The planning thread waits for the queued lines to be written every this many cycles (fewer
// than record::Writer's batch, which wakes its thread): the writer's thread, and the replica
// planning on it, then works only while the planner waits between cycles, never beside it, so
// the planning times measured stay those of a run without a record.
constexpr int kDrainLines = 32;

// Rounded to `decimals` digits (finite values; others become 0, as the drive record's path).
double Round(double v, int decimals) {
  if (!std::isfinite(v)) return 0.0;
  const double f = std::pow(10.0, decimals);
  return std::round(v * f) / f;
}

json Polyline(const std::vector<double>& x, const std::vector<double>& y) {
  json xs = json::array(), ys = json::array();
  for (double v : x) xs.push_back(Round(v, 2));
  for (double v : y) ys.push_back(Round(v, 2));
  return {{"x", std::move(xs)}, {"y", std::move(ys)}};
}

json Outline(const std::vector<Vec2>& points) {
  std::vector<double> x, y;
  for (const Vec2& p : points) {
    x.push_back(p.x);
    y.push_back(p.y);
  }
  return Polyline(x, y);
}

// Each lane's left and right borders, sampled along the reference line where the lane exists.
json RoadJson(const map::Road& road) {
  const map::ReferenceLine& line = road.line();
  json lanes = json::array();
  for (int l = 0; l < road.num_lanes(); ++l) {
    const double s0 = std::clamp(road.LaneBegin(l), 0.0, line.length());
    const double s1 = std::clamp(road.LaneEnd(l), 0.0, line.length());
    const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / kBorderStep)));
    std::vector<double> lx, ly, rx, ry;
    for (int i = 0; i <= n; ++i) {
      const double s = s0 + (s1 - s0) * i / n;
      const map::Road::Span span = road.LaneAt(l, s);
      if (!span.exists) continue;
      const map::CartesianPose left = line.ToCartesian(s, span.left);
      const map::CartesianPose right = line.ToCartesian(s, span.right);
      lx.push_back(left.x);
      ly.push_back(left.y);
      rx.push_back(right.x);
      ry.push_back(right.y);
    }
    lanes.push_back({{"left", Polyline(lx, ly)}, {"right", Polyline(rx, ry)}});
  }
  return {{"lanes", std::move(lanes)}};
}

// Every goal region's outline: shapes, and the polygons of goal lanelets.
json GoalsJson(const Scenario& sc, const PlanningProblem& problem) {
  json goals = json::array();
  for (const GoalState& g : problem.goals) {
    const json steps = g.time ? json::array({g.time->start, g.time->end}) : json(nullptr);
    for (const Shape& sh : g.shapes) {
      std::vector<Vec2> pts = sh.Vertices();
      if (sh.kind == Shape::Kind::kCircle) {
        for (int i = 0; i < kCirclePoints; ++i) {
          const double a = 2 * std::numbers::pi * i / kCirclePoints;
          pts.push_back(
              {sh.center.x + sh.radius * std::cos(a), sh.center.y + sh.radius * std::sin(a)});
        }
      }
      json o = Outline(pts);
      o["steps"] = steps;
      goals.push_back(std::move(o));
    }
    for (int id : g.lanelets) {
      const Lanelet* l = sc.FindLanelet(id);
      if (l == nullptr) continue;
      json o = Outline(l->Polygon());
      o["steps"] = steps;
      goals.push_back(std::move(o));
    }
  }
  return goals;
}

// An obstacle row of the telemetry, with what the drawing needs beyond the planner's row.
struct CarRow {
  plan::SensorCar car;
  double heading = 0;  // rad
};

}  // namespace

std::string RecordFileName(std::string_view benchmark_id, int problem_id) {
  std::string name = FileNamePart(benchmark_id);
  if (name.empty()) name = "scenario";
  return name + "_" + std::to_string(problem_id) + ".jsonl.gz";
}

RunRecorder::RunRecorder(const Scenario& scenario, std::string dir, int vehicle_type,
                         PredictionMode prediction, bool timing)
    : scenario_(scenario),
      dir_(std::move(dir)),
      vehicle_type_(vehicle_type),
      prediction_(prediction),
      timing_(timing) {}

RunRecorder::~RunRecorder() = default;

void RunRecorder::Attach(RunOptions* options) {
  options->on_plan = [this](const CycleInput& in, const plan::PlanResult& result) {
    OnPlan(in, result);
  };
  options->on_problem_end = [this](const PlanningProblem& problem, const ProblemRun& run) {
    OnProblemEnd(problem, run);
  };
}

void RunRecorder::OnPlan(const CycleInput& in, const plan::PlanResult& result) {
  if (failed_) return;
  const map::Road& road = *in.road;
  if (!writer_) {
    problem_ = in.problem.id;
    index_ = 0;
    path_ =
        (std::filesystem::path(dir_) / RecordFileName(scenario_.benchmark_id, problem_)).string();
    auto writer = record::Writer::Open(path_);
    if (!writer.ok()) {
      failed_ = true;
      if (status_.ok()) status_ = writer.status();
      return;
    }
    writer_ = std::move(writer).value();
    const VehicleParams vp = VehicleParamsForType(vehicle_type_).ok()
                                 ? *VehicleParamsForType(vehicle_type_)
                                 : VehicleParams();
    json h = {{key::kType, key::kHeader},
              {key::kVersion, record::kVersion},
              {key::kWorld, key::kCommonRoad},
              {key::kMap, scenario_.source},
              {key::kScenario, scenario_.benchmark_id},
              {key::kProblem, problem_},
              {key::kDt, scenario_.dt},
              {key::kSeed, 0},
              {key::kPlanner, "search"},
              {key::kConfig, record::YamlToJson(in.config.ToYaml())},
              {key::kPrediction, ToString(prediction_)},
              {key::kVehicle, "KS" + std::to_string(vehicle_type_)},
              {key::kTiming, timing_ ? "wall" : "off"},
              {key::kLanes, road.num_lanes()},
              {key::kLaneWidth, Round(road.lane_width(), 3)},
              {key::kMaxS, Round(road.line().length(), 3)},
              {key::kCarLength, vp.length},
              {key::kCarWidth, vp.width},
              {key::kRoad, RoadJson(road)},
              {key::kGoals, GoalsJson(scenario_, in.problem)}};
    writer_->WriteText(JsonText(h));
    auto planner = plan::MakePlanner("search", in.config, in.road);
    if (!planner.ok()) {
      spdlog::warn("record {}: no planner to trace the candidates ({}); they are left out", path_,
                   planner.message());
    }
    replica_ = std::make_shared<record::Replica>(
        planner.ok() ? std::move(planner).value() : nullptr, kRecordCandidates, path_);
  }
  // Copies for the writer's thread.
  const plan::Telemetry& t = in.telemetry;
  std::vector<CarRow> cars;
  cars.reserve(t.sensor_fusion.size());
  for (const plan::SensorCar& c : t.sensor_fusion) {
    CarRow row{c, std::atan2(c.vy, c.vx)};
    if (const Obstacle* o = scenario_.FindObstacle(c.id); o != nullptr) {
      const std::optional<State> st = o->StateAt(in.step);
      if (st && st->orientation) row.heading = *st->orientation;
    }
    cars.push_back(row);
  }
  const double scale = timing_ ? 1.0 : 0.0;
  writer_->Write([i = index_++, step = in.step, seconds = in.step * scenario_.dt, x = t.x, y = t.y,
                  yaw = t.yaw, speed = t.speed, s = t.s, d = t.d, lane = road.LaneOf(t.s, t.d),
                  cars = std::move(cars), path_x = result.x, path_y = result.y,
                  status = result.status, summary = result.summary, scale,
                  candidates = std::vector<plan::CandidateTrace>(), telemetry = t,
                  least_harm = in.least_harm, replica = replica_](std::string* line) mutable {
    // The candidates, traced by the replica; its counts with the driving planner's times.
    replica->Trace(&telemetry, path_x, path_y, i, &summary, &candidates, least_harm);
    json rows = json::array();
    for (const CarRow& r : cars) {
      const plan::SensorCar& c = r.car;
      rows.push_back({c.id, Round(c.x, 3), Round(c.y, 3), Round(c.vx, 3), Round(c.vy, 3),
                      Round(c.s, 3), Round(c.d, 3), Round(c.length, 3), Round(c.width, 3),
                      Round(r.heading * units::kRadToDeg, 2)});
    }
    json px = json::array(), py = json::array();
    for (double v : path_x) px.push_back(Round(v, 3));
    for (double v : path_y) py.push_back(Round(v, 3));
    const json e = {
        {key::kType, key::kExchange},
        {key::kCycle, i},
        {key::kTime, Round(seconds, 6)},
        {key::kStep, step},
        {key::kTelemetry,
         {{"x", Round(x, 4)},
          {"y", Round(y, 4)},
          {"yaw", Round(yaw * units::kRadToDeg, 4)},
          {"speed", Round(speed * units::kMpsToMph, 4)},
          {"s", Round(s, 4)},
          {"d", Round(d, 4)},
          {key::kSensorFusion, std::move(rows)}}},
        {key::kPath, {{"x", std::move(px)}, {"y", std::move(py)}}},
        {key::kPlan, record::PlanJson(status, summary, summary.ms_total, scale, candidates)},
        {key::kMetrics, {{"speed_mph", Round(speed * units::kMpsToMph, 4)}, {"lane", lane}}},
        {key::kIncidents, json::array()}};
    *line += JsonText(e);
  });
  if (index_ % kDrainLines == 0) {
    if (const Status st = writer_->status(); !st.ok()) {
      if (status_.ok()) status_ = st;
      failed_ = true;
      writer_.reset();
      replica_.reset();
    }
  }
}

void RunRecorder::OnProblemEnd(const PlanningProblem& problem, const ProblemRun& run) {
  const bool open = writer_ != nullptr && problem_ == problem.id;
  failed_ = false;
  if (!open) return;
  json failures = json::array();
  for (const Failure& f : run.verdict.failures) {
    json e = {{"kind", ToString(f.kind)}, {"step", f.step}, {"detail", f.detail}};
    e["obstacle"] = f.obstacle_id ? json(*f.obstacle_id) : json(nullptr);
    if (f.entered_s) e["obstacle_entered_s"] = *f.entered_s;
    failures.push_back(std::move(e));
  }
  std::vector<double> ms;
  int fallbacks = 0;
  for (const RunCycle& c : run.cycles) {
    ms.push_back(c.plan_ms);
    fallbacks += c.status != plan::PlanStatus::kOk;
  }
  double distance = 0, max_speed = 0;
  for (size_t i = 0; i < run.trajectory.size(); ++i) {
    max_speed = std::max(max_speed, run.trajectory[i].velocity);
    if (i > 0) {
      distance += std::hypot(run.trajectory[i].x - run.trajectory[i - 1].x,
                             run.trajectory[i].y - run.trajectory[i - 1].y);
    }
  }
  const double seconds = run.cycles.size() * scenario_.dt;
  json by_kind = json::object();
  for (const Failure& f : run.verdict.failures) by_kind[ToString(f.kind)] = 1;
  const json report = {
      {"solved", run.verdict.solved},
      {"goal_step", run.verdict.goal_step ? json(*run.verdict.goal_step) : json(nullptr)},
      {"stop_reason", run.stop_reason},
      {"failures", std::move(failures)},
      {"incidents", std::move(by_kind)},
      {"steps", static_cast<int>(run.cycles.size())},
      {"distance_m", Round(distance, 3)},
      {"sim_seconds", Round(seconds, 6)},
      {"avg_speed_mph", Round(seconds > 0 ? distance / seconds * units::kMpsToMph : 0.0, 3)},
      {"max_speed_mph", Round(max_speed * units::kMpsToMph, 3)},
      {"plan_ms",
       {{"p50", Round(Percentile(ms, 0.5), 4)},
        {"p99", Round(Percentile(ms, 0.99), 4)},
        {"max", Round(ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end()), 4)}}},
      {"plan_fallbacks", fallbacks}};
  writer_->WriteText(JsonText(json({{key::kType, key::kFooter}, {key::kReport, report}})),
                     /*last=*/true);
  const Status st = writer_->status();
  writer_.reset();
  replica_.reset();
  if (!st.ok()) {
    if (status_.ok()) status_ = st;
    return;
  }
  files_.push_back(path_);
}

}  // namespace frenetic::commonroad

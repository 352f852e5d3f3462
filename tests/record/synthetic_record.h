// A synthetic record in the format of record/schema.h, written with the record module's own keys
// and plan object (record::PlanJson) and the footer in the shape the writers write, so the reader
// and the report are tested without the simulator: a short drive on a circular loop with
// traffic, candidates per cycle, a lane change and optionally one incident. Deterministic for a
// given seed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "frenetic/plan/planner.h"
#include "frenetic/record/plan_json.h"
#include "frenetic/record/schema.h"
#include "frenetic/units.h"

namespace frenetic::record::testing {

struct SyntheticOptions {
  int exchanges = 300;    // one per 0.1 s
  bool incident = false;  // a collision at exchange incident_at
  int incident_at = 150;
  bool footer = true;
  int candidates = 6;  // per cycle
  // A CommonRoad run's record: its header (world, problem, the planner's speed cap in its
  // config, the road's lanes over kSyntheticRoadEnd m of the loop instead of the centre line,
  // a goal region), cars of their own sizes and its verdict (a collision at exchange
  // kSyntheticFailureAt) as its footer.
  bool commonroad = false;
  std::uint64_t seed = 7;
};

inline constexpr double kSyntheticRadius = 250.0;     // m, radius of the loop's centre line
inline constexpr double kSyntheticDt = 0.1;           // s between exchanges
inline constexpr int kSyntheticLaneChangeAt = 100;    // the winner goes from lane 1 to lane 0 here
inline constexpr double kSyntheticRoadEnd = 800.0;    // m: a CommonRoad record's road ends here
inline constexpr int kSyntheticFailureAt = 200;       // a CommonRoad record's verdict: a collision
inline constexpr double kSyntheticMph = 1 / units::kMphToMps;  // mph per m/s

// Position on the loop: the road runs counter-clockwise, so d (to the right) points outward.
inline void SyntheticXY(double s, double d, double* x, double* y, double* yaw) {
  const double a = s / kSyntheticRadius;
  *x = (kSyntheticRadius + d) * std::cos(a);
  *y = (kSyntheticRadius + d) * std::sin(a);
  *yaw = a + std::numbers::pi / 2;
}

// The header line.
inline nlohmann::json SyntheticHeader(const SyntheticOptions& options) {
  using json = nlohmann::json;
  const double max_s = 2 * std::numbers::pi * kSyntheticRadius;
  json center = json::array();
  for (double s = 0; s < max_s; s += 2.0) {
    double x, y, yaw;
    SyntheticXY(s, 0, &x, &y, &yaw);
    center.push_back({x, y});
  }
  json header = {
      {key::kType, key::kHeader},
      {key::kVersion, kVersion},
      {key::kMap, "synthetic-loop"},
      {key::kMaxS, max_s},
      {key::kLaneWidth, 4},
      {key::kLanes, 3},
      {key::kScenario, "synthetic"},
      {key::kSeed, options.seed},
      {key::kPlanner, "search"},
      {key::kConfig, {{"weights", {{"efficiency", 2.0}, {"comfort", 1.0}, {"lane_change", 3.0}}}}},
      {key::kCenterline, center},
      {key::kCarLength, 4.6},
      {key::kCarWidth, 2.4}};
  if (!options.commonroad) return header;
  header[key::kWorld] = key::kCommonRoad;
  header[key::kProblem] = 1;
  header[key::kDt] = kSyntheticDt;
  header[key::kPrediction] = "recorded";
  header[key::kVehicle] = "KS2";
  header[key::kConfig]["limits"] = {{"max_speed_mph", 80.5}};
  header[key::kCenterline] = json::array();
  json lanes = json::array();
  for (int l = 0; l < 3; ++l) {
    json lx = json::array(), ly = json::array(), rx = json::array(), ry = json::array();
    for (double s = 0; s <= kSyntheticRoadEnd; s += 10) {
      double x, y, yaw;
      SyntheticXY(s, 4 * l, &x, &y, &yaw);
      lx.push_back(x);
      ly.push_back(y);
      SyntheticXY(s, 4 * l + 4, &x, &y, &yaw);
      rx.push_back(x);
      ry.push_back(y);
    }
    lanes.push_back({{key::kLeft, {{"x", lx}, {"y", ly}}}, {key::kRight, {{"x", rx}, {"y", ry}}}});
  }
  header[key::kRoad] = {{key::kLanes, lanes}};
  json gx = json::array(), gy = json::array();
  for (const auto& [s, d] : {std::pair{700.0, 0.0}, {740.0, 0.0}, {740.0, 12.0}, {700.0, 12.0}}) {
    double x, y, yaw;
    SyntheticXY(s, d, &x, &y, &yaw);
    gx.push_back(x);
    gy.push_back(y);
  }
  header[key::kGoals] = json::array({{{"x", gx}, {"y", gy}, {key::kSteps, {250, 350}}}});
  return header;
}

// The footer's report: a drive's in the shape of DriveReport::ToJson (drive_report.h), a
// CommonRoad run's verdict in the shape of commonroad::RunRecorder's.
inline nlohmann::json SyntheticFooter(const SyntheticOptions& options, double distance,
                                      double gap_min, int incidents) {
  using json = nlohmann::json;
  const double seconds = options.exchanges * kSyntheticDt;
  const json plan_ms = {{"p50", 2.2}, {"p99", 2.5}, {"max", 2.5}};
  json report;
  if (options.commonroad) {
    report = {{"solved", false},
              {"goal_step", nullptr},
              {"stop_reason", "collision"},
              {"failures", json::array({{{"kind", "collision"},
                                         {"step", kSyntheticFailureAt},
                                         {"detail", "with obstacle 3"},
                                         {"obstacle", 3}}})},
              {"incidents", {{"collision", 1}}},
              {"steps", options.exchanges},
              {"distance_m", distance},
              {"sim_seconds", seconds},
              {"avg_speed_mph", distance / seconds * kSyntheticMph},
              {"max_speed_mph", 48.1},
              {"plan_ms", plan_ms},
              {"plan_fallbacks", 0}};
  } else {
    report = {{"distance_m", distance},
              {"miles", distance / units::kMetersPerMile},
              {"sim_seconds", seconds},
              {"avg_speed_mph", distance / seconds * kSyntheticMph},
              {"incidents", incidents},
              {"incidents_by_kind", {{"collision", incidents}}},
              {"miles_to_first_incident", nullptr},
              {"max_speed_mph", 48.1},
              {"max_acc", 1.5},
              {"max_jerk", 3.0},
              {"lane_changes", 1},
              {"min_gap_m", gap_min},
              {"min_headway_s", 1.2},
              {"plan_ms", plan_ms},
              {"plan_fallbacks", 0}};
  }
  return {{key::kType, key::kFooter}, {key::kReport, report}};
}

// The record, one JSON object per line.
inline std::string SyntheticRecord(const SyntheticOptions& options = {}) {
  using json = nlohmann::json;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  const double max_s = 2 * std::numbers::pi * kSyntheticRadius;
  std::string out = SyntheticHeader(options).dump() + "\n";

  const std::vector<std::string> terms = {"efficiency", "comfort", "lane_change"};
  const std::vector<double> weights = {2.0, 1.0, 3.0};
  constexpr int kReasons = 5;  // speed, acceleration, jerk, off_road, collision in turn
  double ego_s = 10, ego_d = 6, speed = 15;
  std::vector<double> car_s = {40, 80, 130, 200, 260, 320}, car_d = {6, 2, 10, 6, 2, 10},
                      car_v = {14, 18, 16, 17, 19, 15};
  double gap_min = 1e9;
  int incidents_total = 0;
  for (int k = 0; k < options.exchanges; ++k) {
    const double t = k * kSyntheticDt;
    const int target_lane = k < kSyntheticLaneChangeAt ? 1 : 0;
    const double target_d = 2 + 4 * target_lane;
    ego_d += std::clamp(target_d - ego_d, -0.15, 0.15);
    speed = std::min(speed + 0.2, 21.5);
    ego_s += speed * kSyntheticDt;
    for (size_t c = 0; c < car_s.size(); ++c) car_s[c] += car_v[c] * kSyntheticDt;
    double x, y, yaw;
    SyntheticXY(ego_s, ego_d, &x, &y, &yaw);

    json fusion = json::array();
    double gap = -1;
    for (size_t c = 0; c < car_s.size(); ++c) {
      double cx, cy, cyaw;
      SyntheticXY(car_s[c], car_d[c], &cx, &cy, &cyaw);
      fusion.push_back({static_cast<int>(c), cx, cy, car_v[c] * std::cos(cyaw),
                        car_v[c] * std::sin(cyaw), std::fmod(car_s[c], max_s), car_d[c]});
      if (options.commonroad) {  // length, width, heading (deg)
        for (double v : {4.0 + 0.4 * c, 1.8, cyaw * 180 / std::numbers::pi}) {
          fusion.back().push_back(v);
        }
      }
      const double ahead = car_s[c] - ego_s;
      if (std::abs(car_d[c] - ego_d) < 2 && ahead > 0 && (gap < 0 || ahead < gap)) gap = ahead;
    }
    json path_x = json::array(), path_y = json::array();
    for (int p = 1; p <= 50; ++p) {
      double px, py, pyaw;
      SyntheticXY(ego_s + speed * 0.02 * p,
                  ego_d + std::clamp(target_d - ego_d, -0.02 * p, 0.02 * p), &px, &py, &pyaw);
      path_x.push_back(px);
      path_y.push_back(py);
    }

    // Candidates: lanes 0..2 x end speeds; costs from simple formulas so the winner is the
    // cheapest candidate that passed; every 4th cycle the best one is rejected.
    std::vector<plan::CandidateTrace> cands;
    for (int c = 0; c < options.candidates; ++c) {
      plan::CandidateTrace cand;
      cand.lane = c % 3;
      cand.end_speed = 18 + 1.5 * (c / 3);
      cand.duration = 3.0;
      const std::vector<double> values = {
          (22.0 - cand.end_speed) / 22.0 + 0.01 * std::abs(noise(rng)), 0.1 + 0.05 * c,
          cand.lane == target_lane ? 0.0 : 1.0};
      for (size_t i = 0; i < terms.size(); ++i) {
        cand.costs.push_back({terms[i], weights[i], values[i]});
        cand.total_cost += weights[i] * values[i];
      }
      cands.push_back(std::move(cand));
    }
    std::sort(cands.begin(), cands.end(),
              [](const auto& a, const auto& b) { return a.total_cost < b.total_cost; });
    plan::PlanSummary summary;
    const int winner = k % 4 == 0 ? 1 : 0;
    for (size_t c = 0; c < cands.size(); ++c) {
      plan::CandidateTrace& cand = cands[c];
      cand.checked = static_cast<int>(c) <= winner;
      cand.winner = static_cast<int>(c) == winner;
      if (k % 4 == 0 && c == 0) {
        cand.reject = (k / 4) % kReasons;
        ++summary.rejections[cand.reject];
      }
      for (int p = 0; p <= 12; ++p) {
        const double tau = p * 0.25;
        const double d = ego_d + (2 + 4 * cand.lane - ego_d) * std::min(1.0, tau / 3.0);
        double px, py, pyaw;
        SyntheticXY(ego_s + (speed + (cand.end_speed - speed) * tau / 6) * tau, d, &px, &py, &pyaw);
        cand.x.push_back(px);
        cand.y.push_back(py);
      }
    }
    const plan::CandidateTrace& w = cands[winner];
    summary.candidates_generated = summary.candidates_scored = 120;
    summary.candidates_checked = winner + 1;
    summary.candidates_feasible = 1;
    summary.winner_costs = w.costs;
    summary.winner_total_cost = w.total_cost;
    summary.winner_lane = w.lane;
    summary.winner_end_speed = w.end_speed;
    summary.winner_duration = w.duration;
    summary.refine_iterations = 10;
    summary.refine_cost_before = w.total_cost;
    summary.refine_cost_after = w.total_cost * 0.95;
    const double plan_ms = 2.0 + 0.5 * std::abs(noise(rng));

    json incidents = json::array();
    if (options.incident && k == options.incident_at) {
      incidents.push_back({{"t", t},
                           {"s", std::fmod(ego_s, max_s)},
                           {"d", ego_d},
                           {"lane", static_cast<int>(ego_d / 4)},
                           {"kind", "collision"},
                           {"value", 1}});
      ++incidents_total;
    }
    if (gap > 0) gap_min = std::min(gap_min, gap);
    json exchange = {{key::kType, key::kExchange},
                     {key::kCycle, k},
                     {key::kTime, t},
                     {key::kTelemetry,
                      {{"x", x},
                       {"y", y},
                       {"yaw", yaw * 180 / std::numbers::pi},
                       {"speed", speed * kSyntheticMph},
                       {"s", std::fmod(ego_s, max_s)},
                       {"d", ego_d},
                       {"previous_path_x", json::array()},
                       {"previous_path_y", json::array()},
                       {"end_path_s", 0},
                       {"end_path_d", 0},
                       {key::kSensorFusion, fusion}}},
                     {key::kPath, {{"x", path_x}, {"y", path_y}}},
                     {key::kPlan, PlanJson(plan::PlanStatus::kOk, summary, plan_ms, 1.0, cands)},
                     {key::kMetrics,
                      {{"speed_mph", speed * kSyntheticMph},
                       {"acc", 1.0 + 0.5 * noise(rng)},
                       {"jerk", 2.0 + noise(rng)},
                       {"lane", static_cast<int>(ego_d / 4)},
                       {"gap", gap > 0 ? json(gap) : json(nullptr)},
                       {"headway", gap > 0 ? json(gap / speed) : json(nullptr)}}},
                     {key::kIncidents, incidents}};
    out += exchange.dump() + "\n";
  }
  if (options.footer) {
    out += SyntheticFooter(options, ego_s - 10, gap_min, incidents_total).dump() + "\n";
  }
  return out;
}

}  // namespace frenetic::record::testing

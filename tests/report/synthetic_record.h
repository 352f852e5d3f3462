// A synthetic drive record in the schema of `frenetic drive --record` (see
// include/frenetic/report/record.h), so the report is tested without the simulator: a short
// drive on a circular loop with traffic, candidates per cycle, a lane change and optionally one
// incident. Deterministic for a given seed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "frenetic/units.h"
namespace frenetic::report::testing {

struct SyntheticOptions {
  int exchanges = 300;          // one per 0.1 s
  bool incident = false;        // a collision at exchange incident_at
  int incident_at = 150;
  bool footer = true;
  // The footer in the shape `frenetic drive` writes (incidents as a number, incidents_by_kind,
  // plan_ms {p50, p99, max}, miles) instead of the names of the record's spec.
  bool simulator_footer = false;
  int candidates = 6;           // per cycle
  // A CommonRoad run's record: its header (world, problem, the planner's speed cap in its
  // config, the road's lanes over kSyntheticRoadEnd m of the loop instead of the centre line,
  // a goal region), cars of their own sizes and its verdict (a collision at exchange
  // kSyntheticFailureAt) in the footer.
  bool commonroad = false;
  std::uint64_t seed = 7;
};

inline constexpr double kSyntheticRadius = 250.0;  // m, radius of the loop's centre line
inline constexpr double kSyntheticDt = 0.1;        // s between exchanges
inline constexpr int kSyntheticLaneChangeAt = 100; // the winner goes from lane 1 to lane 0 here
inline constexpr double kSyntheticRoadEnd = 800.0;  // m: a CommonRoad record's road ends here
inline constexpr int kSyntheticFailureAt = 200;     // a CommonRoad record's verdict: a collision

// Position on the loop: the road runs counter-clockwise, so d (to the right) points outward.
inline void SyntheticXY(double s, double d, double* x, double* y, double* yaw) {
  const double a = s / kSyntheticRadius;
  *x = (kSyntheticRadius + d) * std::cos(a);
  *y = (kSyntheticRadius + d) * std::sin(a);
  *yaw = a + std::numbers::pi / 2;
}

// The record, one JSON object per line.
inline std::string SyntheticRecord(const SyntheticOptions& options = {}) {
  using json = nlohmann::json;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  const double max_s = 2 * std::numbers::pi * kSyntheticRadius;
  std::string out;

  json center = json::array();
  for (double s = 0; s < max_s; s += 2.0) {
    double x, y, yaw;
    SyntheticXY(s, 0, &x, &y, &yaw);
    center.push_back({x, y});
  }
  json header = {{"type", "header"}, {"version", 1}, {"map", "synthetic-loop"},
                 {"max_s", max_s}, {"lane_width", 4}, {"lanes", 3}, {"scenario", "synthetic"},
                 {"seed", options.seed}, {"planner", "search"},
                 {"config", {{"weights", {{"efficiency", 2.0}, {"comfort", 1.0},
                                          {"lane_change", 3.0}}}}},
                 {"centerline", center}, {"car_length", 4.6}, {"car_width", 2.4}};
  if (options.commonroad) {
    header["world"] = "commonroad";
    header["problem"] = 1;
    header["dt"] = kSyntheticDt;
    header["prediction"] = "recorded";
    header["vehicle"] = "KS2";
    header["config"]["limits"] = {{"max_speed_mph", 80.5}};
    header["centerline"] = json::array();
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
      lanes.push_back({{"left", {{"x", lx}, {"y", ly}}}, {"right", {{"x", rx}, {"y", ry}}}});
    }
    header["road"] = {{"lanes", lanes}};
    json gx = json::array(), gy = json::array();
    for (const auto& [s, d] : {std::pair{700.0, 0.0}, {740.0, 0.0}, {740.0, 12.0}, {700.0, 12.0}}) {
      double x, y, yaw;
      SyntheticXY(s, d, &x, &y, &yaw);
      gx.push_back(x);
      gy.push_back(y);
    }
    header["goals"] = json::array({{{"x", gx}, {"y", gy}, {"steps", {250, 350}}}});
  }
  out += header.dump() + "\n";

  const std::vector<std::string> terms = {"efficiency", "comfort", "lane_change"};
  const std::vector<double> weights = {2.0, 1.0, 3.0};
  const std::vector<std::string> reasons = {"speed", "acceleration", "jerk", "off_road",
                                            "collision"};
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
      SyntheticXY(ego_s + speed * 0.02 * p, ego_d + std::clamp(target_d - ego_d, -0.02 * p, 0.02 * p),
                  &px, &py, &pyaw);
      path_x.push_back(px);
      path_y.push_back(py);
    }

    // Candidates: lanes 0..2 x end speeds; costs from simple formulas so the winner is the
    // cheapest candidate that passed; a few are rejected.
    json candidates = json::array();
    struct Cand { int lane; double end_speed; std::vector<double> values; double total; };
    std::vector<Cand> cands;
    for (int c = 0; c < options.candidates; ++c) {
      Cand cand;
      cand.lane = c % 3;
      cand.end_speed = 18 + 1.5 * (c / 3);
      cand.values = {(22.0 - cand.end_speed) / 22.0 + 0.01 * std::abs(noise(rng)),
                     0.1 + 0.05 * c, cand.lane == target_lane ? 0.0 : 1.0};
      cand.total = 0;
      for (size_t i = 0; i < terms.size(); ++i) cand.total += weights[i] * cand.values[i];
      cands.push_back(cand);
    }
    std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) { return a.total < b.total; });
    json rejections = {{"speed", 0}, {"acceleration", 0}, {"jerk", 0}, {"off_road", 0},
                       {"collision", 0}};
    // The checks run best first until one passes: every 4th cycle the best one is rejected.
    const int winner = k % 4 == 0 ? 1 : 0;
    const int checked = winner + 1;
    for (size_t c = 0; c < cands.size(); ++c) {
      json cj = {{"lane", cands[c].lane}, {"end_speed", cands[c].end_speed}, {"duration", 3.0},
                 {"total_cost", cands[c].total}};
      const std::string reject =
          (k % 4 == 0 && c == 0) ? reasons[(k / 4) % reasons.size()] : std::string();
      cj["checked"] = static_cast<int>(c) <= winner;
      cj["winner"] = static_cast<int>(c) == winner;
      cj["reject"] = reject.empty() ? json(nullptr) : json(reject);
      if (!reject.empty()) rejections[reject] = rejections[reject].get<int>() + 1;
      json cx = json::array(), cy = json::array(), costs = json::array();
      for (int p = 0; p <= 12; ++p) {
        const double tau = p * 0.25;
        const double d = ego_d + (2 + 4 * cands[c].lane - ego_d) * std::min(1.0, tau / 3.0);
        double px, py, pyaw;
        SyntheticXY(ego_s + (speed + (cands[c].end_speed - speed) * tau / 6) * tau, d, &px, &py,
                    &pyaw);
        cx.push_back(px);
        cy.push_back(py);
      }
      for (size_t i = 0; i < terms.size(); ++i) {
        costs.push_back({{"name", terms[i]}, {"weight", weights[i]}, {"value", cands[c].values[i]}});
      }
      cj["x"] = cx;
      cj["y"] = cy;
      cj["costs"] = costs;
      candidates.push_back(cj);
    }
    const Cand& w = cands[winner];
    json winner_costs = json::array();
    for (size_t i = 0; i < terms.size(); ++i) {
      winner_costs.push_back({{"name", terms[i]}, {"weight", weights[i]}, {"value", w.values[i]}});
    }
    json incidents = json::array();
    if (options.incident && k == options.incident_at) {
      incidents.push_back({{"t", t}, {"s", std::fmod(ego_s, max_s)}, {"d", ego_d},
                           {"lane", static_cast<int>(ego_d / 4)}, {"kind", "collision"},
                           {"value", 1}});
      ++incidents_total;
    }
    if (gap > 0) gap_min = std::min(gap_min, gap);
    json exchange = {
        {"type", "exchange"}, {"i", k}, {"t", t},
        {"telemetry", {{"x", x}, {"y", y}, {"yaw", yaw * 180 / std::numbers::pi},
                       {"speed", speed / units::kMphToMps}, {"s", std::fmod(ego_s, max_s)},
                       {"d", ego_d},
                       {"previous_path_x", json::array()}, {"previous_path_y", json::array()},
                       {"end_path_s", 0}, {"end_path_d", 0}, {"sensor_fusion", fusion}}},
        {"path", {{"x", path_x}, {"y", path_y}}},
        {"plan", {{"status", "ok"}, {"ms_total", 2.0 + 0.5 * std::abs(noise(rng))},
                  {"candidates_generated", 120}, {"candidates_scored", 120},
                  {"candidates_checked", checked}, {"candidates_feasible", 1},
                  {"rejections", rejections}, {"winner_costs", winner_costs},
                  {"winner_total_cost", w.total}, {"winner_lane", w.lane},
                  {"refine_iterations", 10}, {"refine_cost_before", w.total},
                  {"refine_cost_after", w.total * 0.95}, {"candidates", candidates}}},
        {"metrics", {{"speed_mph", speed / units::kMphToMps}, {"acc", 1.0 + 0.5 * noise(rng)},
                     {"jerk", 2.0 + noise(rng)}, {"lane", static_cast<int>(ego_d / 4)},
                     {"gap", gap > 0 ? json(gap) : json(nullptr)},
                     {"headway", gap > 0 ? json(gap / speed) : json(nullptr)}}},
        {"incidents", incidents}};
    out += exchange.dump() + "\n";
  }
  if (options.footer) {
    const double distance = ego_s - 10;
    const double seconds = options.exchanges * kSyntheticDt;
    json footer = {{"type", "footer"},
                   {"report", {{"distance_m", distance},
                               {"distance_miles", distance / units::kMetersPerMile},
                               {"sim_seconds", seconds},
                               {"avg_speed_mph", distance / seconds / units::kMphToMps},
                               {"incidents", {{"collision", incidents_total}}},
                               {"incidents_total", incidents_total},
                               {"miles_to_first_incident", nullptr},
                               {"max_speed_mph", 48.1}, {"max_acc", 1.5}, {"max_jerk", 3.0},
                               {"lane_changes", 1}, {"min_gap_m", gap_min},
                               {"min_headway_s", 1.2}, {"plan_ms_p50", 2.2},
                               {"plan_ms_p99", 2.5}, {"plan_ms_max", 2.5}}}};
    if (options.simulator_footer) {
      json& r = footer["report"];
      r["miles"] = r["distance_miles"];
      r["incidents_by_kind"] = r["incidents"];
      r["incidents"] = incidents_total;
      r["plan_ms"] = {{"p50", 2.2}, {"p99", 2.5}, {"max", 2.5}};
      for (const char* key : {"distance_miles", "incidents_total", "plan_ms_p50", "plan_ms_p99",
                              "plan_ms_max"}) {
        r.erase(key);
      }
    }
    if (options.commonroad) {  // the verdict, in the shape `frenetic commonroad --record` writes
      json& r = footer["report"];
      r["solved"] = false;
      r["goal_step"] = nullptr;
      r["stop_reason"] = "collision";
      r["failures"] = json::array({{{"kind", "collision"}, {"step", kSyntheticFailureAt},
                                    {"detail", "with obstacle 3"}, {"obstacle", 3}}});
      r["incidents"] = {{"collision", 1}};
      r.erase("incidents_total");
    }
    out += footer.dump() + "\n";
  }
  return out;
}

}  // namespace frenetic::report::testing

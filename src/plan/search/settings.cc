#include "plan/search/settings.h"

#include <algorithm>
#include <limits>

#include "frenetic/cost/cost_term.h"
#include "frenetic/units.h"

namespace frenetic::plan::search {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

Settings::Settings(const PlannerConfig& c) {
  max_speed = c.value("limits.max_speed_mph") * units::kMphToMps;
  max_accel = c.value("limits.max_accel");
  max_jerk = c.value("limits.max_jerk");
  d_min = c.value("limits.d_min");
  d_max = c.value("limits.d_max");
  lane_width = c.value("road.lane_width");
  outer_inset = c.value("road.outer_lane_inset");
  num_lanes = std::clamp(c.int_value("road.num_lanes"), 1, cost::kMaxLanes);
  uniform_road = true;
  edge_margin = c.value("limits.edge_margin");
  ego_length = c.value("check.ego_length");
  ego_width = c.value("check.ego_width");
  vehicle.wheelbase = c.value("vehicle.wheelbase");
  vehicle.max_steer = c.value("vehicle.max_steer");
  vehicle.max_steer_rate = c.value("vehicle.max_steer_rate");
  vehicle.max_accel = c.value("vehicle.max_accel");
  vehicle.switch_speed = c.value("vehicle.switch_speed");
  keep_points = c.int_value("continuity.keep_points");
  output_points = c.int_value("continuity.output_points");
  resync_tolerance = c.value("continuity.resync_tolerance");
  replan_min_ticks = c.int_value("continuity.replan_min_ticks");
  replan_deviation = c.value("continuity.replan_deviation");
  speeds = c.int_value("grid.speeds");
  lane_limit_speeds = c.int_value("grid.lane_limit_speeds") != 0;
  durations = c.int_value("grid.durations");
  min_duration = c.value("grid.min_duration");
  max_duration = c.value("grid.max_duration");
  follow_gaps = c.int_value("grid.follow_gaps");
  gap_targets = c.int_value("grid.gap_targets");
  follow_d0 = c.value("grid.follow_d0");
  follow_tau = c.value("grid.follow_tau");
  follow_tau_step = c.value("grid.follow_tau_step");
  stop = c.int_value("grid.stop") != 0;
  brake_decels = c.int_value("grid.brake_decels");
  brake_targets = c.int_value("grid.brake_targets");
  brake_min_decel = c.value("grid.brake_min_decel");
  brake_max_decel = c.value("grid.brake_max_decel");
  accels = c.int_value("grid.accels");
  accel_min = c.value("grid.min_accel");
  accel_max = c.value("grid.max_accel");
  lat_durations = c.int_value("grid.lat_durations");
  lat_min_duration = c.value("grid.lat_min_duration");
  lat_max_duration = c.value("grid.lat_max_duration");
  lat_offsets = c.int_value("grid.lat_offsets");
  lat_offset_step = c.value("grid.lat_offset_step");
  lane_reach = c.value("grid.lane_reach");
  lat_delays = c.int_value("grid.lat_delays");
  passes = c.int_value("grid.passes") != 0;
  lat_delay_step = c.value("grid.lat_delay_step");
  score_dt = c.value("score.dt");
  score_horizon = c.value("score.horizon");
  check_horizon = c.value("check.horizon");
  collision_dt = c.value("check.collision_dt");
  car_length = c.value("check.car_length");
  car_width = c.value("check.car_width");
  margin_s = c.value("check.margin_s");
  margin_d = c.value("check.margin_d");
  margin_behind = c.value("check.margin_behind");
  headway_min = c.value("check.headway_min");
  clear_enough = c.value("check.clear_enough");
  curve_prefilter = c.int_value("check.curve_prefilter") != 0;
  behind_time = c.value("check.behind_time");
  followers_react = c.int_value("prediction.followers_react") != 0;
  refine = c.int_value("refine.enabled") != 0;
  refine_iterations = c.int_value("refine.max_iterations");
  // A pinned deadline never fires (PlannerConfig::PinDeadlines).
  refine_budget_ms = c.refine_budget_pinned() ? kInf : c.value("refine.budget_ms");
  fallback_decel = c.value("fallback.decel");
  fallback_jerk = c.value("fallback.jerk");
  fallback_lat_duration = c.value("fallback.lat_duration");
  budget_ms = c.budget_pinned() ? kInf : c.budget_ms();
}

Settings::Settings(const PlannerConfig& c, const map::Road& road) : Settings(c) {
  lane_width = road.lane_width();
  num_lanes = std::clamp(road.num_lanes(), 1, cost::kMaxLanes);
  uniform_road = road.uniform();
}

}  // namespace frenetic::plan::search

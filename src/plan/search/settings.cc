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
  limits.max_speed = c.value("limits.max_speed_mph") * units::kMphToMps;
  limits.max_accel = c.value("limits.max_accel");
  limits.max_jerk = c.value("limits.max_jerk");
  limits.d_min = c.value("limits.d_min");
  limits.d_max = c.value("limits.d_max");
  road.lane_width = c.value("road.lane_width");
  road.outer_inset = c.value("road.outer_lane_inset");
  road.num_lanes = std::clamp(c.int_value("road.num_lanes"), 1, cost::kMaxLanes);
  road.uniform = true;
  limits.edge_margin = c.value("limits.edge_margin");
  limits.backward_speed = c.value("limits.backward_speed");
  check.ego_length = c.value("check.ego_length");
  check.ego_width = c.value("check.ego_width");
  vehicle.wheelbase = c.value("vehicle.wheelbase");
  vehicle.max_steer = c.value("vehicle.max_steer");
  vehicle.max_steer_rate = c.value("vehicle.max_steer_rate");
  vehicle.max_accel = c.value("vehicle.max_accel");
  vehicle.switch_speed = c.value("vehicle.switch_speed");
  continuity.keep_points = c.int_value("continuity.keep_points");
  continuity.output_points = c.int_value("continuity.output_points");
  continuity.resync_tolerance = c.value("continuity.resync_tolerance");
  continuity.replan_min_ticks = c.int_value("continuity.replan_min_ticks");
  continuity.replan_deviation = c.value("continuity.replan_deviation");
  grid.speeds = c.int_value("grid.speeds");
  grid.lane_limit_speeds = c.int_value("grid.lane_limit_speeds") != 0;
  grid.durations = c.int_value("grid.durations");
  grid.min_duration = c.value("grid.min_duration");
  grid.max_duration = c.value("grid.max_duration");
  grid.follow_gaps = c.int_value("grid.follow_gaps");
  grid.gap_targets = c.int_value("grid.gap_targets");
  grid.follow_d0 = c.value("grid.follow_d0");
  grid.follow_tau = c.value("grid.follow_tau");
  grid.follow_tau_step = c.value("grid.follow_tau_step");
  grid.stop = c.int_value("grid.stop") != 0;
  brake.decels = c.int_value("grid.brake_decels");
  brake.targets = c.int_value("grid.brake_targets");
  brake.min_decel = c.value("grid.brake_min_decel");
  brake.max_decel = c.value("grid.brake_max_decel");
  grid.accels = c.int_value("grid.accels");
  grid.accel_min = c.value("grid.min_accel");
  grid.accel_max = c.value("grid.max_accel");
  grid.limit_ramps = c.int_value("grid.limit_ramps") != 0;
  lat.durations = c.int_value("grid.lat_durations");
  lat.min_duration = c.value("grid.lat_min_duration");
  lat.max_duration = c.value("grid.lat_max_duration");
  lat.offsets = c.int_value("grid.lat_offsets");
  lat.offset_step = c.value("grid.lat_offset_step");
  lat.escape_offsets = c.int_value("grid.escape_lat_offsets");
  lat.escape_offset_step = c.value("grid.escape_lat_offset_step");
  lat.escape_duration = c.value("grid.escape_lat_duration");
  lat.escape_least_harm = c.int_value("grid.escape_lat_least_harm") != 0;
  grid.lane_reach = c.value("grid.lane_reach");
  lat.delays = c.int_value("grid.lat_delays");
  grid.passes = c.int_value("grid.passes") != 0;
  lat.delay_step = c.value("grid.lat_delay_step");
  score.dt = c.value("score.dt");
  score.horizon = c.value("score.horizon");
  check.horizon = c.value("check.horizon");
  check.collision_dt = c.value("check.collision_dt");
  check.car_length = c.value("check.car_length");
  check.car_width = c.value("check.car_width");
  check.margin_s = c.value("check.margin_s");
  check.margin_d = c.value("check.margin_d");
  check.margin_behind = c.value("check.margin_behind");
  check.headway_min = c.value("check.headway_min");
  check.clear_enough = c.value("check.clear_enough");
  const double side_clear = c.value("check.side_clear");
  check.side_clear = side_clear > 0 ? side_clear : std::numeric_limits<double>::infinity();
  check.keep_side = c.value("check.keep_side");
  check.last_resort_ticks = c.int_value("check.last_resort_ticks");
  check.keep_lane = c.value("check.keep_lane");
  check.curve_prefilter = c.int_value("check.curve_prefilter") != 0;
  check.behind_time = c.value("check.behind_time");
  followers_react = c.int_value("prediction.followers_react") != 0;
  refine.enabled = c.int_value("refine.enabled") != 0;
  refine.iterations = c.int_value("refine.max_iterations");
  // A pinned deadline never fires (PlannerConfig::PinDeadlines).
  refine.budget_ms = c.refine_budget_pinned() ? kInf : c.value("refine.budget_ms");
  fallback.decel = c.value("fallback.decel");
  fallback.jerk = c.value("fallback.jerk");
  fallback.lat_duration = c.value("fallback.lat_duration");
  budget_ms = c.budget_pinned() ? kInf : c.budget_ms();
}

Settings::Settings(const PlannerConfig& c, const map::Road& on) : Settings(c) {
  road.lane_width = on.lane_width();
  road.num_lanes = std::clamp(on.num_lanes(), 1, cost::kMaxLanes);
  road.uniform = on.uniform();
}

}  // namespace frenetic::plan::search

#include "frenetic/sim/simulator.h"

#include <cmath>
#include <limits>

#include "frenetic/units.h"

namespace frenetic::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The real start pose (§4.3) and its s, used on other maps as the start s of the middle lane.
constexpr double kUdacityStartX = 909.48, kUdacityStartY = 1128.67, kUdacityStartS = 124.8336;

double NanToZero(double v) { return std::isnan(v) ? 0.0 : v; }

bool FiniteAsFloat(double v) {
  return std::isfinite(v) && std::abs(v) <= std::numeric_limits<float>::max();
}

}  // namespace

StatusOr<std::unique_ptr<Simulator>> Simulator::Create(std::shared_ptr<const World> world,
                                                       const Scenario& scenario,
                                                       std::uint64_t seed) {
  if (!world || !world->line || !world->chord) return Status::Error("simulator: no world");
  if (Status s = scenario.Validate(); !s.ok()) return s;
  double x = 0, y = 0, yaw = 0;
  const StartPose& p = scenario.start;
  auto on_line = [&](double s, double d) {
    const map::CartesianPose pose = world->line->ToCartesian(s, d);
    x = pose.x;
    y = pose.y;
    yaw = pose.heading;
  };
  switch (p.kind) {
    case StartPose::Kind::kAuto:
      if (world->is_udacity_map) {
        x = kUdacityStartX;
        y = kUdacityStartY;
        yaw = 0;
      } else {
        on_line(kUdacityStartS, 6.0);
      }
      break;
    case StartPose::Kind::kXY:
      x = p.x;
      y = p.y;
      yaw = p.yaw_deg * units::kDegToRad;
      break;
    case StartPose::Kind::kFrenet:
      on_line(p.s < 0 ? world->line->length() + p.s : p.s, p.d);
      break;
  }
  if (!FiniteAsFloat(x) || !FiniteAsFloat(y) || !std::isfinite(yaw)) {
    return Status::Error(scenario.name + ": start pose is not a finite point");
  }
  return std::unique_ptr<Simulator>(new Simulator(std::move(world), scenario, seed,
                                                   static_cast<float>(x),
                                                   static_cast<float>(y), yaw));
}

Simulator::Simulator(std::shared_ptr<const World> world, const Scenario& scenario,
                     std::uint64_t seed, float x, float y, double yaw)
    : world_(std::move(world)),
      scenario_(scenario),
      seed_(seed),
      ego_(x, y, yaw),
      monitor_(scenario.incidents),
      min_gap_(kInf),
      min_headway_(kInf) {
  const map::FrenetPoint f = world_->line->ToFrenet(x, y);
  view_.s = f.s;
  view_.d = f.d;
  UpdateView();
  traffic_.emplace(world_, scenario_.traffic, scenario_.car_length, scenario_.car_width, seed,
                   view_);
  UpdateMetrics();
}

std::unique_ptr<Simulator> Simulator::Clone() const {
  return std::unique_ptr<Simulator>(new Simulator(*this));
}

void Simulator::UpdateView() {
  view_.x = ego_.x();
  view_.y = ego_.y();
  view_.yaw = ego_.yaw();
  view_.speed = ego_.speed();
  const map::FrenetPoint f = world_->line->ToFrenet(view_.x, view_.y, view_.s);
  view_.s = f.s;
  view_.d = f.d;
  const map::FrenetPoint c = world_->chord->Convert(ego_.x(), ego_.y());
  chord_s_ = NanToZero(static_cast<float>(c.s));
  chord_d_ = NanToZero(static_cast<float>(c.d));
}

void Simulator::GetTelemetry(plan::Telemetry* out) const {
  out->x = ego_.x();
  out->y = ego_.y();
  // Degrees in [0, 360) as a float, as the simulator has them, then back to radians.
  float deg = static_cast<float>(ego_.yaw() / units::kDegToRad);
  deg = std::fmod(deg, 360.0f);
  if (deg < 0) deg += 360.0f;
  if (deg >= 360.0f) deg = 0;
  out->yaw = deg * units::kDegToRad;
  out->speed = ego_.speed();
  out->s = chord_s_;
  out->d = chord_d_;
  const auto px = ego_.path_x(), py = ego_.path_y();
  out->previous_path_x.assign(px.begin(), px.end());
  out->previous_path_y.assign(py.begin(), py.end());
  if (px.empty()) {
    out->end_path_s = out->end_path_d = 0;
  } else {
    // The end_path quirk: the segment is chosen from the ego's position, s is not wrapped.
    const map::FrenetPoint e = world_->chord->Convert(px.back(), py.back(), ego_.x(), ego_.y());
    out->end_path_s = NanToZero(static_cast<float>(e.s));
    out->end_path_d = NanToZero(static_cast<float>(e.d));
  }
  traffic_->FillSensorFusion(&out->sensor_fusion);
}

plan::Telemetry Simulator::Telemetry() const {
  plan::Telemetry t;
  GetTelemetry(&t);
  return t;
}

Status Simulator::ApplyPath(std::span<const double> x, std::span<const double> y) {
  if (x.size() != y.size()) {
    return Status::Error("control path: next_x has " + std::to_string(x.size()) +
                         " points but next_y has " + std::to_string(y.size()));
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!FiniteAsFloat(x[i]) || !FiniteAsFloat(y[i])) {
      return Status::Error("control path: point " + std::to_string(i) +
                           " is not a finite float32 number");
    }
  }
  ego_.ApplyPath(x, y);
  return Status::Ok();
}

void Simulator::Advance(int ticks) {
  for (int i = 0; i < ticks; ++i) Tick();
}

void Simulator::Tick() {
  ego_.Tick();
  UpdateView();
  traffic_->Tick(view_, ticks_);
  const Box box{view_.x, view_.y, view_.yaw, scenario_.car_length, scenario_.car_width};
  TickSample sample;
  sample.x = view_.x;
  sample.y = view_.y;
  sample.speed = view_.speed;
  sample.s = chord_s_;
  sample.d = chord_d_;
  sample.collision_with = traffic_->Collides(box);
  ++ticks_;
  monitor_.Update(sample, time());
  // Rendered frames in this tick (none, one or several, at the scenario's frame rate).
  frame_phase_ += scenario_.traffic.frame_rate * kTick;
  while (frame_phase_ >= 1.0 - 1e-9) {
    frame_phase_ -= 1.0;
    traffic_->Frame(view_);
  }
  const bool changed_lane = UpdateMetrics();
  breakdown_.Update(kTick, view_, view_.d >= 0 && view_.d < 12 ? lane_ : -1, changed_lane,
                    monitor_.distance(), leader_.id >= 0 ? leader_.gap : kInf,
                    traffic_->cars(), *world_->line);
}

bool Simulator::UpdateMetrics() {
  // Ego lane with hysteresis: a lane counts once d is within 1.5 m of its centre.
  bool changed = false;
  for (int j = 0; j < 3; ++j) {
    if (std::abs(view_.d - (2.0 + 4.0 * j)) < 1.5) {
      if (lane_ >= 0 && j != lane_) {
        ++lane_changes_;
        changed = true;
      }
      lane_ = j;
    }
  }
  UpdateLeader();
  return changed;
}

void Simulator::UpdateLeader() {
  leader_ = LeaderGap();
  if (view_.d < 0 || view_.d >= 12) return;
  const int ego_lane = static_cast<int>(view_.d / 4.0);
  const map::ReferenceLine& line = *world_->line;
  double best = kInf;
  for (const TrafficCar& c : traffic_->cars()) {
    if (!c.spawned || c.d < 0 || c.d >= 12 || static_cast<int>(c.d / 4.0) != ego_lane) continue;
    const double ds = line.DiffS(c.s, view_.s);
    if (ds > 0 && ds < 200 && ds < best) {
      best = ds;
      leader_.id = c.id;
    }
  }
  if (leader_.id < 0) return;
  leader_.gap = best - scenario_.car_length;
  leader_.headway = view_.speed > 0.1 ? std::max(0.0, leader_.gap) / view_.speed : kInf;
  min_gap_ = std::min(min_gap_, leader_.gap);
  min_headway_ = std::min(min_headway_, leader_.headway);
}

}  // namespace frenetic::sim

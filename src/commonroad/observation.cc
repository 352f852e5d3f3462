#include "frenetic/commonroad/observation.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <optional>

namespace frenetic::commonroad {

Footprint FootprintOf(const Obstacle& o, const State& st) {
  double x0 = 1e18, x1 = -1e18, y0 = 1e18, y1 = -1e18;
  for (const Shape& sh : o.shape.shapes) {
    if (sh.kind == Shape::Kind::kCircle) {
      x0 = std::min(x0, sh.center.x - sh.radius);
      x1 = std::max(x1, sh.center.x + sh.radius);
      y0 = std::min(y0, sh.center.y - sh.radius);
      y1 = std::max(y1, sh.center.y + sh.radius);
      continue;
    }
    for (const Vec2& v : sh.Vertices()) {
      x0 = std::min(x0, v.x);
      x1 = std::max(x1, v.x);
      y0 = std::min(y0, v.y);
      y1 = std::max(y1, v.y);
    }
  }
  Footprint f;
  f.heading = st.orientation.value_or(0.0);
  if (!(x1 > x0) || !(y1 > y0)) {
    f.centre = st.position;
    return f;
  }
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  const double c = std::cos(f.heading), s = std::sin(f.heading);
  f.centre = {st.position.x + c * cx - s * cy, st.position.y + s * cx + c * cy};
  f.length = x1 - x0;
  f.width = y1 - y0;
  return f;
}

namespace {

// FootprintAt with the obstacle's state at `step`.
Footprint FootprintWith(const Obstacle& o, int step, const State& st) {
  if (o.role == ObstacleRole::kStatic || o.prediction != ObstaclePrediction::kSetBased ||
      step == o.initial.time_step) {
    return FootprintOf(o, st);
  }
  // StateAt's position and orientation are this box's centre and heading.
  const double heading = st.orientation.value_or(0.0);
  const std::optional<ShapeGroup> occupied = o.OccupancyAt(step);
  if (!occupied) return FootprintOf(o, st);
  const OrientedBox box = occupied->BoundingBox(heading);
  return Footprint{box.center, heading, box.length, box.width};
}

// SpeedAt with the obstacle's state at `step`.
double StatedSpeed(const Obstacle& o, int step, const State& st, double dt) {
  if (st.velocity) return *st.velocity;
  if (o.role == ObstacleRole::kStatic) return 0;
  const std::optional<State> next = o.StateAt(step + 1), prev = o.StateAt(step - 1);
  if (next) return Distance(next->position, st.position) / dt;
  if (prev) return Distance(st.position, prev->position) / dt;
  return 0;
}

// MeasureVelocity from the stated speed, the body's heading and the states at the step and
// the one before (absent: the obstacle was not there).
MeasuredVelocity Measure(double stated, double heading, const State& st,
                         const std::optional<State>& prev, double dt) {
  MeasuredVelocity out{stated, heading};
  if (!prev) return out;
  const Vec2 motion = st.position - prev->position;
  const double moved = Norm(motion);
  if (!(moved >= kStillDistance)) return out;  // standing (or not finite)
  const double measured = moved / dt;
  if (std::abs(measured - stated) > std::max(kSpeedSlack, kSpeedShare * std::abs(stated))) {
    out.speed = measured;
  }
  const double direction = std::atan2(motion.y, motion.x);
  if (measured >= kSpeedSlack && std::abs(WrapAngle(direction - heading)) > kTurnSlack) {
    // The speed's sign (a stated reversing speed) is the direction's now.
    out.heading = direction;
    out.speed = std::abs(out.speed);
  }
  return out;
}

std::optional<State> StateBefore(const Obstacle& o, int step) {
  return step > INT_MIN ? o.StateAt(step - 1) : std::nullopt;
}

// Appends the obstacle's state at step q (footprint centre, measured speed and heading) to a
// recorded future; `prev` is its state a step before (none: the speed as stated).
Footprint AppendFuture(const Obstacle& o, int q, const State& sq, const std::optional<State>& prev,
                       double dt, plan::CarFuture* fut) {
  const Footprint fq = FootprintWith(o, q, sq);
  const MeasuredVelocity vq = Measure(StatedSpeed(o, q, sq, dt), fq.heading, sq, prev, dt);
  fut->x.push_back(fq.centre.x);
  fut->y.push_back(fq.centre.y);
  fut->v.push_back(vq.speed);
  fut->heading.push_back(vq.heading);
  if (o.prediction == ObstaclePrediction::kSetBased) {
    fut->lengths.push_back(fq.length);
    fut->widths.push_back(fq.width);
  }
  return fq;
}

}  // namespace

std::optional<Footprint> FootprintAt(const Obstacle& o, int step) {
  const std::optional<State> st = o.StateAt(step);
  if (!st) return std::nullopt;
  return FootprintWith(o, step, *st);
}

double SpeedAt(const Obstacle& o, int step, double dt) {
  const std::optional<State> st = o.StateAt(step);
  return st ? StatedSpeed(o, step, *st, dt) : 0.0;
}

MeasuredVelocity MeasureVelocity(const Obstacle& o, int step, double dt) {
  const std::optional<State> st = o.StateAt(step);
  if (!st) return {};
  return Measure(StatedSpeed(o, step, *st, dt), st->orientation.value_or(0.0), *st,
                 StateBefore(o, step), dt);
}

void Observe(const Scenario& sc, int step, const map::ReferenceLine& line, double ego_s,
             PredictionMode mode, plan::Telemetry* out) {
  const double dt = sc.dt;
  out->sensor_fusion.clear();
  size_t futures = 0;  // out->futures in use; the rest are reused or dropped at the end
  for (const Obstacle& o : sc.obstacles) {
    const std::optional<State> st = o.StateAt(step);
    if (!st) continue;
    const std::optional<State> before = StateBefore(o, step);
    const Footprint fp = FootprintWith(o, step, *st);
    const MeasuredVelocity mv = Measure(StatedSpeed(o, step, *st, dt), fp.heading, *st, before, dt);
    plan::SensorCar row;
    row.id = o.id;
    row.x = fp.centre.x;
    row.y = fp.centre.y;
    row.vx = mv.speed * std::cos(mv.heading);
    row.vy = mv.speed * std::sin(mv.heading);
    const map::FrenetPoint fo = line.ToFrenet(row.x, row.y, ego_s);
    row.s = fo.s;
    row.d = fo.d;
    row.length = fp.length;
    row.width = fp.width;
    out->sensor_fusion.push_back(row);
    if (mode != PredictionMode::kRecorded) continue;
    if (futures == out->futures.size()) out->futures.emplace_back();
    plan::CarFuture& fut = out->futures[futures++];
    fut.id = o.id;
    fut.dt = dt;
    fut.start = 0;
    fut.length = fut.width = 0;
    fut.x.clear();
    fut.y.clear();
    fut.v.clear();
    fut.heading.clear();
    fut.lengths.clear();
    fut.widths.clear();
    std::optional<State> prev = before;
    for (int q = step; q <= std::min(step + kFutureSteps, o.LastStep()); ++q) {
      const std::optional<State> sq = q == step ? st : o.StateAt(q);
      if (!sq) break;
      AppendFuture(o, q, *sq, prev, dt, &fut);
      prev = sq;
    }
  }
  // Recorded: the obstacles to come (not there yet, there within kComingSteps), from their
  // first step on.
  for (const Obstacle& o : sc.obstacles) {
    if (mode != PredictionMode::kRecorded) break;
    const int first = o.initial.time_step;
    if (o.role != ObstacleRole::kDynamic || first <= step || first > step + kComingSteps) continue;
    if (futures == out->futures.size()) out->futures.emplace_back();
    plan::CarFuture& fut = out->futures[futures++];
    fut.id = o.id;
    fut.dt = dt;
    fut.start = (first - step) * dt;
    fut.x.clear();
    fut.y.clear();
    fut.v.clear();
    fut.heading.clear();
    fut.lengths.clear();
    fut.widths.clear();
    std::optional<State> prev;
    for (int q = first; q <= std::min(step + kFutureSteps, o.LastStep()); ++q) {
      const std::optional<State> sq = o.StateAt(q);
      if (!sq) break;
      const Footprint fq = AppendFuture(o, q, *sq, prev, dt, &fut);
      if (q == first) {
        fut.length = fq.length;
        fut.width = fq.width;
      }
      prev = sq;
    }
    if (fut.x.empty()) --futures;
  }
  out->futures.resize(futures);
}

}  // namespace frenetic::commonroad

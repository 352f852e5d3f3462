#include "frenetic/commonroad/rescue.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <spdlog/spdlog.h>

#include "frenetic/commonroad/geometry.h"
#include "frenetic/commonroad/path_time.h"
#include "frenetic/commonroad/reach_grid.h"
#include "frenetic/plan/planner.h"

namespace frenetic::commonroad {
namespace {

// Grid cells: position, speed, heading, steering angle; the strata of the spread (position,
// speed, speed across the search's start heading; the 1e3 cell leaves of the steering only its
// sign). See Rescue::Stratum.
constexpr double kCells[5] = {0.25, 0.25, 0.25, 0.01, 0.005};
constexpr double kStrata[5] = {2.0, 2.0, 1.0, 0.5, 1e3};
// m: how far from a lane's begin or end (along the road) its lanelet's end edge may lie slanted
// across the road: a box within it is also checked against the lanelets' outline (OnRoad).
constexpr double kEndReach = 5.0;
// The runner insets goal windows from the verdict's whole steps by up to half a step at each end
// (a window of one step becomes an instant between two): a step within this many steps of a
// window's inset ends is one of its whole steps, and one outside the window is a step or more
// away.
constexpr double kWindowSlack = 0.75;

// When region g's window has closed, s from now, its slack added.
double WindowClose(const cost::GoalRegion& g, double dt) { return g.t_hi + kWindowSlack * dt; }

// The step by which a window closing t_close s from now has closed, when that is before step
// `steps`; -1 when it stays open to then. Compared before the conversion: a window without an
// end (+inf) or NaN gives -1.
int StepClosed(double t_close, int steps, double dt) {
  if (!(t_close < steps * dt)) return -1;
  return static_cast<int>(std::ceil(t_close / dt - 1e-9));
}

// A future's centre and heading at t s from its telemetry's instant, and the sample they come
// from (*sample); false when the car is not there yet. Past its last sample it keeps its last
// speed and heading.
bool FutureAt(const plan::CarFuture& f, double t, double* x, double* y, double* heading,
              int* sample) {
  const int n = static_cast<int>(std::min({f.x.size(), f.y.size(), f.v.size(), f.heading.size()}));
  if (n == 0 || t < f.start - 1e-9) return false;
  const double at = (t - f.start) / f.dt;
  const int i = std::min(static_cast<int>(std::lround(at)), n - 1);
  *sample = i;
  const double beyond = std::max(0.0, at - (n - 1)) * f.dt;
  *heading = f.heading[i];
  if (beyond > 0) {
    *x = f.x[i] + beyond * f.v[i] * std::cos(f.heading[i]);
    *y = f.y[i] + beyond * f.v[i] * std::sin(f.heading[i]);
  } else {  // the same values without the trigonometry (0 times a finite product)
    *x = std::isfinite(f.v[i]) ? f.x[i] : NAN;
    *y = f.y[i];
  }
  return std::isfinite(*x) && std::isfinite(*y) && std::isfinite(*heading);
}

// How far (m) (s, d) lies from goal region g's box (its d span turned by d_slope): 0 inside.
double RegionGap(const cost::GoalRegion& g, double s, double d) {
  const double d_off = g.d_slope * (s - g.s_ref);
  const double ds = std::max({g.s_lo - s, s - g.s_hi, 0.0});
  const double dd = std::max({g.d_lo + d_off - d, d - g.d_hi - d_off, 0.0});
  return std::hypot(ds, dd);
}

// The point of a path (points every plan::kTickSeconds, the first one tick on, or `phase` s
// later) at t s, linear between points (path_time.h), its heading (from the points either
// side) and speed; false when the path ends before it.
struct PathPoint {
  double x, y, heading, speed;
};
bool PathPointAt(const std::vector<double>& x, const std::vector<double>& y, double t, double phase,
                 PathPoint* p) {
  const int n = static_cast<int>(std::min(x.size(), y.size()));
  const PathIndex in = PathIndexAt(t - phase);
  const int j = in.lo, between = in.frac > 0 ? 1 : 0;
  if (j + 1 + between >= n) return false;
  const int a = std::max(0, j - 1), b = j + 1 + between;
  const double dx = x[b] - x[a], dy = y[b] - y[a];
  *p = {PathValueAt(x, in), PathValueAt(y, in), std::atan2(dy, dx),
        std::hypot(dx, dy) / ((b - a) * plan::kTickSeconds)};
  return true;
}

}  // namespace

double Rescue::GoalGap(const Node& n, const std::vector<cost::GoalRegion>& goals) const {
  // Regions whose window is still open at the way's end (all: none is).
  const double t_end = static_cast<double>(steps_) * dt_;
  double best = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2 && !std::isfinite(best); ++pass) {
    for (const cost::GoalRegion& g : goals) {
      if (pass == 0 && g.t_hi < t_end) continue;
      best = std::min(best, RegionGap(g, n.s, n.d));
    }
  }
  return std::isfinite(best) ? best : 0.0;
}

Rescue::Rescue(const map::Road& road, const VehicleParams& vehicle, double dt,
               const RescueOptions& options)
    : road_(road), vehicle_(vehicle), dt_(dt), options_(options) {
  const double step = dt > 0 ? dt : 0.1;
  const auto steps_in = [step](double seconds) {  // at least one, at most 2000
    return std::isfinite(seconds)
               ? static_cast<int>(std::lround(std::clamp(seconds / step, 1.0, 2000.0)))
               : 1;
  };
  // A search layer's scenario steps: about 0.1 s (1 at 0.1 s and above, 3 at 0.04 s).
  sub_ = std::max(1, static_cast<int>(std::lround(std::min(0.1 / step, 100.0))));
  steps_ = steps_in(options_.horizon);
  goal_steps_ = std::clamp(steps_in(options_.goal_horizon), steps_, 10 * steps_);
  options_.max_states = std::max(options_.max_states, 1);
  options_.retry_states = std::max(options_.retry_states, 0);
  cars_.resize(goal_steps_);
  layers_.resize(goal_steps_ + 1);
  half_length_ = 0.5 * vehicle_.length + options_.ego_margin;
  half_width_ = 0.5 * vehicle_.width + options_.ego_margin;
  ego_radius_ = std::hypot(half_length_, half_width_);
}

RescueStep Rescue::Check(const plan::Telemetry& t, const std::vector<double>& x,
                         const std::vector<double>& y, const KsState& ego, bool plan_misses) {
  RescueStep r;
  const PathCheck path = Walk(x, y, t.goals);
  r.hit = path.hit;
  if (r.hit > 0) {
    r.why = RescueStep::Why::kHit;
    r.input = Next(ego, t.goals);
  } else if (const Risk risk = AtRisk(path, t.goals, plan_misses); risk != Risk::kNone) {
    r.why = RescueStep::Why::kGoal;
    // At risk only as the planner's plan is (the window closes past the path): after a search
    // that found no way the next waits a cycle, after two or more in a row two cycles (cycles
    // of 0.1 s: as many steps as a search layer holds at a shorter step).
    const bool far = risk == Risk::kFar;
    if (far && !goal_way_ && far_wait_ > 0) {
      --far_wait_;
      Drop();
      return r;
    }
    r.input = Next(ego, t.goals, true, far);
    if (!r.input) {
      Drop();
      if (far) far_wait_ = std::min(++far_fails_, 2) * sub_;
    } else {
      far_fails_ = far_wait_ = 0;
    }
  } else {
    Drop();
    far_fails_ = far_wait_ = 0;
  }
  return r;
}

void Rescue::Predict(const plan::Telemetry& t) {
  // What each car's boxes come from; the boxes themselves are laid out step by step as the
  // checks reach them (CarsAt): a path's check mostly needs the first 2 s only.
  sources_.clear();
  ready_ = 0;
  held_ = false;
  const auto add = [this](Source::Kind kind, double length, double width) -> Source& {
    Source& src = sources_.emplace_back();
    src.kind = kind;
    src.half_length = 0.5 * length;
    src.half_width = 0.5 * width;
    src.radius = 0.5 * std::hypot(length, width);
    return src;
  };
  for (const plan::SensorCar& car : t.sensor_fusion) {
    const double length = car.length > 0 ? car.length : options_.car_length;
    const double width = car.width > 0 ? car.width : options_.car_width;
    const plan::CarFuture* future = nullptr;
    for (const plan::CarFuture& f : t.futures) {
      if (f.id == car.id && f.start <= 0) future = &f;
    }
    if (future != nullptr) {
      add(Source::kFuture, length, width).future = future;
      continue;
    }
    // Its place on the road: a car without a future moves on along it (the planner's own
    // prediction keeps a car in its lane too; a straight line would run a car on a curving ramp
    // into the next lane), and one standing lies along it.
    const map::ReferenceLine& line = road_.line();
    const map::FrenetPoint fe = line.ToFrenet(car.x, car.y, t.s);
    const double road_heading = line.At(fe.s).heading;
    if (std::hypot(car.vx, car.vy) <= 0.1) {
      // Standing: its heading is unknown (no motion), so its box lies along the road there, at
      // its own length and width, as the planner's prediction has it. (Was a square of its
      // longer side: a bus stopped in one lane then reached into the next, and the planner's
      // paths past it were taken for hits; docs/commonroad.md.)
      Source& src = add(Source::kStill, length, width);
      src.x = car.x;
      src.y = car.y;
      src.rel = road_heading;
      continue;
    }
    // On along the road at its speed along the road, at its offset from the line.
    Source& src = add(Source::kAlong, length, width);
    src.x = fe.s;
    src.y = fe.d;
    src.along = car.vx * std::cos(road_heading) + car.vy * std::sin(road_heading);
    src.rel = std::atan2(car.vy, car.vx) - road_heading;
    // Across the road (d grows to the right): a lane change, as the planner's predictor has it.
    const double across = car.vx * std::sin(road_heading) - car.vy * std::cos(road_heading);
    if (options_.lateral_threshold > 0 && std::abs(across) > options_.lateral_threshold) {
      const double centre = road_.CentreToward(fe.s, fe.d, across);
      if (!std::isnan(centre)) {
        src.across = across;
        src.d_target = centre;
      }
    }
  }
  for (const plan::CarFuture& f : t.futures) {
    if (f.start <= 0) continue;  // a present car's, above
    const double length = f.length > 0 ? f.length : options_.car_length;
    const double width = f.width > 0 ? f.width : options_.car_width;
    add(Source::kFuture, length, width).future = &f;
  }
}

const std::vector<Rescue::Car>& Rescue::CarsAt(int k) const {
  for (; ready_ < k; ++ready_) {
    const int step = ready_ + 1;
    std::vector<Car>& cars = cars_[ready_];
    cars.clear();
    for (const Source& src : sources_) {
      double x = src.x, y = src.y, heading = 0.0;
      double half_length = src.half_length, half_width = src.half_width, radius = src.radius;
      if (src.kind == Source::kFuture) {
        const plan::CarFuture& f = *src.future;
        int i = 0;
        if (!FutureAt(f, step * dt_, &x, &y, &heading, &i)) continue;
        if (i < static_cast<int>(std::min(f.lengths.size(), f.widths.size())) &&
            f.lengths[i] > 0 && f.widths[i] > 0) {  // a footprint of its own at this sample
          half_length = 0.5 * f.lengths[i];
          half_width = 0.5 * f.widths[i];
          radius = std::hypot(half_length, half_width);
        }
      } else if (src.kind == Source::kStill) {
        heading = src.rel;
      } else if (src.kind == Source::kAlong) {
        double d = src.y, rel = src.rel;
        if (src.across != 0) {
          d += src.across * step * dt_;
          if ((d - src.d_target) * src.across >= 0) {  // in the lane's centre: straight on
            d = src.d_target;
            rel = 0;
          }
        }
        const map::CartesianPose at = road_.line().ToCartesian(src.x + src.along * step * dt_, d);
        x = at.x;
        y = at.y;
        heading = at.heading + rel;
      }
      Car& c = cars.emplace_back();
      c.box = {x, y, heading, half_length, half_width};
      c.cos_h = std::cos(heading);
      c.sin_h = std::sin(heading);
      c.radius = radius;
    }
  }
  return cars_[k - 1];
}

bool Rescue::Clear(const KsState& s, int k, double s_hint, map::FrenetPoint* at) const {
  ++checked_;
  if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.orientation)) return false;
  // The cars first (cheaper, and in a box-in most states fail there), then the road: the box's
  // extent along the line and across it between the edges at both ends.
  return ClearOfCars(s, k) && OnRoad(s, s_hint, at);
}

void Rescue::SetRoadArea(const RoadArea* area) {
  area_ = area;
  area_stretches_.clear();
  if (area_ == nullptr) return;
  // The stretches along the line where the box is checked against the area: every lane's begin
  // and end (a point), and wherever a boundary segment of the area lies more than kInside inside
  // the edges, where the edges alone do not tell the area's inside.
  std::vector<std::pair<double, double>> spans;
  for (int l = 0; l < road_.num_lanes(); ++l) {
    for (const double end : {road_.LaneBegin(l), road_.LaneEnd(l)}) {
      if (std::isfinite(end)) spans.emplace_back(end, end);
    }
  }
  constexpr double kInside = 0.05;  // m
  const map::ReferenceLine& line = road_.line();
  for (const std::vector<Vec2>& ring : area_->BoundaryRings()) {
    double s_prev = std::numeric_limits<double>::quiet_NaN();
    bool inside_prev = false;
    for (const Vec2& p : ring) {
      const map::FrenetPoint fe = line.ToFrenet(p.x, p.y, s_prev);
      if (!std::isfinite(fe.s) || !std::isfinite(fe.d)) {
        s_prev = std::numeric_limits<double>::quiet_NaN();
        inside_prev = false;
        continue;
      }
      const map::Road::Span e = road_.EdgesAt(fe.s);
      const bool inside = e.exists && fe.d > e.left + kInside && fe.d < e.right - kInside;
      if (inside || inside_prev) {  // the segment from the last point, or this point
        spans.emplace_back(std::isfinite(s_prev) ? std::min(s_prev, fe.s) : fe.s,
                           std::isfinite(s_prev) ? std::max(s_prev, fe.s) : fe.s);
      }
      s_prev = fe.s;
      inside_prev = inside;
    }
  }
  // Merged (a gap under 1 m changes no answer: OnRoad asks about at least 10 m).
  std::sort(spans.begin(), spans.end());
  for (const auto& [lo, hi] : spans) {
    if (!area_stretches_.empty() && lo <= area_stretches_.back().second + 1.0) {
      area_stretches_.back().second = std::max(area_stretches_.back().second, hi);
    } else {
      area_stretches_.emplace_back(lo, hi);
    }
  }
  double length = 0;
  for (const auto& [lo, hi] : area_stretches_) length += hi - lo;
  spdlog::debug("rescue: the box is checked against the road area over {} stretches, {:.1f} m",
                area_stretches_.size(), length);
}

bool Rescue::OnRoad(const KsState& s, double s_hint, map::FrenetPoint* at) const {
  const double hl = half_length_, hw = half_width_;
  const map::ReferenceLine& line = road_.line();
  const map::FrenetPoint fe = line.ToFrenet(s.x, s.y, s_hint);
  *at = fe;
  const double rel = s.orientation - line.At(fe.s).heading;
  const double c = std::abs(std::cos(rel)), sn = std::abs(std::sin(rel));
  const double along = hl * c + hw * sn, across = hl * sn + hw * c;
  for (const double at : {fe.s - along, fe.s + along}) {
    const map::Road::Span e = road_.EdgesAt(at);
    if (!e.exists || fe.d - across < e.left || fe.d + across > e.right) return false;
  }
  // Between the borders: off the lanelets only where a lane's end edge may lie slanted under the
  // box or the outline runs inside the borders (area_stretches_, within kEndReach), and there
  // only if the outline's boundary crosses it (inside the borders, the box is not wholly outside
  // the lanelets).
  const double lo = fe.s - along - kEndReach, hi = fe.s + along + kEndReach;
  const auto stretch = std::lower_bound(area_stretches_.begin(), area_stretches_.end(), lo,
                                        [](const auto& c, double v) { return c.second < v; });
  if (stretch != area_stretches_.end() && stretch->first <= hi) {
    const auto corners = BoxCorners({s.x, s.y}, s.orientation, 2 * hl, 2 * hw);
    return !area_->BoundaryTouches(corners);
  }
  return true;
}

bool Rescue::ClearOfCars(const KsState& s, int k) const {
  const traj::OrientedBox ego{s.x, s.y, s.orientation, half_length_, half_width_};
  const double cos_e = std::cos(s.orientation), sin_e = std::sin(s.orientation);
  for (const Car& car : CarsAt(k)) {
    const double reach = ego_radius_ + car.radius;
    const double dx = car.box.cx - s.x, dy = car.box.cy - s.y;
    if (dx * dx + dy * dy > reach * reach) continue;
    if (traj::Overlap(ego, cos_e, sin_e, car.box, car.cos_h, car.sin_h)) return false;
  }
  return true;
}

Rescue::PathCheck Rescue::Walk(const std::vector<double>& x, const std::vector<double>& y,
                               const std::vector<cost::GoalRegion>& goals) const {
  PathCheck c;
  PathPoint p;
  double s_hint = std::numeric_limits<double>::quiet_NaN();
  map::FrenetPoint at{};
  for (int k = 1; k <= steps_ && PathPointAt(x, y, k * dt_, path_phase_, &p); ++k) {
    KsState st;
    st.x = p.x;
    st.y = p.y;
    st.orientation = p.heading;
    if (!std::isfinite(st.x) || !std::isfinite(st.y) || !std::isfinite(st.orientation) ||
        !ClearOfCars(st, k)) {
      c.hit = k;
      return c;
    }
    if (c.met) continue;  // the run ends there: the road past it is not judged
    if (!OnRoad(st, s_hint, &at)) {
      c.hit = k;
      return c;
    }
    s_hint = at.s;
    c.judged = c.judged && std::isfinite(p.speed);
    c.met = GoalDistance(at.s, at.d, p.speed, p.heading, k * dt_, goals) == 0;
    c.t_end = k * dt_;
    c.s_end = at.s;
    c.d_end = at.d;
  }
  return c;
}

int Rescue::PathHit(const std::vector<double>& x, const std::vector<double>& y,
                    const std::vector<cost::GoalRegion>& goals) const {
  return Walk(x, y, goals).hit;
}

bool Rescue::Holds(const KsState& ego, const std::vector<cost::GoalRegion>& goals) {
  const int rest = static_cast<int>(way_.size()) - 1;  // after the step driven since
  held_ = goal_way_ && rest >= 1 && Lasts(ego, &goals, 1) == rest;
  return held_;
}

RescueStep Rescue::Continue() {
  RescueStep r;
  if (!held_) {
    Drop();
    return r;
  }
  held_ = false;
  r.why = RescueStep::Why::kNoPath;
  way_.erase(way_.begin());  // the step driven since
  r.input = way_.front();
  return r;
}

RescueStep Rescue::Answer(const plan::Telemetry& t, const std::vector<double>& x,
                          const std::vector<double>& y, const KsState& ego, bool none_passed,
                          bool plan_misses) {
  return held_ && none_passed ? Continue() : Check(t, x, y, ego, plan_misses);
}

int Rescue::Lasts(const KsState& ego, const std::vector<cost::GoalRegion>* goals, int from) {
  KsState s = ego;
  double s_hint = std::numeric_limits<double>::quiet_NaN();
  const int n = std::min(static_cast<int>(way_.size()) - from, goal_steps_);
  map::FrenetPoint at{};
  for (int k = 1; k <= n; ++k) {
    s = SimulateKs(s, way_[from + k - 1], dt_, vehicle_, 1);
    if (!Clear(s, k, s_hint, &at)) return k - 1;
    s_hint = at.s;
  }
  if (goals != nullptr && (n == 0 || GoalDistance(at.s, at.d, s.velocity, s.orientation,
                                                  n * dt_, *goals) != 0)) {
    return -1;
  }
  return n;
}

std::optional<KsInput> Rescue::Next(const KsState& ego,
                                    const std::vector<cost::GoalRegion>& goals, bool goal_only,
                                    bool far) {
  held_ = false;
  if (!way_.empty()) way_.erase(way_.begin());  // the step driven since
  const int rest = static_cast<int>(way_.size());
  // A way to a goal is kept while it still meets it; another while it lasts long enough.
  const bool keep = goal_way_ ? Lasts(ego, &goals) == rest
                              : !goal_only && rest >= (steps_ + 1) / 2 && Lasts(ego) == rest;
  if (!keep) {
    // A way to a goal whose every window closes within the horizon first, also when the path
    // hits a car (a way that only lasts may leave the goal out of reach): a search that ends at
    // the windows' close, with as many states in all as one over the whole horizon. A goal the
    // path misses may close past the horizon, within goal_steps: the search runs to its close.
    Drop();
    const map::FrenetPoint fe0 = road_.line().ToFrenet(ego.x, ego.y);  // once for every search
    const int goal_steps = far ? FarGoalSteps(goals, fe0.s) : GoalSteps(goals, steps_);
    const auto search = [&](bool to_goal) {
      const int horizon = to_goal && goal_steps > steps_ ? goal_steps : steps_;
      const int scale = to_goal && goal_steps > 0 ? std::max(1, steps_ / goal_steps) : 1;
      // Past the horizon, fewer a step: as many in all as over the horizon.
      const auto states = [&](int n) {
        return horizon > steps_ ? std::max(1, n * steps_ / horizon) : n * scale;
      };
      Search(ego, fe0, goals, states(options_.max_states), horizon, to_goal);
      // None at the usual size: once more with more states a step (a narrow way through).
      if (way_.empty() && options_.retry_states > options_.max_states) {
        Search(ego, fe0, goals, states(options_.retry_states), horizon, to_goal);
      }
    };
    if (goal_only || goal_steps > 0) search(true);
    if (way_.empty() && !goal_only) search(false);
  }
  if (way_.empty()) return std::nullopt;
  return way_.front();
}

int Rescue::GoalSteps(const std::vector<cost::GoalRegion>& goals, int horizon) const {
  if (goals.empty()) return 0;
  double last = 0;
  for (const cost::GoalRegion& g : goals) last = std::max(last, WindowClose(g, dt_));
  const int steps = StepClosed(last, horizon, dt_);
  return steps >= 1 && steps < horizon ? steps : 0;
}

int Rescue::ClosingStep(const cost::GoalRegion& g) const {
  const int steps = StepClosed(WindowClose(g, dt_), goal_steps_, dt_);
  return steps < 0 ? 0 : std::max(1, steps);
}

int Rescue::FarGoalSteps(const std::vector<cost::GoalRegion>& goals, double s) const {
  int steps = 0;
  for (const cost::GoalRegion& g : goals) {
    if (s > g.s_hi) continue;  // passed: no way meets it, whenever it closes
    const int k = ClosingStep(g);
    if (k == 0) return 0;
    steps = std::max(steps, k);
  }
  return std::min(steps, goal_steps_);
}

double Rescue::GoalDistance(double s, double d, double v, double orientation, double t,
                            const std::vector<cost::GoalRegion>& goals) const {
  double best = std::numeric_limits<double>::infinity();
  const double slack = kWindowSlack * dt_;
  for (const cost::GoalRegion& g : goals) {
    if (t < g.t_lo - slack || t > g.t_hi + slack) continue;
    double dist = RegionGap(g, s, d);
    if (dist == 0) {
      // Against the road's heading where the region's interval was read from it (its s mid,
      // AddHeading in goal_frenet.cc): the same absolute orientations as the verdict's.
      const double at_s = std::isfinite(g.s_lo) && std::isfinite(g.s_hi) ? 0.5 * (g.s_lo + g.s_hi) : s;
      const double tangent = std::tan(orientation - road_.line().At(at_s).heading);
      const bool fits = v >= g.v_lo && v <= g.v_hi && -tangent >= g.h_lo && -tangent <= g.h_hi;
      if (!fits) dist = 1e-3;  // there, not yet as the region asks
    }
    best = std::min(best, dist);
  }
  return best;
}

bool Rescue::MayMeetGoal(double s, double d, const KsState& state, double t,
                         const std::vector<cost::GoalRegion>& goals, int steps) const {
  const double horizon = steps * dt_;
  const double v = state.velocity, a = vehicle_.a_max;
  // The farthest along the road within `time` s, at full acceleration.
  const auto reach = [v, a](double time) { return v * time + 0.5 * a * time * time; };
  for (const cost::GoalRegion& g : goals) {
    const double t_last = std::min(WindowClose(g, dt_), horizon);
    if (t > t_last || s > g.s_hi) continue;  // closed, or passed (the way never backs up)
    double time = t_last - t;
    if (s + reach(time) < g.s_lo) continue;
    // Past the region's end the way cannot meet it: the latest it gets there is braking at the
    // vehicle's limit from now (never, when it stops short).
    const double ahead = g.s_hi - s;
    if (v * v > 2 * a * ahead) time = std::min(time, (v - std::sqrt(v * v - 2 * a * ahead)) / a);
    // Across: the band's nearest edge at s (its slope over the reach added as slack) within
    // the most the vehicle can move toward it in the time left.
    const double slack = std::abs(g.d_slope) * reach(time);
    const double d_off = g.d_slope * (s - g.s_ref);
    const double below = g.d_lo + d_off - slack - d, above = d - (g.d_hi + d_off + slack);
    if (below <= 0 && above <= 0) return true;
    const double gap = std::max(below, above);
    if (gap <= LateralReach(s, state, below > 0 ? 1 : -1, time)) return true;
  }
  return false;
}

double Rescue::LateralReach(double s, const KsState& state, int toward, double time) const {
  // An upper bound of the KS model's displacement across the road toward +d (toward 1) or -d
  // (-1) in `time` s, of its centre: the rear axle's (the KS model's point, which moves along
  // the heading) and the centre's turn about it. The steering turned toward it at the largest
  // rate from the present angle (the curvature tan(delta) / l growing at most at rate / (l cos^2
  // of the largest angle reachable), up to the steering limit and the friction circle at the
  // lowest speed reachable), the heading's rate at the speed that makes it largest, the road's
  // own curvature over the reach added against the vehicle, the displacement at the highest
  // speed reachable (the lowest while heading away). Small steps, each taken at its largest rate.
  const VehicleParams& p = vehicle_;
  const double l = p.Wheelbase();
  const double a = p.a_max;
  const double v = std::max(0.0, state.velocity);
  const double v_hi = v + a * time, v_lo = std::max(0.0, v - a * time);
  const double steer_max = std::max(std::abs(p.steering_min), std::abs(p.steering_max));
  const double rate = std::max(std::abs(p.steering_rate_min), std::abs(p.steering_rate_max));
  const double delta_reach = std::min(steer_max, std::abs(state.steering_angle) + rate * time);
  const double cos_reach = std::cos(delta_reach);
  const double kappa_rate = rate / (l * cos_reach * cos_reach);
  double kappa_cap = std::tan(steer_max) / l;
  if (v_lo > 0) kappa_cap = std::min(kappa_cap, a / (v_lo * v_lo));
  const map::ReferenceLine& line = road_.line();
  double road_kappa = 0;
  for (const double f : {0.0, 0.5, 1.0}) {
    road_kappa = std::max(road_kappa, std::abs(line.At(s + f * v_hi * time).kappa));
  }
  // d grows as the heading turns clockwise from the road's: the heading toward the band is
  // -toward * (orientation - road heading), its curvature -toward * kappa.
  double phi = -toward * WrapAngle(state.orientation - line.At(s).heading);
  if (std::abs(phi) > 0.5 * std::numbers::pi) return std::numeric_limits<double>::infinity();
  const double phi0 = phi;
  double kappa = std::min(kappa_cap, -toward * std::tan(state.steering_angle) / l);
  constexpr int kSteps = 16;
  const double h = time / kSteps;
  double reach = 0;
  for (int i = 0; i < kSteps; ++i) {
    const double k_end = std::min(kappa_cap, kappa + kappa_rate * h);
    const double turn = (k_end >= 0 ? v_hi * k_end : v_lo * k_end) + v_hi * road_kappa;
    const double phi_end = std::min(0.5 * std::numbers::pi, phi + h * turn);
    const double sin_hi = std::sin(std::max(phi, phi_end));
    reach += h * (sin_hi >= 0 ? v_hi * sin_hi : v_lo * sin_hi);
    phi = phi_end;
    kappa = k_end;
  }
  // The rear axle's move; the centre, b ahead of it, turns with the heading.
  return reach + p.b * (std::sin(phi) - std::sin(phi0));
}

bool Rescue::GoalAtRisk(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<cost::GoalRegion>& goals, bool plan_misses) const {
  return AtRisk(Walk(x, y, goals), goals, plan_misses) != Risk::kNone;
}

Rescue::Risk Rescue::AtRisk(const PathCheck& path, const std::vector<cost::GoalRegion>& goals,
                            bool plan_misses) const {
  if (goals.empty() || path.hit > 0 || !path.judged || path.met) return Risk::kNone;
  Risk risk = Risk::kNear;
  for (const cost::GoalRegion& g : goals) {
    if (g.t_hi <= path.t_end || path.s_end > g.s_hi) continue;  // closed within it, or passed
    // Closing within a goal search's horizon while the path ends short of the region or beside
    // it: whether the rest of the way still gets there is the search's to tell.
    if (plan_misses && path.t_end > 0 && ClosingStep(g) > 0 &&
        RegionGap(g, path.s_end, path.d_end) > 0) {
      risk = Risk::kFar;
      continue;
    }
    return Risk::kNone;  // still ahead, and open, or reached where the path ends
  }
  return risk;
}

void Rescue::Search(const KsState& ego, const map::FrenetPoint& fe0,
                    const std::vector<cost::GoalRegion>& goals, int max_states, int steps,
                    bool goal_only) {
  way_.clear();
  goal_way_ = false;
  if (goal_only && !MayMeetGoal(fe0.s, fe0.d, ego, 0.0, goals, steps)) return;  // out of reach
  ++searches_;
  const VehicleParams& p = vehicle_;
  const double share = options_.limit_share;
  const double wheelbase = p.Wheelbase();
  const double a_max = share * p.a_max;
  const double steer_max = share * std::min(std::abs(p.steering_min), std::abs(p.steering_max));
  const double rate = share * std::min(std::abs(p.steering_rate_min), std::abs(p.steering_rate_max));
  const double rates[5] = {-rate, -0.5 * rate, 0.0, 0.5 * rate, rate};
  // A layer of the search holds its input for sub_ scenario steps (the last one for what is
  // left of `steps`): about 0.1 s whatever the file's step size. A goal is looked for at every
  // step, within a layer too (a window of one step may lie between two layers' ends).
  const int layers = (steps + sub_ - 1) / sub_;
  // tan of each rate's change of the steering angle to a quarter layer, mid-layer and its end.
  double tan_rq[5] = {}, tan_rm[5] = {}, tan_r1[5] = {};
  double h = 0;
  for (std::vector<Node>& layer : layers_) layer.clear();
  KsState start = ego;
  start.time_step = 0;
  layers_[0].push_back({start, fe0.s, fe0.d, -1, {}, 0.0});
  // Stratum's speed across the start heading, from each child's sine and cosine of its heading.
  const double cos_h0 = std::cos(ego.orientation), sin_h0 = std::sin(ego.orientation);
  int depth = 0, met = -1, met_steps = 0;  // met_steps: the scenario steps of the way that met
  for (int k = 1; k <= layers; ++k) {
    const int k_end = std::min(k * sub_, steps);  // the layer's last scenario step
    const int n_sub = k_end - (k - 1) * sub_;
    if (n_sub * dt_ != h) {
      h = n_sub * dt_;
      for (int j = 0; j < 5; ++j) {
        tan_rq[j] = std::tan(rates[j] * 0.25 * h);
        tan_rm[j] = std::tan(rates[j] * 0.5 * h);
        tan_r1[j] = std::tan(rates[j] * h);
      }
    }
    next_.clear();
    seen_.Clear();
    const std::vector<Node>& now = layers_[k - 1];
    for (int i = 0; i < static_cast<int>(now.size()); ++i) {
      const KsState& s = now[i].state;
      const double up = share * p.MaxAcceleration(s.velocity);
      const double floor = -s.velocity / h;  // never backwards
      const double accels[5] = {-a_max, -0.5 * a_max, 0.0, 0.5 * up, up};
      // The KS model over the step with the input held (the steering angle and the speed
      // linear in time): the yaw rate v tan(delta) / l by Simpson's rule, to mid-step and to
      // the end, and the rear axle's motion by Simpson's rule on those headings; within
      // micrometres of SimulateKs (RK4) over a step. A parent's state costs one sine, cosine
      // and tangent; its children none (the sum of angles, reach::SmallSinCos for the turn).
      const double c0 = std::cos(s.orientation), s0 = std::sin(s.orientation);
      const double rx = s.x - p.b * c0, ry = s.y - p.b * s0;
      const double tan0 = std::tan(s.steering_angle);
      double tan_q[5], tan_m[5], tan_1[5];
      for (int j = 0; j < 5; ++j) {  // tan(delta + b) from tan delta and the rate's tan b
        tan_q[j] = (tan0 + tan_rq[j]) / (1 - tan0 * tan_rq[j]);
        tan_m[j] = (tan0 + tan_rm[j]) / (1 - tan0 * tan_rm[j]);
        tan_1[j] = (tan0 + tan_r1[j]) / (1 - tan0 * tan_r1[j]);
      }
      const double lateral0 = s.velocity * s.velocity * tan0 / wheelbase;
      const double w0 = s.velocity * tan0 / wheelbase;  // the yaw rate at the step's start
      for (const double a0 : accels) {
        const double a = std::max(a0, floor);
        const double v1 = std::max(0.0, s.velocity + a * h);
        if (a * a + lateral0 * lateral0 > a_max * a_max) continue;
        const double vq = s.velocity + a * 0.25 * h, vm = s.velocity + a * 0.5 * h;
        for (int j = 0; j < 5; ++j) {
          const double r = rates[j];
          const double delta1 = s.steering_angle + r * h;
          if (std::abs(delta1) > steer_max) continue;
          const double lateral1 = v1 * v1 * tan_1[j] / wheelbase;
          if (a * a + lateral1 * lateral1 > a_max * a_max) continue;
          const double wq = vq * tan_q[j] / wheelbase;
          const double wm = vm * tan_m[j] / wheelbase, w1 = v1 * tan_1[j] / wheelbase;
          // The turns to mid-step and to the step's end, and their headings' sines and
          // cosines by the sum of angles from the parent's.
          const double turn_m = h / 12 * (w0 + 4 * wq + wm), turn_1 = h / 6 * (w0 + 4 * wm + w1);
          const double psi_1 = s.orientation + turn_1;
          double sin_tm, cos_tm, sin_t1, cos_t1;
          reach::SmallSinCos(turn_m, &sin_tm, &cos_tm);
          reach::SmallSinCos(turn_1, &sin_t1, &cos_t1);
          const double cm = c0 * cos_tm - s0 * sin_tm, sm = s0 * cos_tm + c0 * sin_tm;
          const double c1 = c0 * cos_t1 - s0 * sin_t1, s1 = s0 * cos_t1 + c0 * sin_t1;
          KsState q;
          q.time_step = k_end;
          q.orientation = psi_1;
          q.steering_angle = delta1;
          q.velocity = v1;
          q.x = rx + h / 6 * (s.velocity * c0 + 4 * vm * cm + v1 * c1) + p.b * c1;
          q.y = ry + h / 6 * (s.velocity * s0 + 4 * vm * sm + v1 * s1) + p.b * s1;
          const std::uint64_t cell =
              reach::CellOf(q.x, q.y, q.velocity, q.orientation, q.steering_angle, kCells);
          if (seen_.Insert(cell)) {
            const double across = SpeedAcross(v1, c1, s1, cos_h0, sin_h0);
            next_.push_back({cell, Node{q, now[i].s, now[i].d, i, {r, a}, across}});
          }
        }
      }
    }
    // Checked round-robin over the strata until max_states are valid.
    reach::SpreadOrder(
        next_,
        [](const Node& n) { return StratumAcross(n.state, n.across); },
        spread_, rank_);
    std::vector<Node>& layer = layers_[k];
    const std::size_t cap = static_cast<std::size_t>(max_states);
    for (std::size_t v = 0; v < rank_.size() && layer.size() < cap; ++v) {
      Node node = next_[rank_[v].second].second;
      map::FrenetPoint at;
      // The layer's end first (most states that fail, fail there), then the steps within it.
      int met_within = 0;  // the first step within the layer that meets a goal (0: none)
      if (Clear(node.state, k_end, node.s, &at) &&
          (n_sub == 1 || ClearBetween(now[node.parent].state, node.input, (k - 1) * sub_, n_sub,
                                      node.s, met < 0 ? &goals : nullptr, &met_within))) {
        node.s = at.s;
        node.d = at.d;
        const double t = k_end * dt_;
        if (met < 0 && met_within > 0) {  // the way ends there
          layer.push_back(node);
          met = static_cast<int>(layer.size()) - 1;
          met_steps = (k - 1) * sub_ + met_within;
          continue;
        }
        if (goal_only && !MayMeetGoal(node.s, node.d, node.state, t, goals, steps)) continue;
        layer.push_back(node);
        if (met < 0 && GoalDistance(node.s, node.d, node.state.velocity, node.state.orientation, t,
                                    goals) == 0) {
          met = static_cast<int>(layer.size()) - 1;
          met_steps = k_end;
        }
      }
    }
    if (layer.empty()) break;
    depth = k;
    if (met >= 0) break;
  }
  if (met < 0 && (goal_only || std::min(depth * sub_, steps) < steps)) return;
  // The state that meets a goal, else the last layer's nearest a goal region at its end (then
  // the farthest along the road, then the first), and its inputs back.
  const std::vector<Node>& last = layers_[depth];
  int best = std::max(met, 0);
  if (met < 0) {
    double best_gap = GoalGap(last[0], goals);
    for (int i = 1; i < static_cast<int>(last.size()); ++i) {
      const double gap = GoalGap(last[i], goals);
      if (gap < best_gap || (gap == best_gap && last[i].s > last[best].s)) {
        best = i;
        best_gap = gap;
      }
    }
  }
  goal_way_ = met >= 0;
  // Each layer's input for each scenario step it holds (to the step that met a goal).
  way_.resize(met >= 0 ? met_steps : std::min(depth * sub_, steps));
  for (int k = depth, i = best; k >= 1; --k) {
    const Node& node = layers_[k][i];
    const int q_end = std::min({k * sub_, steps, static_cast<int>(way_.size())});
    for (int q = (k - 1) * sub_; q < q_end; ++q) way_[q] = node.input;
    i = node.parent;
  }
}

bool Rescue::ClearBetween(const KsState& from, const KsInput& input, int k0, int n, double s_hint,
                          const std::vector<cost::GoalRegion>* goals, int* met) const {
  KsState q = from;
  map::FrenetPoint at;
  for (int j = 1; j < n; ++j) {
    q = SimulateKs(q, input, dt_, vehicle_, 1);
    if (!Clear(q, k0 + j, s_hint, &at)) return false;
    s_hint = at.s;
    if (goals != nullptr && *met == 0 &&
        GoalDistance(at.s, at.d, q.velocity, q.orientation, (k0 + j) * dt_, *goals) == 0) {
      *met = j;
      return true;  // the way ends here: the rest of the layer is not driven
    }
  }
  return true;
}

std::uint64_t Rescue::Stratum(const KsState& q, double heading0) {
  return StratumAcross(q, SpeedAcross(q.velocity, std::cos(q.orientation),
                                      std::sin(q.orientation), std::cos(heading0),
                                      std::sin(heading0)));
}

std::uint64_t Rescue::StratumAcross(const KsState& q, double across) {
  return reach::CellOf(q.x, q.y, q.velocity, across, q.steering_angle, kStrata);
}

void Rescue::Points(const KsState& ego, std::vector<double>* x, std::vector<double>* y) const {
  x->clear();
  y->clear();
  const double tick = plan::kTickSeconds;
  const double per_step = dt_ / tick;
  KsState s = ego;
  if (std::abs(per_step - std::round(per_step)) < 1e-9) {  // whole ticks a step
    const int ticks = plan::TicksIn(dt_);
    const double h = dt_ / ticks;
    for (const KsInput& u : way_) {
      for (int i = 0; i < ticks; ++i) {
        s = SimulateKs(s, u, h, vehicle_, 1);
        x->push_back(s.x);
        y->push_back(s.y);
      }
    }
    return;
  }
  // A point every tick; a step's input changes between two of them.
  const double total = static_cast<double>(way_.size()) * dt_;
  double t = 0;
  std::size_t u = 0;
  for (int i = 1; i * tick <= total + 1e-9 && u < way_.size(); ++i) {
    const double target = std::min(i * tick, total);
    while (t < target - 1e-12 && u < way_.size()) {
      const double boundary = static_cast<double>(u + 1) * dt_;
      const double to = std::min(target, boundary);
      s = SimulateKs(s, way_[u], to - t, vehicle_, 1);
      t = to;
      if (t >= boundary - 1e-12) ++u;
    }
    x->push_back(s.x);
    y->push_back(s.y);
  }
}

}  // namespace frenetic::commonroad

#include "frenetic/sim/incident_monitor.h"

#include <algorithm>
#include <cmath>

#include "frenetic/units.h"

namespace frenetic::sim {
namespace {

// The simulator's own miles conversion (§7.6).
constexpr double kCounterMetersPerMile = 1609.34;

bool HeldByDisplay(IncidentKind k) {
  return k == IncidentKind::kCollision || k == IncidentKind::kSpeed || k == IncidentKind::kLane ||
         k == IncidentKind::kOffRoad;
}

}  // namespace

const char* ToString(IncidentKind kind) {
  switch (kind) {
    case IncidentKind::kCollision: return "collision";
    case IncidentKind::kSpeed: return "speed";
    case IncidentKind::kAcceleration: return "acceleration";
    case IncidentKind::kJerk: return "jerk";
    case IncidentKind::kLane: return "lane";
    case IncidentKind::kOffRoad: return "off_road";
    case IncidentKind::kCount: break;
  }
  return "?";
}

double MeanMengerCurvature(const double* x, const double* y, int n) {
  if (n < 3) return 0;
  double sum = 0;
  for (int i = 0; i + 2 < n; ++i) {
    const double ax = x[i + 1] - x[i], ay = y[i + 1] - y[i];
    const double bx = x[i + 2] - x[i + 1], by = y[i + 2] - y[i + 1];
    const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
    if (la == 0 || lb == 0) continue;  // a zero-length step adds 0 but still counts
    const double cross = ax * by - ay * bx, dot = ax * bx + ay * by;
    if (cross == 0 && dot < 0) {  // an exact reversal: the simulator adds a huge value
      sum += 1e6;
      continue;
    }
    const double chord = std::hypot(x[i + 2] - x[i], y[i + 2] - y[i]);
    if (chord == 0) continue;
    const double sin_theta = std::abs(cross) / (la * lb);
    sum += 2 * sin_theta / chord;
  }
  return sum / (n - 2);
}

bool BoxesOverlap(const Box& a, const Box& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double ra = 0.5 * std::hypot(a.length, a.width), rb = 0.5 * std::hypot(b.length, b.width);
  if (dx * dx + dy * dy > (ra + rb) * (ra + rb)) return false;  // cheap reject
  const double ca = std::cos(a.heading), sa = std::sin(a.heading);
  const double cb = std::cos(b.heading), sb = std::sin(b.heading);
  // Axes: both boxes' length and width directions.
  const double axes[4][2] = {{ca, sa}, {-sa, ca}, {cb, sb}, {-sb, cb}};
  for (const auto& ax : axes) {
    auto half = [&](const Box& box, double c, double s) {
      const double along = std::abs(c * ax[0] + s * ax[1]);
      const double across = std::abs(-s * ax[0] + c * ax[1]);
      return 0.5 * box.length * along + 0.5 * box.width * across;
    };
    const double dist = std::abs(dx * ax[0] + dy * ax[1]);
    if (dist > half(a, ca, sa) + half(b, cb, sb)) return false;
  }
  return true;
}

IncidentMonitor::IncidentMonitor(const IncidentOptions& options) : options_(options) {
  last_active_tick_.fill(-1000000000);
  log_.reserve(64);
}

void IncidentMonitor::Raise(IncidentKind kind, bool on, const TickSample& sample, double t,
                            double value) {
  const int k = static_cast<int>(kind);
  if (on) {
    // An onset is a rising edge; flicker within merge_ticks of the last active tick is the same
    // incident, so the log counts events, not ticks.
    if (!active_[k] && tick_ - last_active_tick_[k] > options_.merge_ticks) {
      Incident inc;
      inc.t = t;
      inc.s = sample.s;
      inc.d = sample.d;
      inc.lane = static_cast<int>(std::floor(sample.d / 4.0));
      inc.lane = std::clamp(inc.lane, -1, 3);
      inc.kind = kind;
      inc.value = value;
      if (log_.empty()) first_at_ = distance_;
      log_.push_back(inc);
      ++counts_[k];
    }
    last_active_tick_[k] = tick_;
    if (HeldByDisplay(kind) && display_[k] == 0) display_[k] = options_.display_hold_frames;
  }
  active_[k] = on;
}

void IncidentMonitor::Update(const TickSample& sample, double t) {
  ++tick_;
  const double speed = sample.speed;
  distance_ += speed * kTick;
  max_speed_ = std::max(max_speed_, speed);

  // 10-tick blocks of speed and position (§7.2).
  block_v_[block_n_] = speed;
  block_x_[block_n_] = sample.x;
  block_y_[block_n_] = sample.y;
  if (++block_n_ == kBlockTicks) {
    block_n_ = 0;
    double vbar = 0;
    for (double v : block_v_) vbar += v;
    vbar /= 10;
    const double a_t = (vbar - prev_block_v_) / 0.2;
    const double kappa = MeanMengerCurvature(block_x_.data(), block_y_.data(), 10);
    const double a_n = vbar * vbar * kappa;
    prev_block_v_ = vbar;
    last_acc_t_ = a_t;
    last_acc_n_ = a_n;
    last_acc_ = std::sqrt(a_t * a_t + a_n * a_n);
    max_acc_ = std::max(max_acc_, last_acc_);
    // Every 5 acceleration samples: jerk from 1 s means (§7.3).
    acc_samples_[acc_n_] = last_acc_;
    if (++acc_n_ == 5) {
      acc_n_ = 0;
      double abar = 0;
      for (double a : acc_samples_) abar += a;
      abar /= 5;
      last_jerk_ = abar - prev_mean_acc_;
      prev_mean_acc_ = abar;
      max_abs_jerk_ = std::max(max_abs_jerk_, std::abs(last_jerk_));
      sum_sq_jerk_ += last_jerk_ * last_jerk_;
      ++jerk_samples_;
    }
  }

  const double mph = speed * units::kSimMpsToMph;
  Raise(IncidentKind::kSpeed, mph > options_.speed_limit_mph, sample, t, mph);
  Raise(IncidentKind::kAcceleration, last_acc_ >= options_.acc_limit, sample, t, last_acc_);
  Raise(IncidentKind::kJerk, std::abs(last_jerk_) >= options_.jerk_limit, sample, t, last_jerk_);
  const double d = sample.d;
  Raise(IncidentKind::kOffRoad, d < 0.8 || d > 11.2, sample, t, d);
  const bool on_line = (d > 3.2 && d < 4.8) || (d > 7.2 && d < 8.8);
  lane_counter_ = on_line ? lane_counter_ + 1 : 0;
  Raise(IncidentKind::kLane, lane_counter_ > options_.lane_line_ticks, sample, t, lane_counter_);
  Raise(IncidentKind::kCollision, sample.collision_with >= 0, sample, t, sample.collision_with);

  // The on-screen counter (§7.6): any displayed flag resets distance and timer.
  bool displayed = active_[static_cast<int>(IncidentKind::kAcceleration)] ||
                   active_[static_cast<int>(IncidentKind::kJerk)];
  for (int k = 0; k < kIncidentKinds; ++k) {
    if (display_[k] > 0) {
      displayed = true;
      --display_[k];
    }
  }
  if (displayed) {
    current_miles_ = 0;
    timer_ = 0;
  } else {
    current_miles_ += speed * kTick / kCounterMetersPerMile;
    timer_ += kTick;
  }
  best_miles_ = std::max(best_miles_, current_miles_);
}

}  // namespace frenetic::sim

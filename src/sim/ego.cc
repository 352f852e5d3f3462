#include "frenetic/sim/ego.h"

#include <algorithm>
#include <cmath>

namespace frenetic::sim {

int TrimStart(std::span<const float> x, std::span<const float> y, float car_x, float car_y) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) return 0;
  // The simulator scans with a running minimum that starts at 10000 m and keeps the first of
  // equal distances; distances are float (Unity's Vector3.Distance).
  float closest = 10000.0f;
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float dx = x[i] - car_x, dy = y[i] - car_y;
    const float dist = std::sqrt(dx * dx + dy * dy);
    if (dist < closest) {
      closest = dist;
      k = i;
    }
  }
  if (k > 0) return static_cast<int>(k + 1);
  // k = 0: point 0 counts as reached only at distance exactly 0; otherwise it is still ahead.
  return closest == 0.0f ? 1 : 0;
}

EgoCar::EgoCar(float x, float y, double yaw) : x_(x), y_(y), yaw_(yaw) {
  px_.reserve(256);
  py_.reserve(256);
  scratch_x_.reserve(256);
  scratch_y_.reserve(256);
}

void EgoCar::ApplyPath(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = std::min(x.size(), y.size());
  scratch_x_.resize(n);
  scratch_y_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    scratch_x_[i] = static_cast<float>(x[i]);
    scratch_y_[i] = static_cast<float>(y[i]);
  }
  const int start = TrimStart(scratch_x_, scratch_y_, x_, y_);
  px_.assign(scratch_x_.begin() + start, scratch_x_.end());
  py_.assign(scratch_y_.begin() + start, scratch_y_.end());
  head_ = 0;
}

void EgoCar::Tick() {
  const std::size_t left = px_.size() - head_;
  if (left >= 2) {
    const float nx = px_[head_], ny = py_[head_];
    // Velocity is the displacement over the tick (kinematic rigidbody moved by teleport).
    vx_ = (nx - x_) / 0.02f;
    vy_ = (ny - y_) / 0.02f;
    speed_ = std::sqrt(vx_ * vx_ + vy_ * vy_);
    // The nose turns from the pre-tick position toward the second remaining point.
    const float hx = px_[head_ + 1] - x_, hy = py_[head_ + 1] - y_;
    if (hx != 0.0f || hy != 0.0f) yaw_ = std::atan2(static_cast<double>(hy), hx);
    x_ = nx;
    y_ = ny;
  } else {
    vx_ = vy_ = speed_ = 0.0f;
  }
  if (left >= 2) {
    ++head_;
  } else {
    px_.clear();
    py_.clear();
    head_ = 0;
  }
}

}  // namespace frenetic::sim

// The ego car's "perfect controller" (udacity-sim.md §4): one path point per 0.02 s tick,
// teleport to it and turn toward the next; the closest-point trimming of a new path. Positions
// are float32, as in the simulator.
#pragma once

#include <span>
#include <vector>

namespace frenetic::sim {

// The trimming of §4.2 applied to a new path (already float32): the index of the first point
// kept. The closest point k to (car_x, car_y) is searched with the running minimum starting at
// 10000 m (ties keep the first); k > 0 drops points 0..k, k = 0 drops point 0 only when its
// distance is exactly 0. An empty path returns 0.
int TrimStart(std::span<const float> x, std::span<const float> y, float car_x, float car_y);

class EgoCar {
 public:
  EgoCar(float x, float y, double yaw);

  // Replaces the path with the new one (converted to float32, then trimmed). x and y of unequal
  // length use the shorter; the caller has rejected non-finite values.
  void ApplyPath(std::span<const double> x, std::span<const double> y);
  // One 0.02 s tick: with >= 2 points, teleport to the first and turn toward the second (from
  // the pre-tick position); then drop the first point. Fewer than 2 points: stand still.
  void Tick();

  float x() const { return x_; }
  float y() const { return y_; }
  double yaw() const { return yaw_; }      // rad, counter-clockwise from +x
  float speed() const { return speed_; }   // m/s, displacement of the last tick / 0.02 s
  float vx() const { return vx_; }
  float vy() const { return vy_; }
  // Unvisited points, in order.
  std::span<const float> path_x() const { return {px_.data() + head_, px_.size() - head_}; }
  std::span<const float> path_y() const { return {py_.data() + head_, py_.size() - head_}; }
  int path_size() const { return static_cast<int>(px_.size() - head_); }

 private:
  float x_, y_;
  double yaw_;
  float speed_ = 0, vx_ = 0, vy_ = 0;
  std::vector<float> px_, py_, scratch_x_, scratch_y_;
  std::size_t head_ = 0;
};

}  // namespace frenetic::sim

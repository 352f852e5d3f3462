// The simulator's incident checks (udacity-sim.md §7), evaluated every 0.02 s tick on what the
// ego did: speed > 50 mph; total acceleration on 10-tick blocks (tangential from block-mean
// speeds, normal from the block-mean Menger curvature); jerk on 1 s blocks; road edges and the
// lane-line timer on the chord-based d; contact of oriented car boxes. Also the "miles without
// incident" counter with its display hold (§7.6) and a log with one entry per onset.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "frenetic/sim/scenario.h"

namespace frenetic::sim {

enum class IncidentKind : std::uint8_t {
  kCollision, kSpeed, kAcceleration, kJerk, kLane, kOffRoad, kCount
};
inline constexpr int kIncidentKinds = static_cast<int>(IncidentKind::kCount);
// Ticks of one acceleration block (0.2 s): the monitor measures acceleration block by block.
inline constexpr int kBlockTicks = 10;
// "collision", "speed", "acceleration", "jerk", "lane", "off_road".
const char* ToString(IncidentKind kind);

// One incident onset. value: speed mph, acceleration m/s^2, jerk m/s^3 (signed), ticks on the
// lane line, d for off_road, the other car's id for a collision.
struct Incident {
  double t = 0;         // simulated s since the episode started
  double s = 0, d = 0;  // the simulator's Frenet of the ego, m
  int lane = -1;        // floor(d / 4), -1 left of the road, 3 right of it
  IncidentKind kind = IncidentKind::kCollision;
  double value = 0;
};

// What the monitor needs about one tick.
struct TickSample {
  double x = 0, y = 0;  // ego position after the tick, m
  double speed = 0;     // m/s, displacement / 0.02 s
  double s = 0, d = 0;  // chord Frenet of the ego (NaN already replaced)
  int collision_with = -1;  // id of a car whose box overlaps the ego's, or -1
};

class IncidentMonitor {
 public:
  explicit IncidentMonitor(const IncidentOptions& options);

  // Feeds one tick (time t after it, s).
  void Update(const TickSample& sample, double t);

  // Flags as the simulator has them after the last tick.
  bool active(IncidentKind kind) const { return active_[static_cast<int>(kind)]; }
  const std::vector<Incident>& log() const { return log_; }
  // Drops the log (flags, meters and counters stay): a copy that only judges what comes next
  // (the incident judge's search) then copies no history.
  void ClearLog() { log_.clear(); }
  const std::array<int, kIncidentKinds>& counts() const { return counts_; }
  int total() const { return static_cast<int>(log_.size()); }

  double last_acc() const { return last_acc_; }    // latest 0.2 s block total acceleration
  double last_acc_t() const { return last_acc_t_; }  // tangential part (signed)
  double last_acc_n() const { return last_acc_n_; }  // normal part
  double last_jerk() const { return last_jerk_; }  // latest 1 s block jerk (signed)
  double max_speed() const { return max_speed_; }  // m/s, over all ticks
  double max_acc() const { return max_acc_; }
  double max_abs_jerk() const { return max_abs_jerk_; }
  double sum_sq_jerk() const { return sum_sq_jerk_; }
  int jerk_samples() const { return jerk_samples_; }

  double distance() const { return distance_; }  // m driven (sum of per-tick displacements)
  double current_miles() const { return current_miles_; }  // since the last displayed incident
  double best_miles() const { return best_miles_; }
  double timer() const { return timer_; }  // s since the last reset of the counter
  // Distance driven before the first incident (the whole distance while there is none), m.
  double distance_to_first_incident() const { return log_.empty() ? distance_ : first_at_; }

 private:
  void Raise(IncidentKind kind, bool on, const TickSample& sample, double t, double value);

  IncidentOptions options_;
  // 10-tick block of speeds and positions.
  std::array<double, kBlockTicks> block_v_{}, block_x_{}, block_y_{};
  int block_n_ = 0;
  double prev_block_v_ = 0;
  std::array<double, 5> acc_samples_{};
  int acc_n_ = 0;
  double prev_mean_acc_ = 0;
  int lane_counter_ = 0;
  std::array<bool, kIncidentKinds> active_{};
  std::array<std::int64_t, kIncidentKinds> last_active_tick_{};
  std::array<int, kIncidentKinds> display_{};
  std::array<int, kIncidentKinds> counts_{};
  std::vector<Incident> log_;
  std::int64_t tick_ = 0;
  double last_acc_ = 0, last_acc_t_ = 0, last_acc_n_ = 0, last_jerk_ = 0;
  double max_speed_ = 0, max_acc_ = 0, max_abs_jerk_ = 0, sum_sq_jerk_ = 0;
  int jerk_samples_ = 0;
  double distance_ = 0, current_miles_ = 0, best_miles_ = 0, timer_ = 0, first_at_ = 0;
};

// Mean Menger curvature of the consecutive triples of `n` points (1/m): a zero-length step adds
// 0 but counts, an exact reversal adds 1e6. Used on the 10 positions of a block (8 triples).
double MeanMengerCurvature(const double* x, const double* y, int n);

// Whether two oriented boxes overlap (separating-axis test). Centre (m), heading (rad), length
// along the heading and width across it (m).
struct Box {
  double x = 0, y = 0, heading = 0, length = 4.6, width = 2.4;
};
bool BoxesOverlap(const Box& a, const Box& b);

}  // namespace frenetic::sim

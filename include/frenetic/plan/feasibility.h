// Hard feasibility of a path in the map frame, measured the way the simulator measures it
// (udacity-sim.md §7.1–7.3): per-tick speed; total acceleration as differences of 0.2 s block
// means of speed plus v^2 times the block's mean Menger curvature; jerk as differences of 1 s
// means of that acceleration. The planner's check evaluates EVERY block alignment (sliding
// windows), so it is conservative whatever phase the simulator's blocks have.
#pragma once

#include <span>
#include <vector>

namespace frenetic::plan {

struct XyLimits {
  double max_speed = 22.128;  // m/s per 0.02 s step
  double max_accel = 9.0;     // m/s^2
  double max_jerk = 9.0;      // m/s^3
};

// A real vehicle's kinematic limits, those of CommonRoad's single-track models (the Udacity
// simulator has none): the steering angle delta = atan(wheelbase kappa) and its rate, and the
// forward acceleration, a_max up to switch_speed and a_max switch_speed / v above it. Measured
// on 0.1 s block means (speed, signed curvature) of the path, every alignment; the steering only
// where the blocks' speeds are 2 m/s or more (at a crawl the path's curvature is no steering
// angle). A limit of 0 is not measured.
struct VehicleLimits {
  double wheelbase = 0;       // m
  double max_steer = 0;       // rad
  double max_steer_rate = 0;  // rad/s
  double max_accel = 0;       // m/s^2, forward
  double switch_speed = 0;    // m/s
  bool any() const { return max_steer > 0 || max_steer_rate > 0 || max_accel > 0; }
  // The forward acceleration allowed at speed v (m/s^2): max_accel up to switch_speed,
  // max_accel switch_speed / v above it.
  double MaxForwardAccel(double v) const {
    return switch_speed > 0 && v > switch_speed ? max_accel * switch_speed / v : max_accel;
  }
};

// The Menger curvature of three points as the simulator computes it, 2 sin(theta) / |p3 - p1|
// (0 when a leg has no length, 1e6 for a reversal or a zero chord), and the same of every
// triple (i - 1, i, i + 1) for i in [first, n - 1) into kappa[i]: bit for bit the same values
// (two triples at a time where SSE2 is there).
double MengerCurvature(double x1, double y1, double x2, double y2, double x3, double y3);
void MengerCurvatures(const double* x, const double* y, int first, int n, double* kappa);

// Worst values found (m/s, m/s^2, m/s^3), and with VehicleLimits the worst ratio of each of
// its measures to its limit (<= 1: within it; 0 when not measured).
struct XyMeasure {
  double max_speed = 0, max_accel = 0, max_jerk = 0;
  double steer_ratio = 0, steer_rate_ratio = 0, forward_accel_ratio = 0;
};

class XyChecker {
 public:
  explicit XyChecker(int capacity = 1024, const VehicleLimits& vehicle = {});
  // Worst speed, acceleration and jerk of the path (points 0.02 s apart) over all windows that
  // end at or after index `first`. Windows reaching before index 0 are skipped. Does not
  // allocate for n <= capacity (larger n is truncated to capacity). NaN points give NaN values.
  XyMeasure Measure(const double* x, const double* y, int n, int first);
  // The same for paths that all start with the same points (the driven history and the kept
  // points, common to every candidate of a cycle): SetPrefix computes their part once, and
  // MeasureWithPrefix, given a path whose first prefix points are those, only the rest.
  void SetPrefix(const double* x, const double* y, int n);
  // stop_over (optional): when the speed or the acceleration is already over its limit there
  // (value / limit - 1 > 0), the jerk and the vehicle's measures are left at 0, unmeasured (a
  // caller asking only whether any limit is broken has its answer); the speed and the
  // acceleration are then lower bounds, one of them over its limit (the speeds are measured
  // first, and when the change of their 0.2 s block means alone is over the acceleration's
  // limit, the curvature is not measured).
  XyMeasure MeasureWithPrefix(const double* x, const double* y, int n, int first,
                              const XyLimits* stop_over = nullptr);

 private:
  // Fills the per-tick arrays from index `from` on (1: the whole path), assuming the earlier
  // entries are those of the same path; returns the path length used. speeds_done: the
  // speeds' part (ComputeSpeeds) is filled already.
  int Compute(const double* x, const double* y, int n, int from, bool speeds_done = false);
  // Compute's speeds, their prefix sums and the 0.2 s block means only.
  int ComputeSpeeds(const double* x, const double* y, int n, int from);
  // After ComputeSpeeds: whether the speed (m->max_speed, as Worst measures it) or the change
  // of the block means of speed alone (a lower bound of the total acceleration, m->max_accel)
  // is over `limits` (as Worst's stop_over tests them): then Worst would stop there too.
  bool SpeedOrPaceOver(int n, int first, const XyLimits& limits, XyMeasure* m) const;
  XyMeasure Worst(int n, int first, const XyLimits* stop_over = nullptr) const;
  void WorstVehicle(int n, int first, XyMeasure* m) const;
  int prefix_ = 0;
  VehicleLimits vehicle_;
  std::vector<double> v_, kappa_, vsum_, ksum_, acc_, asum_;
  std::vector<double> vmean_block_;  // Compute's 0.2 s block means of speed, by last tick
  std::vector<double> ksigned_sum_;  // prefix sums of the signed curvature (VehicleLimits)
  // WorstVehicle's block means of speed and signed curvature (scratch).
  mutable std::vector<double> vmean_, kmean_;
};

// The simulator's own measure for tests: fixed blocks starting at tick `phase`, with
// v̄_{-1} = 0 and Ā_{-1} = 0 as the simulator starts. Speeds are displacement / 0.02 s.
XyMeasure MeasureLikeSimulator(std::span<const double> x, std::span<const double> y,
                               int phase = 0);

}  // namespace frenetic::plan

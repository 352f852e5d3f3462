// Prediction of the surrounding traffic from sensor_fusion rows. Rows are converted to Frenet on
// the smooth reference line (from x, y: this also repairs the simulator's s = d = 0 glitch at the
// seam), rows off the carriageway (parked cars) are dropped, and the one-message speed spike of a
// just-spawned car is repaired. The default predictor keeps each car at constant speed along its
// lane; the interface leaves room for better ones.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/plan/telemetry.h"

namespace frenetic::plan {

// One tracked car at the observation instant. s is relative to the ego reference passed to
// Observe (m, along the line, in [-L/2, L/2)), d its lateral offset (m, right positive), v_s its
// speed along the lane (m/s).
struct TrackedCar {
  int id = 0;
  double s = 0, d = 0, v_s = 0;
};

struct PredictorOptions {
  double range = 200;        // m: cars farther along s are ignored
  double d_min = -1, d_max = 13;  // m: the carriageway
  double max_speed = 30;     // m/s: faster readings are the spawn glitch
  double spike_ratio = 1.8;  // a reading this much above the id's last one is the spawn glitch
  int max_cars = 64;         // rows beyond this are ignored (keeps Observe allocation-free)
};

class Predictor {
 public:
  virtual ~Predictor() = default;
  // Replaces the tracked set with the valid rows of `rows`, relative to the ego's line
  // coordinate `ego_s` (wrapped or not). Never fails: invalid rows are skipped.
  virtual void Observe(std::span<const SensorCar> rows, double ego_s) = 0;
  virtual std::span<const TrackedCar> cars() const = 0;
  // Predicted (s, d) of car i, t seconds after the observation.
  virtual void Predict(int i, double t, double* s, double* d) const = 0;
  virtual void Reset() = 0;
};

// Constant speed along the lane, constant d.
std::unique_ptr<Predictor> MakeConstantVelocityPredictor(
    std::shared_ptr<const map::ReferenceLine> line, const PredictorOptions& options);

}  // namespace frenetic::plan

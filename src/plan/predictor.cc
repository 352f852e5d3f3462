#include "frenetic/plan/predictor.h"

#include <cmath>

namespace frenetic::plan {
namespace {

constexpr double kMphPerMps = 2.2369362920544;

class ConstantVelocityPredictor : public Predictor {
 public:
  ConstantVelocityPredictor(std::shared_ptr<const map::ReferenceLine> line,
                            const PredictorOptions& options)
      : line_(std::move(line)), options_(options) {
    cars_.reserve(options_.max_cars);
    memory_.reserve(options_.max_cars);
  }

  void Observe(std::span<const SensorCar> rows, double ego_s) override {
    cars_.clear();
    if (!std::isfinite(ego_s)) return;
    for (const SensorCar& row : rows) {
      if (static_cast<int>(cars_.size()) >= options_.max_cars) break;
      if (!std::isfinite(row.x) || !std::isfinite(row.y) || !std::isfinite(row.vx) ||
          !std::isfinite(row.vy) || std::abs(row.x) > 1e6 || std::abs(row.y) > 1e6) {
        continue;
      }
      // Recompute Frenet from x, y: the reported s, d may be the seam's 0/0 glitch. The reported
      // s is only a hint (the line falls back to a global search when it is wrong).
      const double hint = std::isfinite(row.s) ? row.s : ego_s;
      const map::FrenetPoint f = line_->ToFrenet(row.x, row.y, hint);
      if (!std::isfinite(f.s) || !std::isfinite(f.d)) continue;
      if (f.d < options_.d_min || f.d > options_.d_max) continue;  // parked / off the road
      const double rel = line_->DiffS(f.s, line_->WrapS(ego_s));
      if (std::abs(rel) > options_.range) continue;
      const double heading = line_->At(f.s).heading;
      double v = row.vx * std::cos(heading) + row.vy * std::sin(heading);
      v = Repair(row.id, v);
      cars_.push_back({row.id, rel, f.d, v});
    }
  }

  std::span<const TrackedCar> cars() const override { return cars_; }

  void Predict(int i, double t, double* s, double* d) const override {
    const TrackedCar& c = cars_[i];
    *s = c.s + c.v_s * t;
    *d = c.d;
  }

  void Reset() override {
    cars_.clear();
    memory_.clear();
  }

 private:
  // The spawn glitch reports the speed in mph as if it were m/s for one message: use the id's
  // previous speed, or undo the unit slip, and remember good readings.
  double Repair(int id, double v) {
    Memory* m = nullptr;
    for (Memory& e : memory_) {
      if (e.id == id) m = &e;
    }
    const bool glitch_ratio = m != nullptr && m->v > 1.0 && v > options_.spike_ratio * m->v;
    if (v > options_.max_speed || glitch_ratio) {
      v = m != nullptr ? m->v : std::min(v / kMphPerMps, options_.max_speed);
      return v;
    }
    if (m != nullptr) {
      m->v = v;
    } else if (static_cast<int>(memory_.size()) < options_.max_cars) {
      memory_.push_back({id, v});
    }
    return v;
  }

  struct Memory {
    int id;
    double v;
  };
  std::shared_ptr<const map::ReferenceLine> line_;
  PredictorOptions options_;
  std::vector<TrackedCar> cars_;
  std::vector<Memory> memory_;
};

}  // namespace

std::unique_ptr<Predictor> MakeConstantVelocityPredictor(
    std::shared_ptr<const map::ReferenceLine> line, const PredictorOptions& options) {
  return std::make_unique<ConstantVelocityPredictor>(std::move(line), options);
}

}  // namespace frenetic::plan

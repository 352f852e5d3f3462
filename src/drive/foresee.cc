#include "frenetic/drive/foresee.h"

#include <cmath>
#include <memory>

#include "frenetic/map/reference_line.h"
#include "frenetic/sim/traffic.h"
#include "frenetic/sim/world.h"

namespace frenetic::sim {
namespace {
// m per 0.1 s sample: farther is a respawn, not a drive (60 m/s).
constexpr double kJump = 6.0;
}  // namespace

void Foresee(const Simulator& sim, double seconds, std::vector<plan::CarFuture>* out) {
  out->clear();
  std::unique_ptr<Simulator> copy = sim.Clone();
  plan::Telemetry now;
  copy->GetTelemetry(&now);
  std::vector<double> x(now.previous_path_x), y(now.previous_path_y);
  const map::ReferenceLine& line = *sim.world().line;
  if (x.empty()) {
    x.push_back(now.x);
    y.push_back(now.y);
  }
  const std::size_t n = x.size();
  const double step =
      n >= 2 ? std::hypot(x[n - 1] - x[n - 2], y[n - 1] - y[n - 2]) : now.speed * kTick;
  const map::FrenetPoint end = line.ToFrenet(x.back(), y.back());
  const int extra = static_cast<int>(std::ceil(seconds / kTick)) + 1;
  for (int i = 1; i <= extra; ++i) {
    const map::CartesianPose p = line.ToCartesian(end.s + i * step, end.d);
    x.push_back(p.x);
    y.push_back(p.y);
  }
  (void)copy->ApplyPath(x, y);
  const int samples = static_cast<int>(std::floor(seconds / 0.1 + 1e-9)) + 1;
  // The traffic's slots stay where they are (a respawn reuses its slot): each future reads its
  // car's slot.
  std::vector<std::size_t> slots;
  for (std::size_t i = 0; i < copy->traffic().cars().size(); ++i) {
    const TrafficCar& c = copy->traffic().cars()[i];
    if (!c.spawned) continue;
    slots.push_back(i);
    plan::CarFuture& f = out->emplace_back();
    f.id = c.id;
    f.dt = 0.1;
  }
  std::vector<char> cut(slots.size(), 0);
  for (int k = 0; k < samples; ++k) {
    if (k > 0) copy->Advance(5);
    for (std::size_t i = 0; i < slots.size(); ++i) {
      if (cut[i]) continue;
      const TrafficCar& c = copy->traffic().cars()[slots[i]];
      plan::CarFuture& f = (*out)[i];
      if (c.id != f.id || !c.spawned ||
          (!f.x.empty() && std::hypot(c.x - f.x.back(), c.y - f.y.back()) > kJump)) {
        cut[i] = 1;
        continue;
      }
      f.x.push_back(c.x);
      f.y.push_back(c.y);
      f.v.push_back(std::hypot(c.vx, c.vy));
      f.heading.push_back(std::atan2(c.vy, c.vx));
    }
  }
  std::erase_if(*out, [](const plan::CarFuture& f) { return f.x.size() < 2; });
}

}  // namespace frenetic::sim

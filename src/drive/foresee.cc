#include "frenetic/drive/foresee.h"

#include <algorithm>
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
  std::vector<int> ids;
  for (const TrafficCar& c : copy->traffic().cars()) {
    if (c.spawned) ids.push_back(c.id);
  }
  for (int id : ids) {
    plan::CarFuture f;
    f.id = id;
    f.dt = 0.1;
    out->push_back(std::move(f));
  }
  std::vector<char> cut(ids.size(), 0);
  for (int k = 0; k < samples; ++k) {
    if (k > 0) copy->Advance(5);
    const auto& cars = copy->traffic().cars();
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (cut[i]) continue;
      const auto it = std::find_if(cars.begin(), cars.end(),
                                   [&](const TrafficCar& c) { return c.id == ids[i]; });
      plan::CarFuture& f = (*out)[i];
      const bool jumped =
          it == cars.end() || !it->spawned ||
          (!f.x.empty() && std::hypot(it->x - f.x.back(), it->y - f.y.back()) > kJump);
      if (jumped) {
        cut[i] = 1;
        continue;
      }
      f.x.push_back(it->x);
      f.y.push_back(it->y);
      f.v.push_back(std::hypot(it->vx, it->vy));
      f.heading.push_back(std::atan2(it->vy, it->vx));
    }
  }
  std::erase_if(*out, [](const plan::CarFuture& f) { return f.x.size() < 2; });
}

}  // namespace frenetic::sim

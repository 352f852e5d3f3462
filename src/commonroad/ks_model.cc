#include "frenetic/commonroad/ks_model.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace frenetic::commonroad {

Vec2 RearAxle(const KsState& s, const VehicleParams& p) {
  return {s.x - p.b * std::cos(s.orientation), s.y - p.b * std::sin(s.orientation)};
}

Vec2 CenterFromRearAxle(Vec2 rear, double orientation, const VehicleParams& p) {
  return {rear.x + p.b * std::cos(orientation), rear.y + p.b * std::sin(orientation)};
}

KsInput ConstrainInput(double steering_angle, double velocity, KsInput u,
                       const VehicleParams& p) {
  KsInput out = u;
  // vehiclemodels/utils/steering_constraints.py
  if ((steering_angle <= p.steering_min && u.steering_rate <= 0) ||
      (steering_angle >= p.steering_max && u.steering_rate >= 0)) {
    out.steering_rate = 0;
  } else {
    out.steering_rate = std::clamp(u.steering_rate, p.steering_rate_min, p.steering_rate_max);
  }
  // vehiclemodels/utils/acceleration_constraints.py
  if ((velocity <= p.v_min && u.acceleration <= 0) ||
      (velocity >= p.v_max && u.acceleration >= 0)) {
    out.acceleration = 0;
  } else if (u.acceleration <= -p.a_max) {
    out.acceleration = -p.a_max;
  } else {
    out.acceleration = std::min(u.acceleration, p.MaxAcceleration(velocity));
  }
  return out;
}

namespace {

using Vec5 = std::array<double, 5>;  // x_r, y_r, delta, v, psi

Vec5 Derivative(const Vec5& s, KsInput u, const VehicleParams& p) {
  const KsInput c = ConstrainInput(s[2], s[3], u, p);
  return {s[3] * std::cos(s[4]), s[3] * std::sin(s[4]), c.steering_rate, c.acceleration,
          s[3] / p.Wheelbase() * std::tan(s[2])};
}

Vec5 Axpy(const Vec5& s, double h, const Vec5& d) {
  Vec5 out;
  for (int i = 0; i < 5; ++i) out[i] = s[i] + h * d[i];
  return out;
}

}  // namespace

KsState SimulateKs(const KsState& start, KsInput u, double dt, const VehicleParams& p,
                   int substeps) {
  substeps = std::max(substeps, 1);
  const Vec2 rear = RearAxle(start, p);
  Vec5 s{rear.x, rear.y, start.steering_angle, start.velocity, start.orientation};
  const double h = dt / substeps;
  for (int i = 0; i < substeps; ++i) {
    const Vec5 k1 = Derivative(s, u, p);
    const Vec5 k2 = Derivative(Axpy(s, h / 2, k1), u, p);
    const Vec5 k3 = Derivative(Axpy(s, h / 2, k2), u, p);
    const Vec5 k4 = Derivative(Axpy(s, h, k3), u, p);
    for (int j = 0; j < 5; ++j) s[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
  }
  KsState end;
  end.time_step = start.time_step + 1;
  const Vec2 center = CenterFromRearAxle({s[0], s[1]}, s[4], p);
  end.x = center.x;
  end.y = center.y;
  end.steering_angle = s[2];
  end.velocity = s[3];
  end.orientation = s[4];
  return end;
}

}  // namespace frenetic::commonroad

// Closed-form boundary-value solutions of Werling et al., ICRA 2010, §III.
#include "frenetic/traj/polynomial.h"

#include <cmath>

namespace frenetic::traj {

double Polynomial5::JerkSquaredIntegral(double t_end) const {
  if (!(t_end > 0)) return 0.0;
  // J(t) = a + b t + c t^2; expand the square and integrate term by term.
  const double a = 6 * c[3], b = 24 * c[4], cc = 60 * c[5];
  const double t = t_end, t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  return a * a * t + a * b * t2 + (b * b + 2 * a * cc) * t3 / 3.0 + b * cc * t4 / 2.0 +
         cc * cc * t5 / 5.0;
}

bool Polynomial5::IsFinite() const {
  for (double v : c) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

Polynomial5 SolveQuintic(double x0, double v0, double a0, double x1, double v1, double a1,
                         double T) {
  Polynomial5 p;
  p.c[0] = x0;
  p.c[1] = v0;
  p.c[2] = 0.5 * a0;
  if (!(T > 0)) return p;
  const double T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  // Residuals of the end state after the start state's own motion.
  const double h = x1 - (x0 + v0 * T + 0.5 * a0 * T2);
  const double dv = v1 - (v0 + a0 * T);
  const double da = a1 - a0;
  p.c[3] = (10 * h - 4 * dv * T + 0.5 * da * T2) / T3;
  p.c[4] = (-15 * h + 7 * dv * T - da * T2) / T4;
  p.c[5] = (6 * h - 3 * dv * T + 0.5 * da * T2) / T5;
  return p;
}

Polynomial5 SolveQuartic(double x0, double v0, double a0, double v1, double a1, double T) {
  Polynomial5 p;
  p.c[0] = x0;
  p.c[1] = v0;
  p.c[2] = 0.5 * a0;
  if (!(T > 0)) return p;
  const double dv = v1 - (v0 + a0 * T);
  const double da = a1 - a0;
  p.c[3] = (3 * dv - da * T) / (3 * T * T);
  p.c[4] = (-2 * dv + da * T) / (4 * T * T * T);
  return p;
}

}  // namespace frenetic::traj

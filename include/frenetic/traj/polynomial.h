// Jerk-optimal 1-D polynomials of the Frenet lattice (Werling, Ziegler, Kammel, Thrun, "Optimal
// Trajectory Generation for Dynamic Street Scenarios in a Frenet Frame", ICRA 2010): quintics
// that join a start state (position, velocity, acceleration) to an end state, and quartics that
// join a start state to an end velocity and acceleration (velocity keeping).
#pragma once

#include <array>

namespace frenetic::traj {

// Position, velocity, acceleration and jerk of a 1-D motion at one instant (SI units).
struct State1d {
  double p = 0, v = 0, a = 0, j = 0;
};

// p(t) = c0 + c1 t + c2 t^2 + c3 t^3 + c4 t^4 + c5 t^5, t in seconds from the start.
struct Polynomial5 {
  std::array<double, 6> c{};

  double P(double t) const { return c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5])))); }
  double V(double t) const { return c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5]))); }
  double A(double t) const { return 2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5])); }
  double J(double t) const { return 6 * c[3] + t * (24 * c[4] + t * 60 * c[5]); }
  State1d At(double t) const { return {P(t), V(t), A(t), J(t)}; }
  // Closed form of the integral of J(t)^2 over [0, t_end], the comfort term of Werling et al.
  double JerkSquaredIntegral(double t_end) const;
  bool IsFinite() const;
};

// The quintic with p(0)=x0, v(0)=v0, a(0)=a0, p(T)=x1, v(T)=v1, a(T)=a1. T must be > 0
// (callers validate; T <= 0 returns the constant-velocity polynomial through the start state).
Polynomial5 SolveQuintic(double x0, double v0, double a0, double x1, double v1, double a1, double T);

// The quartic (c5 = 0) with p(0)=x0, v(0)=v0, a(0)=a0, v(T)=v1, a(T)=a1; the end position is free.
// T <= 0 returns the constant-velocity polynomial through the start state.
Polynomial5 SolveQuartic(double x0, double v0, double a0, double v1, double a1, double T);

// A polynomial valid on [0, duration], continued at constant velocity (zero acceleration) after
// its end: the lattice's trajectories all end with zero acceleration, so the continuation is C1
// and, for those, C2. With a delay the motion holds still at the polynomial's start for that long
// and follows it after (a lane change that waits): for polynomials that start at rest, this is C2.
// With a second move (back_duration > 0: a pass, out into a lane and back), the continuation
// lasts `hold` s, then `back` (which starts where the continuation is then) runs over
// back_duration, continued likewise.
struct Trajectory1d {
  Polynomial5 poly;
  double duration = 0;  // s, of the polynomial
  double delay = 0;     // s before the polynomial starts
  Polynomial5 back{};
  double hold = 0, back_duration = 0;  // s
  double end_time() const {
    return back_duration > 0 ? delay + duration + hold + back_duration : delay + duration;
  }
  // The integral of the squared jerk over the moves.
  double JerkSquared() const {
    const double j = poly.JerkSquaredIntegral(duration);
    return back_duration > 0 ? j + back.JerkSquaredIntegral(back_duration) : j;
  }
  bool IsFinite() const { return poly.IsFinite() && (back_duration <= 0 || back.IsFinite()); }

  // The pieces of the motion, in time order: held at poly's start (the delay), on poly, the
  // continuation after it, then with a second move on back and the continuation after it.
  enum class Piece { kHold, kPoly, kAfterPoly, kBack, kAfterBack };
  // The piece time t (s) falls on, and *u the time since that piece's start (s; 0 on kHold).
  // At and Sample both evaluate from it.
  Piece Locate(double t, double* u) const {
    *u = 0;
    if (t < delay) return Piece::kHold;
    t -= delay;
    if (t <= duration) {
      *u = t;
      return Piece::kPoly;
    }
    if (back_duration > 0 && t > duration + hold) {
      const double b = t - duration - hold;
      if (b <= back_duration) {
        *u = b;
        return Piece::kBack;
      }
      *u = b - back_duration;
      return Piece::kAfterBack;
    }
    *u = t - duration;
    return Piece::kAfterPoly;
  }

  State1d At(double t) const {
    double u = 0;
    switch (Locate(t, &u)) {
      case Piece::kHold:
        return {poly.c[0], 0.0, 0.0, 0.0};
      case Piece::kPoly:
        return poly.At(u);
      case Piece::kBack:
        return back.At(u);
      case Piece::kAfterBack: {
        const State1d b = back.At(back_duration);
        return {b.p + b.v * u, b.v, 0.0, 0.0};
      }
      case Piece::kAfterPoly:
        break;
    }
    const State1d e = poly.At(duration);
    return {e.p + e.v * u, e.v, 0.0, 0.0};
  }
  // At(time(k)).p, .v and .a in p[k], v[k] and a[k] (a may be null) for k in [k0, k1): the
  // same values (the same expressions), with the continuations' starts, the moves' end states,
  // evaluated once instead of at every sample past them, and no jerk.
  template <typename Time>
  void Sample(int k0, int k1, Time time, double* p, double* v, double* a) const {
    const double end_p = poly.P(duration), end_v = poly.V(duration);
    const double back_p = back_duration > 0 ? back.P(back_duration) : 0.0;
    const double back_v = back_duration > 0 ? back.V(back_duration) : 0.0;
    for (int k = k0; k < k1; ++k) {
      double u = 0, pk = 0, vk = 0, ak = 0;
      switch (Locate(time(k), &u)) {
        case Piece::kHold:
          pk = poly.c[0];
          break;
        case Piece::kPoly:
          pk = poly.P(u);
          vk = poly.V(u);
          ak = a != nullptr ? poly.A(u) : 0.0;
          break;
        case Piece::kBack:
          pk = back.P(u);
          vk = back.V(u);
          ak = a != nullptr ? back.A(u) : 0.0;
          break;
        case Piece::kAfterBack:
          pk = back_p + back_v * u;
          vk = back_v;
          break;
        case Piece::kAfterPoly:
          pk = end_p + end_v * u;
          vk = end_v;
          break;
      }
      p[k] = pk;
      v[k] = vk;
      if (a != nullptr) a[k] = ak;
    }
  }
};

}  // namespace frenetic::traj

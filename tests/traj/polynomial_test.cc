#include "frenetic/traj/polynomial.h"

#include <cmath>
#include <cstring>
#include <utility>
#include <random>

#include <gtest/gtest.h>

#include "frenetic/traj/box.h"
#include "frenetic/traj/frenet.h"

namespace frenetic::traj {
namespace {

constexpr double kTol = 1e-9;

TEST(PolynomialTest, QuinticMeetsBoundaryConditions) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5.0, 5.0), dur(0.5, 8.0);
  for (int i = 0; i < 200; ++i) {
    const double x0 = 10 * u(rng), v0 = u(rng), a0 = u(rng);
    const double x1 = 10 * u(rng), v1 = u(rng), a1 = u(rng), T = dur(rng);
    const Polynomial5 p = SolveQuintic(x0, v0, a0, x1, v1, a1, T);
    // Relative tolerance on the end position: values reach ~100 m.
    EXPECT_NEAR(p.P(0), x0, kTol);
    EXPECT_NEAR(p.V(0), v0, kTol);
    EXPECT_NEAR(p.A(0), a0, kTol);
    EXPECT_NEAR(p.P(T), x1, kTol * 100);
    EXPECT_NEAR(p.V(T), v1, kTol * 100);
    EXPECT_NEAR(p.A(T), a1, kTol * 100);
  }
}

TEST(PolynomialTest, QuarticMeetsBoundaryConditions) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5.0, 5.0), dur(0.5, 8.0);
  for (int i = 0; i < 200; ++i) {
    const double x0 = 10 * u(rng), v0 = u(rng), a0 = u(rng), v1 = u(rng), a1 = u(rng);
    const double T = dur(rng);
    const Polynomial5 p = SolveQuartic(x0, v0, a0, v1, a1, T);
    EXPECT_EQ(p.c[5], 0.0);
    EXPECT_NEAR(p.P(0), x0, kTol);
    EXPECT_NEAR(p.V(0), v0, kTol);
    EXPECT_NEAR(p.A(0), a0, kTol);
    EXPECT_NEAR(p.V(T), v1, kTol * 100);
    EXPECT_NEAR(p.A(T), a1, kTol * 100);
  }
}

TEST(PolynomialTest, DerivativesMatchFiniteDifferences) {
  const Polynomial5 p = SolveQuintic(1, 2, -1, 40, 10, 0.5, 4.0);
  const double h = 1e-5;
  for (double t = 0.1; t < 4.0; t += 0.37) {
    EXPECT_NEAR(p.V(t), (p.P(t + h) - p.P(t - h)) / (2 * h), 1e-5);
    EXPECT_NEAR(p.A(t), (p.V(t + h) - p.V(t - h)) / (2 * h), 1e-5);
    EXPECT_NEAR(p.J(t), (p.A(t + h) - p.A(t - h)) / (2 * h), 1e-5);
  }
}

TEST(PolynomialTest, JerkIntegralMatchesQuadrature) {
  const Polynomial5 p = SolveQuintic(0, 15, 1, 80, 20, 0, 4.5);
  const int n = 100000;
  const double T = 4.5, h = T / n;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double j = p.J((i + 0.5) * h);
    sum += j * j * h;
  }
  EXPECT_NEAR(p.JerkSquaredIntegral(T), sum, 1e-6 * sum);
  EXPECT_GT(sum, 0);
}

TEST(PolynomialTest, VelocityKeepingQuarticIsMonotonicFromRest) {
  const Polynomial5 p = SolveQuartic(0, 0, 0, 22, 0, 6.0);
  double last = -1;
  for (double t = 0; t <= 6.0; t += 0.02) {
    EXPECT_GE(p.V(t), last);
    last = p.V(t);
  }
}

TEST(PolynomialTest, DegenerateDurationKeepsStartState) {
  const Polynomial5 p = SolveQuintic(3, 4, 5, 100, 0, 0, 0.0);
  EXPECT_TRUE(p.IsFinite());
  EXPECT_DOUBLE_EQ(p.P(0), 3);
  EXPECT_DOUBLE_EQ(p.V(0), 4);
}

// A one-move trajectory: `poly` over `duration` after `delay`.
Trajectory1d Move(const Polynomial5& poly, double duration, double delay = 0) {
  Trajectory1d t;
  t.poly = poly;
  t.duration = duration;
  t.delay = delay;
  return t;
}

// Out from 0 to -3.5 in 2 s, 1 s there, back to 0 in 1.5 s: a pass.
Trajectory1d Pass() {
  Trajectory1d t = Move(SolveQuintic(0, 0, 0, -3.5, 0, 0, 2.0), 2.0);
  t.hold = 1.0;
  t.back = SolveQuintic(-3.5, 0, 0, 0, 0, 0, 1.5);
  t.back_duration = 1.5;
  return t;
}

TEST(TrajectoryTest, ContinuesAtConstantVelocityAfterItsEnd) {
  Trajectory1d t = Move(SolveQuartic(0, 10, 0, 20, 0, 3.0), 3.0);
  const State1d end = t.At(3.0), later = t.At(5.0);
  EXPECT_NEAR(later.v, 20, 1e-9);
  EXPECT_NEAR(later.p, end.p + 2 * 20, 1e-9);
  EXPECT_EQ(later.a, 0);
  FrenetTrajectory ft{t, Move(SolveQuintic(6, 0, 0, 2, 0, 0, 2.0), 2.0)};
  EXPECT_NEAR(ft.At(2.5).d, 2, 1e-9);
  EXPECT_TRUE(ft.At(1.0).IsFinite());
  // A delayed lane change holds its start for the delay, then follows the quintic, shifted.
  Trajectory1d wait = Move(SolveQuintic(6, 0, 0, 2, 0, 0, 2.0), 2.0, 1.5);
  EXPECT_EQ(wait.end_time(), 3.5);
  EXPECT_EQ(wait.At(0.0).p, 6);
  EXPECT_EQ(wait.At(1.4).p, 6);
  EXPECT_EQ(wait.At(1.4).v, 0);
  EXPECT_NEAR(wait.At(1.5 + 1.2).p, ft.lat.At(1.2).p, 1e-12);
  EXPECT_NEAR(wait.At(1.5 + 1.2).v, ft.lat.At(1.2).v, 1e-12);
  EXPECT_NEAR(wait.At(10).p, 2, 1e-9);
}

TEST(TrajectoryTest, APassGoesOutHoldsThereAndComesBack) {
  const Trajectory1d pass = Pass();
  EXPECT_EQ(pass.end_time(), 4.5);
  EXPECT_NEAR(pass.At(1.0).p, -1.75, 1e-9);  // halfway out
  EXPECT_NEAR(pass.At(2.5).p, -3.5, 1e-9);   // held
  EXPECT_NEAR(pass.At(2.5).v, 0.0, 1e-9);
  EXPECT_NEAR(pass.At(3.0 + 0.75).p, -1.75, 1e-9);  // halfway back
  EXPECT_NEAR(pass.At(9.0).p, 0.0, 1e-9);
  EXPECT_EQ(pass.At(9.0).v, 0.0);
  EXPECT_TRUE(pass.IsFinite());
  EXPECT_NEAR(pass.JerkSquared(), pass.poly.JerkSquaredIntegral(2.0) +
                                      pass.back.JerkSquaredIntegral(1.5), 1e-9);
  // Without the move back it is the move out, continued.
  Trajectory1d out = pass;
  out.back_duration = 0;
  EXPECT_EQ(out.end_time(), 2.0);
  EXPECT_NEAR(out.At(9.0).p, -3.5, 1e-9);
  EXPECT_EQ(out.JerkSquared(), out.poly.JerkSquaredIntegral(2.0));
}

TEST(TrajectoryTest, LocateNamesEachPieceInTimeOrder) {
  using P = Trajectory1d::Piece;
  Trajectory1d pass = Pass();
  pass.delay = 0.5;  // held 0.5 s, out until 2.5, held there until 3.5, back until 5.0
  const std::pair<double, P> at[] = {{0.2, P::kHold},      {1.0, P::kPoly},  {3.0, P::kAfterPoly},
                                     {4.0, P::kBack},      {6.0, P::kAfterBack}};
  const double since[] = {0.0, 0.5, 0.5, 0.5, 1.0};  // s since the piece's start
  for (int i = 0; i < 5; ++i) {
    double u = -1;
    EXPECT_EQ(pass.Locate(at[i].first, &u), at[i].second) << at[i].first;
    EXPECT_NEAR(u, since[i], 1e-12) << at[i].first;
  }
  // Without a second move the continuation lasts for ever.
  pass.back_duration = 0;
  double u = -1;
  EXPECT_EQ(pass.Locate(6.0, &u), P::kAfterPoly);
  EXPECT_NEAR(u, 3.5, 1e-12);
}

TEST(TrajectoryTest, SampleGivesAtsValuesExactly) {
  // Before the delay, on the polynomial, past its end, a pass's hold and move back; and NaN
  // times: bit for bit At's values.
  const Trajectory1d trs[] = {Move(SolveQuartic(0, 10, 0, 20, 0, 3.0), 3.0),
                              Move(SolveQuintic(6, 0, 0, 2, 0, 0, 2.0), 2.0, 1.5),
                              Move(SolveQuintic(0, 20, 1, 90, 15, 0, 4.7), 4.7, 0.3), Pass()};
  constexpr int kN = 61;
  const auto time = [](int k) { return k == kN - 1 ? NAN : k * 0.1; };
  for (const Trajectory1d& tr : trs) {
    double p[kN], v[kN], a[kN], p2[kN], v2[kN];
    tr.Sample(0, kN, time, p, v, a);
    tr.Sample(2, kN, time, p2, v2, nullptr);  // from k = 2 on, without the acceleration
    for (int k = 0; k < kN; ++k) {
      const State1d st = tr.At(time(k));
      EXPECT_EQ(std::memcmp(&p[k], &st.p, sizeof(double)), 0) << k;
      EXPECT_EQ(std::memcmp(&v[k], &st.v, sizeof(double)), 0) << k;
      EXPECT_EQ(std::memcmp(&a[k], &st.a, sizeof(double)), 0) << k;
      if (k >= 2) {
        EXPECT_EQ(std::memcmp(&p2[k], &st.p, sizeof(double)), 0) << k;
        EXPECT_EQ(std::memcmp(&v2[k], &st.v, sizeof(double)), 0) << k;
      }
    }
  }
}

TEST(BoxTest, OverlapSeparatingAxis) {
  const OrientedBox a{0, 0, 0, 2.4, 1.2};
  EXPECT_TRUE(Overlap(a, OrientedBox{4.7, 0, 0, 2.4, 1.2}));
  EXPECT_FALSE(Overlap(a, OrientedBox{4.9, 0, 0, 2.4, 1.2}));
  EXPECT_FALSE(Overlap(a, OrientedBox{0, 2.5, 0, 2.4, 1.2}));
  // Rotated by 90 degrees: the long side now reaches across.
  EXPECT_TRUE(Overlap(a, OrientedBox{0, 3.5, 1.5707963267948966, 2.4, 1.2}));
  // Diagonal corner cases: axis-aligned bounding boxes would overlap, the real ones do not.
  EXPECT_FALSE(Overlap(OrientedBox{0, 0, 0.785, 2.0, 0.3}, OrientedBox{2.2, -2.2, 0.785, 2.0, 0.3}));
  EXPECT_FALSE(Overlap(a, OrientedBox{std::nan(""), 0, 0, 1, 1}));
}

}  // namespace
}  // namespace frenetic::traj

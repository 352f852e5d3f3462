#include "frenetic/plan/feasibility.h"

#include <algorithm>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace frenetic::plan {
namespace {

constexpr double kDt = 0.02;
constexpr int kBlock = 10;  // ticks per acceleration sample (0.2 s)
constexpr int kJerkBlocks = 5;  // acceleration samples per jerk sample (1 s)
constexpr int kVehicleBlock = 5;  // ticks per VehicleLimits sample (0.1 s, CommonRoad's step)
constexpr double kSteerSpeed = 2.0;  // m/s: VehicleLimits' steering is measured from this speed on

double Norm(double x, double y) { return std::sqrt(x * x + y * y); }

}  // namespace

// Menger curvature of three points as the simulator computes it: 2 sin(theta) / |p3 - p1|.
// Squared lengths and one square root: the path coordinates are far from overflow, so
// std::hypot's care (and cost) is not needed.
double MengerCurvature(double x1, double y1, double x2, double y2, double x3, double y3) {
  const double ax = x2 - x1, ay = y2 - y1, bx = x3 - x2, by = y3 - y2;
  const double la2 = ax * ax + ay * ay, lb2 = bx * bx + by * by;
  if (la2 == 0 || lb2 == 0) return 0.0;
  const double cross = ax * by - ay * bx, dot = ax * bx + ay * by;
  const double lalb = std::sqrt(la2 * lb2);
  if (std::abs(cross) < 1e-12 * lalb && dot < 0) return 1e6;  // reversal
  const double cx = x3 - x1, cy = y3 - y1;
  const double chord2 = cx * cx + cy * cy;
  if (chord2 == 0) return 1e6;
  return 2.0 * std::abs(cross) / (lalb * std::sqrt(chord2));
}

void MengerCurvatures(const double* x, const double* y, int first, int n, double* kappa) {
  int i = std::max(1, first);
#if defined(__SSE2__)
  // Two triples at a time: MengerCurvature's operations lane by lane (IEEE, the same values), its cases
  // selected by masks.
  for (; i + 2 < n; i += 2) {
    const __m128d x1 = _mm_loadu_pd(x + i - 1), x2 = _mm_loadu_pd(x + i),
                  x3 = _mm_loadu_pd(x + i + 1);
    const __m128d y1 = _mm_loadu_pd(y + i - 1), y2 = _mm_loadu_pd(y + i),
                  y3 = _mm_loadu_pd(y + i + 1);
    const __m128d ax = _mm_sub_pd(x2, x1), ay = _mm_sub_pd(y2, y1);
    const __m128d bx = _mm_sub_pd(x3, x2), by = _mm_sub_pd(y3, y2);
    const __m128d la2 = _mm_add_pd(_mm_mul_pd(ax, ax), _mm_mul_pd(ay, ay));
    const __m128d lb2 = _mm_add_pd(_mm_mul_pd(bx, bx), _mm_mul_pd(by, by));
    const __m128d cross = _mm_sub_pd(_mm_mul_pd(ax, by), _mm_mul_pd(ay, bx));
    const __m128d dot = _mm_add_pd(_mm_mul_pd(ax, bx), _mm_mul_pd(ay, by));
    const __m128d lalb = _mm_sqrt_pd(_mm_mul_pd(la2, lb2));
    const __m128d cx = _mm_sub_pd(x3, x1), cy = _mm_sub_pd(y3, y1);
    const __m128d chord2 = _mm_add_pd(_mm_mul_pd(cx, cx), _mm_mul_pd(cy, cy));
    const __m128d abs_cross = _mm_andnot_pd(_mm_set1_pd(-0.0), cross);
    const __m128d curv =
        _mm_div_pd(_mm_mul_pd(_mm_set1_pd(2.0), abs_cross), _mm_mul_pd(lalb, _mm_sqrt_pd(chord2)));
    const __m128d zero = _mm_setzero_pd();
    const __m128d reversal = _mm_and_pd(
        _mm_cmplt_pd(abs_cross, _mm_mul_pd(_mm_set1_pd(1e-12), lalb)), _mm_cmplt_pd(dot, zero));
    const __m128d big = _mm_or_pd(reversal, _mm_cmpeq_pd(chord2, zero));
    const __m128d bent = _mm_or_pd(_mm_and_pd(big, _mm_set1_pd(1e6)), _mm_andnot_pd(big, curv));
    const __m128d flat = _mm_or_pd(_mm_cmpeq_pd(la2, zero), _mm_cmpeq_pd(lb2, zero));
    _mm_storeu_pd(&kappa[i], _mm_andnot_pd(flat, bent));
  }
#endif
  for (; i + 1 < n; ++i) {
    kappa[i] = MengerCurvature(x[i - 1], y[i - 1], x[i], y[i], x[i + 1], y[i + 1]);
  }
}

XyChecker::XyChecker(int capacity, const VehicleLimits& vehicle) : vehicle_(vehicle) {
  for (auto* v : {&v_, &kappa_, &vsum_, &ksum_, &acc_, &asum_, &vmean_block_}) {
    v->assign(capacity + 1, 0.0);
  }
  if (vehicle_.any()) {
    for (auto* v : {&ksigned_sum_, &vmean_, &kmean_}) v->assign(capacity + 1, 0.0);
  }
}

XyMeasure XyChecker::Measure(const double* x, const double* y, int n, int first) {
  n = Compute(x, y, n, 1);
  return n < 2 ? XyMeasure{} : Worst(n, first);
}

void XyChecker::WorstVehicle(int n, int first, XyMeasure* m) const {
  const VehicleLimits& lim = vehicle_;
  constexpr int b = kVehicleBlock;
  constexpr double bt = b * kDt;
  // Block means over ticks j-4..j: speed, and the signed curvature of the triples centred there;
  // each block's once (the loop reads the block before too).
  const int j0 = std::max(b, first);
  for (int j = std::max(b, j0 - b); j <= n - 2; ++j) {
    vmean_[j] = (vsum_[j + 1] - vsum_[j + 1 - b]) / b;
    kmean_[j] = (ksigned_sum_[j + 1] - ksigned_sum_[j + 1 - b]) / b;
  }
  auto vmean = [&](int j) { return vmean_[j]; };
  auto kmean = [&](int j) { return kmean_[j]; };
  // The steering angle is atan(wheelbase kappa): its worst size and change are taken on
  // tangents (atan is monotone; atan x - atan y = atan((x - y) / (1 + x y)) for x y > -1), and
  // one atan each at the end.
  double max_tan = 0, max_change = 0;
  // The last point's curvature is not known (0): blocks end at n - 2.
  for (int j = j0; j <= n - 2; ++j) {
    // At a crawl a path's curvature says nothing about the steering (a car turns its wheels at
    // a standstill, and points millimetres apart bend any way): steering is measured from
    // kSteerSpeed on.
    const bool steering = vmean(j) >= kSteerSpeed && (j < 2 * b || vmean(j - b) >= kSteerSpeed);
    const double x = lim.wheelbase * kmean(j);
    if (steering) max_tan = std::max(max_tan, std::abs(x));
    if (j < 2 * b) continue;  // the rates need the block before (from tick 1 on)
    if (lim.max_steer_rate > 0 && steering) {
      const double y = lim.wheelbase * kmean(j - b);
      const double den = 1 + x * y;
      const double change =
          den > 0 ? std::abs(x - y) / den : std::tan(std::abs(std::atan(x) - std::atan(y)));
      max_change = std::max(max_change, change);
    }
    if (lim.max_accel > 0) {
      const double v0 = vmean(j - b), a = (vmean(j) - v0) / bt;
      m->forward_accel_ratio = std::max(m->forward_accel_ratio, a / lim.MaxForwardAccel(v0));
    }
  }
  if (lim.max_steer > 0) m->steer_ratio = std::atan(max_tan) / lim.max_steer;
  if (lim.max_steer_rate > 0) m->steer_rate_ratio = std::atan(max_change) / bt / lim.max_steer_rate;
  if (std::isnan(v_[n - 1])) m->steer_ratio = m->steer_rate_ratio = m->forward_accel_ratio = NAN;
}

void XyChecker::SetPrefix(const double* x, const double* y, int n) {
  prefix_ = std::max(0, Compute(x, y, n, 1));
}

XyMeasure XyChecker::MeasureWithPrefix(const double* x, const double* y, int n, int first,
                                        const XyLimits* stop_over) {
  const int from = std::max(1, prefix_);
  if (stop_over != nullptr) {
    // Asked whether a limit is broken: the speeds first, and no curvature when they answer.
    const int m_n = ComputeSpeeds(x, y, n, from);
    XyMeasure m;
    if (m_n >= 2 && SpeedOrPaceOver(m_n, first, *stop_over, &m)) return m;
  }
  n = Compute(x, y, n, from, stop_over != nullptr);
  return n < 2 ? XyMeasure{} : Worst(n, first, stop_over);
}

int XyChecker::ComputeSpeeds(const double* x, const double* y, int n, int from) {
  n = std::min(n, static_cast<int>(v_.size()) - 1);
  if (n < 2) return n;
  from = std::clamp(from, 1, n);
  // v_[i]: speed at tick i (from i-1).
  v_[0] = 0;
  for (int i = from; i < n; ++i) v_[i] = Norm(x[i] - x[i - 1], y[i] - y[i - 1]) / kDt;
  vsum_[0] = 0;
  for (int i = std::max(0, from - 1); i < n; ++i) vsum_[i + 1] = vsum_[i] + v_[i];
  // Block means of speed, each block's once (a block's acceleration reads the block before):
  // those ending before tick from - 1 are the same path's (its sums up to there are unchanged).
  for (int j = std::max(kBlock - 1, from - 1); j < n; ++j) {
    vmean_block_[j] = (vsum_[j + 1] - vsum_[j + 1 - kBlock]) / kBlock;
  }
  return n;
}

bool XyChecker::SpeedOrPaceOver(int n, int first, const XyLimits& limits, XyMeasure* m) const {
  first = std::clamp(first, 1, n - 1);
  for (int i = first; i < n; ++i) m->max_speed = std::max(m->max_speed, v_[i]);
  if (m->max_speed / limits.max_speed - 1.0 > 0) return true;
  // The change of the block means alone: the total acceleration is the norm of it and of the
  // curvature's part, never less (but for rounding: the margin of 1e-12 covers it).
  double pace = 0;
  for (int j = std::max(2 * kBlock, first); j < n; ++j) {
    pace = std::max(pace, std::abs(vmean_block_[j] - vmean_block_[j - kBlock]) / (kBlock * kDt));
  }
  if (pace / limits.max_accel - 1.0 > 1e-12) {
    m->max_accel = pace;
    return true;
  }
  return false;
}

int XyChecker::Compute(const double* x, const double* y, int n, int from, bool speeds_done) {
  if (!speeds_done) ComputeSpeeds(x, y, n, from);
  n = std::min(n, static_cast<int>(v_.size()) - 1);
  if (n < 2) return n;
  from = std::clamp(from, 1, n);
  // kappa_[i]: Menger curvature of (i-1, i, i+1), 0 for the last point (recomputed once a later
  // point exists).
  kappa_[0] = 0;
  MengerCurvatures(x, y, std::max(1, from - 1), n, kappa_.data());
  kappa_[n - 1] = 0;
  // Prefix sums make every sliding block mean O(1) (the speeds' are ComputeSpeeds').
  ksum_[0] = 0;
  for (int i = std::max(0, from - 1); i < n; ++i) ksum_[i + 1] = ksum_[i] + kappa_[i];
  if (vehicle_.any()) {
    // The curvature's sign (left positive) from the triple's cross product.
    ksigned_sum_[0] = 0;
    for (int i = std::max(0, from - 1); i < n; ++i) {
      double k = kappa_[i];
      if (i >= 1 && i + 1 < n) {
        const double cross = (x[i] - x[i - 1]) * (y[i + 1] - y[i]) - (y[i] - y[i - 1]) * (x[i + 1] - x[i]);
        if (cross < 0) k = -k;
      }
      ksigned_sum_[i + 1] = ksigned_sum_[i] + k;
    }
  }
  // Block ending at tick j holds ticks j-9..j; its triples are centred at j-8..j-1.
  auto kmean = [&](int j) { return (ksum_[j] - ksum_[j - 8]) / 8.0; };
  // acc_[j] valid for j >= 2 * kBlock (needs the previous block, which starts at tick >= 1).
  for (int j = std::max(2 * kBlock, from); j < n; ++j) {
    const double vm = vmean_block_[j], vp = vmean_block_[j - kBlock];
    const double at = (vm - vp) / (kBlock * kDt), an = vm * vm * kmean(j);
    acc_[j] = Norm(at, an);
  }
  return n;
}

XyMeasure XyChecker::Worst(int n, int first, const XyLimits* stop_over) const {
  XyMeasure m;
  first = std::clamp(first, 1, n - 1);
  for (int i = first; i < n; ++i) m.max_speed = std::max(m.max_speed, v_[i]);
  if (std::isnan(v_[n - 1])) m.max_speed = NAN;
  const int a0 = 2 * kBlock;
  for (int j = std::max(a0, first); j < n; ++j) m.max_accel = std::max(m.max_accel, acc_[j]);
  if (stop_over != nullptr && (m.max_speed / stop_over->max_speed - 1.0 > 0 ||
                               m.max_accel / stop_over->max_accel - 1.0 > 0)) {
    return m;
  }
  // Jerk from 1 s means of the acceleration samples, block-aligned with j.
  const int span = kBlock * kJerkBlocks;
  for (int j = std::max(a0 + (kJerkBlocks - 1) * kBlock + span, first); j < n; ++j) {
    double now = 0, before = 0;
    for (int b = 0; b < kJerkBlocks; ++b) {
      now += acc_[j - b * kBlock];
      before += acc_[j - span - b * kBlock];
    }
    const double jerk = std::abs(now - before) / kJerkBlocks / (span * kDt);
    m.max_jerk = std::max(m.max_jerk, jerk);
  }
  if (vehicle_.any()) WorstVehicle(n, first, &m);
  return m;
}

XyMeasure MeasureLikeSimulator(std::span<const double> x, std::span<const double> y, int phase) {
  XyMeasure m;
  const int n = static_cast<int>(std::min(x.size(), y.size()));
  double v_prev_mean = 0, a_prev_mean = 0;
  double a_acc = 0;
  int a_count = 0;
  // Records start at tick `phase`+1 (the first tick with a displacement).
  for (int start = phase + 1; start + kBlock <= n; start += kBlock) {
    double vs = 0, ks = 0;
    for (int i = start; i < start + kBlock; ++i) {
      const double v = std::hypot(x[i] - x[i - 1], y[i] - y[i - 1]) / kDt;
      m.max_speed = std::max(m.max_speed, v);
      vs += v;
    }
    for (int i = start + 1; i + 1 < start + kBlock; ++i) {
      ks += MengerCurvature(x[i - 1], y[i - 1], x[i], y[i], x[i + 1], y[i + 1]);
    }
    const double vm = vs / kBlock, km = ks / 8.0;
    const double a = std::hypot((vm - v_prev_mean) / (kBlock * kDt), vm * vm * km);
    v_prev_mean = vm;
    m.max_accel = std::max(m.max_accel, a);
    a_acc += a;
    if (++a_count == kJerkBlocks) {
      const double mean = a_acc / kJerkBlocks;
      m.max_jerk =
          std::max(m.max_jerk, std::abs(mean - a_prev_mean) / (kJerkBlocks * kBlock * kDt));
      a_prev_mean = mean;
      a_acc = 0;
      a_count = 0;
    }
  }
  return m;
}

}  // namespace frenetic::plan

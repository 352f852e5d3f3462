// The cost-term interface. A term measures one thing about one candidate trajectory and returns
// an UNWEIGHTED, finite, non-negative number scaled by a physical bound (jerk / 2 m/s^3, offset /
// lane width...), so that the weights in config/planner.yaml stay within about 1–10. A term never
// knows its weight. Terms live in costs/*.cc, one per file, and register themselves by name with
// FRENETIC_REGISTER_COST (cost_registry.h).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "frenetic/cost/goal_region.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace frenetic::cost {

inline constexpr int kMaxLanes = 8;

// What every term may read about the planning cycle (shared by all candidates). Frenet frame of
// the reference line, s unwrapped (continuous through the loop's seam), d positive to the right.
// Sample k of every array is at time t_k = k * dt after the candidates' start state.
struct CostContext {
  int num_samples = 0;  // n
  double dt = 0.25;     // s between samples
  double lane_width = 4.0;
  int num_lanes = 3;
  // Largest s-speed per lane that keeps the XY speed under the cap (m/s; curves make outer lanes
  // faster in XY than in s).
  double lane_speed_limit[kMaxLanes] = {};
  double lane_center[kMaxLanes] = {};  // d of each lane's centre, m
  // A two-way road: the right border (d, m) of the oncoming lane on the left, at the start's s
  // (-infinity: none, as on the Udacity track and one-way roads).
  double oncoming_right = -std::numeric_limits<double>::infinity();
  // The start state.
  double start_s = 0, start_d = 0, start_speed = 0;
  int current_lane = 0;  // lane whose centre is nearest start_d
  // Decision memory for hysteresis: the lane targeted last cycle and how long ago the latest
  // lane change was chosen (s; large when none).
  int previous_target_lane = -1;
  double time_since_lane_change = 1e9;
  int lane_before_change = -1;  // lane the latest lane change left (-1: none)
  // Last cycle's chosen trajectory at the same sample times (nullptr when there is none).
  const double* previous_s = nullptr;
  const double* previous_d = nullptr;
  // Predicted traffic: car c at sample k is at (car_s[c * n + k], car_d[c * n + k]) moving at
  // car_v[c * n + k] along the lane. Cars the planner deems irrelevant (far, or behind in the
  // ego's own lane) are already left out.
  int num_cars = 0;
  const double* car_s = nullptr;
  const double* car_d = nullptr;
  const double* car_v = nullptr;
  // An upper bound of every car_v value (m/s; infinity when unknown): bounds broad-phase reaches.
  double max_car_speed = std::numeric_limits<double>::infinity();
  double car_length = 4.8, car_width = 2.4;  // footprint of a car without its own, m
  double ego_length = 4.8, ego_width = 2.4;  // the ego's footprint, m
  // Per car (nullptr: car_length / 2 and car_width / 2 for every car): half its length and
  // width, m. HalfLength / HalfWidth read them.
  const double* car_half_length = nullptr;
  const double* car_half_width = nullptr;
  double HalfLength(int c) const {
    return car_half_length != nullptr ? car_half_length[c] : 0.5 * car_length;
  }
  double HalfWidth(int c) const {
    return car_half_width != nullptr ? car_half_width[c] : 0.5 * car_width;
  }
  // The largest HalfLength and HalfWidth of the cars (bounds for broad phases), m.
  double max_half_length = 2.4, max_half_width = 1.2;
  // The goals to reach (none on the Udacity track), times relative to the start state.
  int num_goals = 0;
  const GoalRegion* goals = nullptr;
  // Reaches of the broad-phase masks in CostInput (m), tighter first: see NearCars.
  double near_lateral[2] = {0, 0};
  double near_longitudinal[2] = {0, 0};
};

// Longitudinal families: quartic velocity keeping, quintic following (time-gap law) and
// stopping, constant-deceleration braking to a lower speed (the strongest, fastest braking
// the lattice can express; Apollo's backup profiles) and constant-acceleration runs up to a
// lane's limit (the quickest way up that the acceleration and jerk limits allow).
enum class LonKind : int {
  kVelocityKeeping = 0, kFollowing = 1, kStopping = 2, kBraking = 3, kAccelerating = 4
};

// One candidate, as sampled for scoring (struct of arrays, ctx.num_samples long).
struct CostInput {
  const double* s = nullptr;  // m
  const double* s_d = nullptr;
  const double* s_dd = nullptr;
  const double* d = nullptr;  // m
  const double* d_d = nullptr;
  const double* d_dd = nullptr;
  double lon_duration = 0, lat_duration = 0;  // s
  // Integrals of squared jerk over each polynomial's duration (m^2/s^5).
  double lon_jerk_squared = 0, lat_jerk_squared = 0;
  double end_speed = 0;  // s-speed at the end of the longitudinal polynomial, m/s
  double end_d = 0;      // m
  int target_lane = 0;
  LonKind kind = LonKind::kVelocityKeeping;
  // Optional broad phase (nullptr: none). Bit c of near_lat[m][k] is set for every car c < 64
  // with |ctx.car_d[c * n + k] - d[k]| < ctx.near_lateral[m], bit c of near_lon[m][k] for every car with
  // |ctx.car_s[c * n + k] - s[k]| < ctx.near_longitudinal[m]. Each depends on one motion only,
  // so the planner computes them once per lateral or longitudinal trajectory, not per candidate.
  const std::uint64_t* near_lat[2] = {nullptr, nullptr};
  const std::uint64_t* near_lon[2] = {nullptr, nullptr};
};

// The broad-phase masks a term may use for given reaches: the tightest of CostInput::near_lat and
// near_lon that cover them (either may be absent: then that direction does not filter). Choose
// once per candidate, then visit the cars near each sample. A superset: terms still apply their
// exact test. Cars are visited in index order either way.
class NearCars {
 public:
  NearCars(const CostContext& ctx, const CostInput& in, double lateral, double longitudinal)
      : lat_(Pick(in.near_lat, ctx.near_lateral, lateral)),
        lon_(Pick(in.near_lon, ctx.near_longitudinal, longitudinal)),
        all_(ctx.num_cars >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << ctx.num_cars) - 1),
        num_cars_(ctx.num_cars) {}

  // Bit c set: car c may be near at sample k.
  std::uint64_t At(int k) const {
    std::uint64_t m = all_;
    if (lat_ != nullptr) m &= lat_[k];
    if (lon_ != nullptr) m &= lon_[k];
    return m;
  }
  // Whether any car may be near at any of the n samples.
  bool Any(int n) const {
    if (num_cars_ == 0) return false;
    if (lat_ == nullptr && lon_ == nullptr) return true;
    std::uint64_t any = 0;
    for (int k = 0; k < n; ++k) any |= At(k);
    return any != 0;
  }
  // Calls fn(c) for the cars near sample k until fn returns false.
  template <typename Fn>
  void ForEach(int k, Fn&& fn) const {
    if (num_cars_ > 64) {  // beyond the masks' reach: every car
      for (int c = 0; c < num_cars_; ++c) {
        if (!fn(c)) return;
      }
      return;
    }
    for (std::uint64_t m = At(k); m != 0; m &= m - 1) {
      if (!fn(std::countr_zero(m))) return;
    }
  }

 private:
  static const std::uint64_t* Pick(const std::uint64_t* const masks[2], const double reaches[2],
                                   double reach) {
    for (int i = 0; i < 2; ++i) {
      if (masks[i] != nullptr && reach < reaches[i]) return masks[i];
    }
    return nullptr;
  }
  const std::uint64_t* lat_;
  const std::uint64_t* lon_;
  std::uint64_t all_;
  int num_cars_;
};

// m: the broad-phase reaches the planner builds its masks with, tighter first. Laterally: the
// buffer term's same-lane test; the collision term's boxes up to a ~20 degree heading.
// Longitudinally: the collision term's boxes; the buffer term's desired gap up to ~50 m. A term
// that needs more reach than a mask covers is handed every car instead (NearCars).
inline constexpr double kNearLateral[2] = {3.2, 4.5};
inline constexpr double kNearLongitudinal[2] = {8.0, 60.0};

// Builds one trajectory's pair of broad-phase masks (CostInput::near_lat or near_lon): bit c of
// near[k] (of near[n + k]) is set when |cars[c * stride + k] - x[k]| < reach[0] (reach[1]),
// for cars c < num_cars <= 64, with x the trajectory's d (or s) at the n samples and cars the
// cars' rows of d (or s) at the same samples. Four samples at a time, car by car, the masks in
// registers until every car is in (SSE2 where it is there).
inline void FillNearMasks(const double* x, int n, int num_cars, const double reach[2],
                          const double* cars, int stride, std::uint64_t* near) {
  const int count = std::min(num_cars, 64);
  int k0 = 0;
#if defined(__SSE2__)
  const __m128d r0 = _mm_set1_pd(reach[0]), r1 = _mm_set1_pd(reach[1]);
  const __m128d sign = _mm_set1_pd(-0.0);
  for (; k0 + 4 <= n; k0 += 4) {
    const __m128d xa = _mm_loadu_pd(x + k0), xb = _mm_loadu_pd(x + k0 + 2);
    __m128i a0 = _mm_setzero_si128(), b0 = a0, a1 = a0, b1 = a0;
    for (int c = 0; c < count; ++c) {
      const __m128i bit = _mm_set1_epi64x(static_cast<long long>(std::uint64_t{1} << c));
      const double* row = cars + static_cast<std::ptrdiff_t>(c) * stride + k0;
      // |car - x| < reach: the same comparison, lane by lane (NaN compares false).
      const __m128d da = _mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(row), xa));
      const __m128d db = _mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(row + 2), xb));
      a0 = _mm_or_si128(a0, _mm_and_si128(_mm_castpd_si128(_mm_cmplt_pd(da, r0)), bit));
      b0 = _mm_or_si128(b0, _mm_and_si128(_mm_castpd_si128(_mm_cmplt_pd(db, r0)), bit));
      a1 = _mm_or_si128(a1, _mm_and_si128(_mm_castpd_si128(_mm_cmplt_pd(da, r1)), bit));
      b1 = _mm_or_si128(b1, _mm_and_si128(_mm_castpd_si128(_mm_cmplt_pd(db, r1)), bit));
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(near + k0), a0);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(near + k0 + 2), b0);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(near + n + k0), a1);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(near + n + k0 + 2), b1);
  }
#endif
  // The rest (the last samples), car-major.
  std::fill(near + k0, near + n, std::uint64_t{0});
  std::fill(near + n + k0, near + 2 * n, std::uint64_t{0});
  for (int c = 0; c < count; ++c) {
    const std::uint64_t bit = std::uint64_t{1} << c;
    const double* row = cars + static_cast<std::ptrdiff_t>(c) * stride;
    for (int k = k0; k < n; ++k) {
      const double dist = std::abs(row[k] - x[k]);
      near[k] |= dist < reach[0] ? bit : 0;
      near[n + k] |= dist < reach[1] ? bit : 0;
    }
  }
}

// A tunable parameter a term declares, with its default and a sensible range.
struct CostParamSpec {
  std::string key;
  double default_value = 0, lo = 0, hi = 0;
  bool log_scale = false;
};

class CostTerm {
 public:
  virtual ~CostTerm() = default;
  // The term's parameters (none by default). Keys are plain identifiers.
  virtual std::vector<CostParamSpec> ParamSpecs() const { return {}; }
  // Receives one value per ParamSpecs() entry, in that order, each within [lo, hi].
  virtual void Configure(std::span<const double> values) { (void)values; }
  // The unweighted cost: finite and >= 0 for any finite input. Must not allocate.
  virtual double Evaluate(const CostContext& ctx, const CostInput& in) const = 0;
  // Whether Evaluate is costly (it visits the traffic at every sample). A planner may then leave
  // the term out of a first, cheap lower bound of the total (CostSet::LowerBound) and evaluate it
  // only for the candidates that bound cannot rule out. Changes no value.
  virtual bool Expensive() const { return false; }
  // For an Expensive() term: a cheap lower bound of Evaluate for the same input (finite, >= 0,
  // never above Evaluate; NaN only where Evaluate is), which the bounds that leave the term out
  // (CostSet::LowerBound, SumOf) count in its place. 0 by default. Must not allocate.
  virtual double LowerBound(const CostContext& ctx, const CostInput& in) const {
    (void)ctx;
    (void)in;
    return 0.0;
  }
  // Whether Evaluate reads the input sample by sample (its cost grows with num_samples), where
  // the others read a few numbers (durations, the end state, the jerk integrals, the target
  // lane). A planner may then leave such a term out of a coarser first bound too
  // (CostSet::CoarseLowerBound) and evaluate it only for the candidates that bound cannot rule
  // out. Changes no value.
  virtual bool Sampled() const { return false; }
  // Whether Evaluate reads nothing of the input but in.target_lane: within one context, every
  // candidate bound for a lane has the same value, so a caller may keep it per lane
  // (CostSet::LaneMemo). Changes no value.
  virtual bool LaneOnly() const { return false; }
};

}  // namespace frenetic::cost

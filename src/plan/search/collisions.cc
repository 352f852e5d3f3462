#include "plan/search/collisions.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace frenetic::plan::search {
namespace {

// m[j] for j in [1, n]: bit c set unless |cars[c * w + j] - x[j]| - extra[c] > reach[j] (NaN
// passes), for cars c < num_cars <= 64. Four steps at a time, car by car, the masks in SSE2
// registers until every car is in; the rest car by car over the last steps. The scoring's
// cost::FillNearMasks is built the same way but is not this test: a reach per step here
// (FirstCollision's, from the step's speed), and a car at a NaN distance is kept (HitsAt then
// decides), where a broad-phase mask leaves it out.
void ReachMasks(const double* x, const double* reach, const double* cars, int w, int n,
                int num_cars, const double* extra, std::uint64_t* m) {
  int j = 1;
#if defined(__SSE2__)
  const __m128d sign = _mm_set1_pd(-0.0);
  for (; j + 3 <= n; j += 4) {
    const __m128d xa = _mm_loadu_pd(x + j), xb = _mm_loadu_pd(x + j + 2);
    const __m128d ra = _mm_loadu_pd(reach + j), rb = _mm_loadu_pd(reach + j + 2);
    __m128i a = _mm_setzero_si128(), b = a;
    for (int car = 0; car < num_cars; ++car) {
      const __m128i bit = _mm_set1_epi64x(static_cast<long long>(std::uint64_t{1} << car));
      const double* row = cars + static_cast<std::ptrdiff_t>(car) * w + j;
      const __m128d ex = _mm_set1_pd(extra[car]);
      const __m128d da = _mm_sub_pd(_mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(row), xa)), ex);
      const __m128d db = _mm_sub_pd(_mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(row + 2), xb)), ex);
      // !(|d| > reach): the same test, lane by lane (NaN passes).
      a = _mm_or_si128(a, _mm_and_si128(_mm_castpd_si128(_mm_cmpngt_pd(da, ra)), bit));
      b = _mm_or_si128(b, _mm_and_si128(_mm_castpd_si128(_mm_cmpngt_pd(db, rb)), bit));
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(m + j), a);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(m + j + 2), b);
  }
#endif
  const int j0 = j;
  for (; j <= n; ++j) m[j] = 0;
  for (int car = 0; car < num_cars; ++car) {
    const double* row = cars + static_cast<std::ptrdiff_t>(car) * w;
    const std::uint64_t bit = std::uint64_t{1} << car;
    for (j = j0; j <= n; ++j) m[j] |= std::abs(row[j] - x[j]) - extra[car] > reach[j] ? 0 : bit;
  }
}

// m[j] for j in [1, n] loses bit c when |cars[c * w + j] - x[j]| - extra[c * w + j] > reach[j]
// (NaN keeps it), for cars c < num_cars <= 64: a per-step reach and a per-car-and-step extra.
// Two steps at a time, car by car, the bits to clear in SSE2 registers.
void NarrowMasks(const double* x, const double* reach, const double* cars, const double* extra,
                 int w, int n, int num_cars, std::uint64_t* m) {
  int j = 1;
#if defined(__SSE2__)
  const __m128d sign = _mm_set1_pd(-0.0);
  for (; j + 1 <= n; j += 2) {
    const __m128d xa = _mm_loadu_pd(x + j), ra = _mm_loadu_pd(reach + j);
    __m128i drop = _mm_setzero_si128();
    for (int car = 0; car < num_cars; ++car) {
      const __m128i bit = _mm_set1_epi64x(static_cast<long long>(std::uint64_t{1} << car));
      const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(car) * w + j;
      const __m128d da = _mm_sub_pd(_mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(cars + at), xa)),
                                    _mm_loadu_pd(extra + at));
      drop = _mm_or_si128(drop, _mm_and_si128(_mm_castpd_si128(_mm_cmpgt_pd(da, ra)), bit));
    }
    __m128i* mj = reinterpret_cast<__m128i*>(m + j);
    _mm_storeu_si128(mj, _mm_andnot_si128(drop, _mm_loadu_si128(mj)));
  }
#endif
  for (; j <= n; ++j) {
    std::uint64_t drop = 0;
    for (int car = 0; car < num_cars; ++car) {
      const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(car) * w + j;
      if (std::abs(cars[at] - x[j]) - extra[at] > reach[j]) drop |= std::uint64_t{1} << car;
    }
    m[j] &= ~drop;
  }
}

}  // namespace

CollisionChecker::CollisionChecker(const Settings& cfg, Workspace& ws) : cfg_(cfg), ws_(ws) {
  const std::size_t n_lon = ws_.lon.capacity(), n_lat = ws_.lat.capacity();
  const std::size_t w = ws_.n_steps + 1;
  lon_steps_.Resize(n_lon, static_cast<int>(w));
  lat_steps_.Resize(n_lat, static_cast<int>(w));
  lon_near_.assign(2 * n_lon * w, 0);
  lat_near_.assign(n_lat * w, 0);
  reach_.assign(w, 0.0);
  lat_reach_.assign(w, ws_.reach_d);
  lon_near_key_.assign(2 * n_lon, LonNearKey{});
  lat_near_stamp_.assign(n_lat, 0);
  lat_tight_.assign(n_lat * w, 0);
  lat_tight_stamp_.assign(n_lat, 0);
  lon_tight_stamp_.assign(n_lon, 0);
  lon_tight_ok_.assign(n_lon, 0);
  car_extent_d_.assign(ws_.step_d.size(), 0.0);
  tight_reach_.assign(w, 0.0);
  last_hit_.assign(2 * n_lon, LastHit{});
  lat_last_hit_.assign(n_lat, LastHit{});
  bare_hit_.assign(ws_.order.capacity(), 0);
  bare_epoch_.assign(ws_.order.capacity(), 0);
}

int CollisionChecker::BareContact(int c) {
  const auto uc = static_cast<std::size_t>(c);
  if (uc >= bare_hit_.size()) {  // beyond the sized candidates: measured, not kept
    return FirstCollision(StepsOf(c, 0.0, 1.0), 0.0, 1.0, nullptr, false);
  }
  if (bare_traffic_ != ws_.traffic_stamp || bare_candidates_ != ws_.candidate_stamp) {
    bare_traffic_ = ws_.traffic_stamp;
    bare_candidates_ = ws_.candidate_stamp;
    if (++epoch_ == 0) {  // wrapped: no stale entry may match
      std::fill(bare_epoch_.begin(), bare_epoch_.end(), 0);
      epoch_ = 1;
    }
  }
  if (bare_epoch_[uc] != epoch_) {
    // With CandidateCollides' narrower lateral test: it bounds the inflated boxes' extent, so a
    // car it leaves out fails HitsAt on bare boxes too.
    const StepStates reach = StepsOf(c, 0.0, 1.0);
    bare_hit_[uc] = FirstCollision(reach.WithNearLat(TightLatNear(ws_.cand_lon[c], ws_.cand_lat[c])),
                                   0.0, 1.0, nullptr, false);
    bare_epoch_[uc] = epoch_;
  }
  return bare_hit_[uc];
}

bool CollisionChecker::BareContactImpliesCollision() const {
  const Settings::Check& k = cfg_.check;
  return k.margin_s >= 0 && k.margin_d >= 0 && k.margin_behind >= 0 && k.behind_time >= 0 &&
         k.headway_min >= 0;
}

bool CollisionChecker::SampleSteps(const traj::Trajectory1d& tr, int i, BundleRows& rows) {
  // The time FirstCollision's callers sample at: tick j * collision_step.
  const int step = ws_.collision_step;
  return rows.Sample(tr, i, [step](int j) { return (j * step) * kTickSeconds; });
}

StepStates CollisionChecker::StepsOf(int c, double margin_scale, double behind_scale) {
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const int w = ws_.n_steps + 1;
  const int num_cars =
      std::min(ws_.num_check_cars, 64);  // ghosts too; FirstCollision may drop them
  // The reach tests of FirstCollision, on the same values (a car is kept unless it fails).
  const bool new_lon = SampleSteps(ws_.lon[i].traj, i, lon_steps_);
  // The bare boxes' masks (the least-harm tests) apart from the others', so that the two
  // kinds of test taking turns on a bundle do not measure its masks anew each time.
  const std::size_t slot = (margin_scale == 0.0 && behind_scale == 1.0 ? lon_near_key_.size() / 2
                                                                         : 0) + i;
  std::uint64_t* const lon_near = &lon_near_[slot * w];
  LonNearKey& lk = lon_near_key_[slot];
  if (new_lon) {  // both kinds are stale
    lon_near_key_[i].stamp = lon_near_key_[lon_near_key_.size() / 2 + i].stamp = 0;
  }
  // No branch on which cars pass (ReachMasks).
  if (lk.stamp != ws_.traffic_stamp || lk.margin_scale != margin_scale ||
      lk.behind_scale != behind_scale) {
    for (int j = 1; j <= ws_.n_steps; ++j) {
      reach_[j] = ReachS(lon_steps_.v[i * w + j], margin_scale, behind_scale);
    }
    ReachMasks(&lon_steps_.p[i * w], reach_.data(), ws_.step_s.data(), w, ws_.n_steps, num_cars,
               ws_.car_reach_s.data(), lon_near);
    lk = {ws_.traffic_stamp, margin_scale, behind_scale};
    lon_tight_stamp_[i] = 0;
  }
  const bool new_lat = SampleSteps(ws_.lat[k].traj, k, lat_steps_);
  if (new_lat || lat_near_stamp_[k] != ws_.traffic_stamp) {
    if (lat_reach_[1] != ws_.reach_d) std::fill(lat_reach_.begin(), lat_reach_.end(), ws_.reach_d);
    ReachMasks(&lat_steps_.p[k * w], lat_reach_.data(), ws_.step_d.data(), w, ws_.n_steps, num_cars,
               ws_.car_reach_d.data(), &lat_near_[k * w]);
    lat_near_stamp_[k] = ws_.traffic_stamp;
    lat_tight_stamp_[k] = 0;
  }
  return {lon_steps_.p.data() + i * w, lon_steps_.v.data() + i * w, lat_steps_.p.data() + k * w,
          lat_steps_.v.data() + k * w, ws_.collision_step, lon_near,
          lat_near_.data() + k * w};
}

CollisionChecker::Rows CollisionChecker::StepRows(int c) {
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const int w = ws_.n_steps + 1;
  // A bundle sampled anew here has no reach tests yet (traffic_stamp is never 0 in a cycle).
  if (SampleSteps(ws_.lon[i].traj, i, lon_steps_)) {
    lon_near_key_[i].stamp = lon_near_key_[lon_near_key_.size() / 2 + i].stamp = 0;
  }
  if (SampleSteps(ws_.lat[k].traj, k, lat_steps_)) {
    lat_near_stamp_[k] = 0;
  }
  return {lon_steps_.p.data() + i * w, lat_steps_.p.data() + k * w};
}

const std::uint64_t* CollisionChecker::TightLatNear(int i, int k) {
  const int w = ws_.n_steps + 1, n_steps = ws_.n_steps;
  const std::uint64_t stamp = ws_.traffic_stamp;
  const int num_cars = std::min(ws_.num_check_cars, 64);
  if (tight_stamp_ != stamp) {
    // A cap on the margins that holds for every lon slot of ordinary speeds (the margin grows
    // with the ego's s' ahead and shrinks with it behind: the ends of the range bound it).
    const double top = std::max(cfg_.limits.max_speed, ws_.start.s_d) + 5.0;
    tight_margin_ = std::max(Widest(0.0, 1.0, 1.0), Widest(top, 1.0, 1.0));
    // The car's extent along d in HitsAt (its box's half length times |heading's d| plus its
    // half width times heading's s), with the margin at most tight_margin_.
    for (int car = 0; car < num_cars; ++car) {
      for (int j = 1; j <= n_steps; ++j) {
        const int at = car * w + j;
        car_extent_d_[at] = (ws_.car_hl[car] + tight_margin_) * std::abs(ws_.step_dir_d[at]) +
                            (ws_.car_hw[car] + cfg_.check.margin_d) * ws_.step_dir_s[at];
      }
    }
    tight_stamp_ = stamp;
  }
  if (!std::isfinite(tight_margin_)) return &lat_near_[k * w];
  if (lon_tight_stamp_[i] != stamp) {
    bool ok = true;
    for (int j = 1; j <= n_steps && ok; ++j) {
      const double s_d = lon_steps_.v[i * w + j];
      ok = std::isfinite(s_d) && Widest(s_d, 1.0, 1.0) <= tight_margin_;
    }
    lon_tight_ok_[i] = ok;
    lon_tight_stamp_[i] = stamp;
  }
  if (!lon_tight_ok_[i]) return &lat_near_[k * w];
  if (lat_tight_stamp_[k] != stamp) {
    // The ego's extent along d: half length times |heading's d| plus half width times heading's
    // s, for a unit heading (s', d') with s' >= 0.5 (EgoAt): |heading's d| is at most
    // |d'| / sqrt(0.25 + d'^2) =: u, and the extent at most hl u + hw sqrt(1 - u^2) while u
    // is below hl / r, r (the half diagonal) past it. Plus HitsAt's 1 mm, and 1e-9 m for the
    // rounding of both sides; a d' that is not finite keeps every car.
    const double hl = 0.5 * cfg_.check.ego_length, hw = 0.5 * cfg_.check.ego_width;
    const double r = std::hypot(hl, hw);
    for (int j = 1; j <= n_steps; ++j) {
      const double vd = lat_steps_.v[k * w + j];
      double ego = std::numeric_limits<double>::infinity();
      if (std::isfinite(vd)) {
        const double u = std::abs(vd) < 1e6 ? std::abs(vd) / std::sqrt(0.25 + vd * vd) : 1.0;
        ego = u >= hl / r ? r : hl * u + hw * std::sqrt(std::max(0.0, 1.0 - u * u));
      }
      tight_reach_[j] = ego + 1e-3 + 1e-9;
      lat_tight_[k * w + j] = lat_near_[k * w + j];
    }
    // HitsAt's d-axis separation for every margin up to tight_margin_ (NaN keeps the car).
    NarrowMasks(&lat_steps_.p[k * w], tight_reach_.data(), ws_.step_d.data(), car_extent_d_.data(),
                w, n_steps, num_cars, &lat_tight_[k * w]);
    lat_tight_stamp_[k] = stamp;
  }
  return &lat_tight_[k * w];
}

bool CollisionChecker::CandidateCollides(int c) {
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const int w = ws_.n_steps + 1;
  // A hit at a remembered step and car is one FirstCollision finds too, at that step at the
  // latest (the car passes the same reach tests): the lon bundle's last two, its lat bundle's
  // last one.
  LastHit* const hints[3] = {&last_hit_[2 * i], &last_hit_[2 * i + 1], &lat_last_hit_[k]};
  // A swerve into its goal region is checked up to its end only.
  const int n_steps = ws_.CheckSteps(c);
  bool sampled = false;
  for (const LastHit* h : hints) {
    if (h->stamp != ws_.traffic_stamp || h->step > n_steps) continue;
    if (!sampled) StepRows(c);
    sampled = true;
    const int j = h->step;
    const traj::FrenetState st{lon_steps_.p[i * w + j], lon_steps_.v[i * w + j], 0.0,
                               lat_steps_.p[k * w + j], lat_steps_.v[k * w + j], 0.0};
    if (HitsAt(EgoAt(st, 1.0, 1.0), j, h->car, 1.0, 1.0)) return true;
  }
  // Every step then, from the first hint's on (a collision mostly lasts a few steps: one near
  // a neighbour's is found sooner); any hit answers.
  const StepStates reach = StepsOf(c);  // the rows and the reach masks
  // With the narrower lateral test: the cars it leaves out fail HitsAt anyway.
  const StepStates steps = reach.WithNearLat(TightLatNear(i, k));
  const std::uint64_t cars = CarMask(true);
  const int from =
      hints[0]->stamp == ws_.traffic_stamp && hints[0]->step <= n_steps ? hints[0]->step : 1;
  int hit = 0, car = -1;
  for (int q = 0; q < n_steps && hit == 0; ++q) {
    const int j = (from - 1 + q) % n_steps + 1;
    car = FirstCarHit(steps, j, cars, 1.0, 1.0);
    if (car >= 0) hit = j;
  }
  if (hit == 0) return false;
  const LastHit now{ws_.traffic_stamp, hit, car};
  last_hit_[2 * i + 1] = last_hit_[2 * i];
  last_hit_[2 * i] = now;
  lat_last_hit_[k] = now;
  return true;
}

}  // namespace frenetic::plan::search

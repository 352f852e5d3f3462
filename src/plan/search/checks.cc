#include "plan/search/checks.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace frenetic::plan::search {
namespace {

// m[j] for j in [1, n]: bit c set unless |cars[c * w + j] - x[j]| - extra[c] > reach[j] (NaN
// passes), for cars c < num_cars <= 64. Four steps at a time, car by car, the masks in SSE2 registers until
// every car is in; the rest car by car over the last steps. The scoring's
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

Checker::Checker(const Settings& cfg, const map::ReferenceLine& line, Workspace& ws)
    : cfg_(cfg),
      line_(line),
      ws_(ws),
      xy_(kHistory + 64 + static_cast<int>(std::ceil(cfg.check_horizon / kTickSeconds)) +
              cfg.output_points,
          cfg.vehicle) {
  const int path_cap = kHistory + cfg.output_points + ws_.n_ticks + 8;
  chk_x_.assign(path_cap, 0.0);
  chk_y_.assign(path_cap, 0.0);
  const std::size_t n_lon = ws_.lon.capacity(), n_lat = ws_.lat.capacity();
  const std::size_t w = ws_.n_steps + 1;
  lon_key_.resize(n_lon);
  lat_key_.resize(n_lat);
  lon_have_.assign(n_lon, 0);
  lat_have_.assign(n_lat, 0);
  for (auto* v : {&lon_s_, &lon_sd_}) v->assign(n_lon * w, 0.0);
  for (auto* v : {&lat_d_, &lat_dd_}) v->assign(n_lat * w, 0.0);
  lon_near_.assign(n_lon * w, 0);
  lat_near_.assign(n_lat * w, 0);
  reach_.assign(w, 0.0);
  lat_reach_.assign(w, ws_.reach_d);
  lon_near_key_.assign(n_lon, LonNearKey{});
  lat_near_stamp_.assign(n_lat, 0);
  lat_tight_.assign(n_lat * w, 0);
  lat_tight_stamp_.assign(n_lat, 0);
  lon_tight_stamp_.assign(n_lon, 0);
  lon_tight_ok_.assign(n_lon, 0);
  car_extent_d_.assign(ws_.step_d.size(), 0.0);
  tight_reach_.assign(w, 0.0);
  verdicts_.resize(ws_.order.capacity());
  last_hit_.assign(2 * n_lon, LastHit{});
  lat_last_hit_.assign(n_lat, LastHit{});
  const std::size_t wt = ws_.n_ticks + 1;
  for (auto [rows, n] : {std::pair{&lon_ticks_, n_lon}, std::pair{&lat_ticks_, n_lat}}) {
    rows->key.resize(n);
    rows->have.assign(n, 0);
    for (auto* v : {&rows->p, &rows->v, &rows->a}) v->assign(n * wt, 0.0);
  }
  lon_centre_.resize(n_lon * wt);
  lon_centre_have_.assign(n_lon, 0);
}

bool Checker::SampleTicks(const traj::Trajectory1d& tr, int i, TickRows& rows) {
  if (rows.have[i] && std::memcmp(&rows.key[i], &tr, sizeof(tr)) == 0) return false;
  const int w = ws_.n_ticks + 1;
  tr.Sample(1, ws_.n_ticks + 1, [](int t) { return 0.0 + t * kTickSeconds; },  // FillTicks' time
            &rows.p[i * w], &rows.v[i * w], &rows.a[i * w]);
  std::memcpy(&rows.key[i], &tr, sizeof(tr));
  rows.have[i] = 1;
  return true;
}

bool Checker::SampleSteps(const traj::Trajectory1d& tr, int i,
                          std::vector<traj::Trajectory1d>& key, std::vector<char>& have,
                          std::vector<double>& p, std::vector<double>& v) {
  if (have[i] && std::memcmp(&key[i], &tr, sizeof(tr)) == 0) return false;
  const int w = ws_.n_steps + 1;
  // The time FirstCollision's callers sample at: tick j * collision_step.
  const int step = ws_.collision_step;
  tr.Sample(1, ws_.n_steps + 1, [step](int j) { return (j * step) * kTickSeconds; }, &p[i * w],
            &v[i * w], nullptr);
  std::memcpy(&key[i], &tr, sizeof(tr));
  have[i] = 1;
  return true;
}

StepStates Checker::StepsOf(int c, double margin_scale, double behind_scale) {
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const int w = ws_.n_steps + 1;
  const int num_cars = std::min(ws_.num_check_cars, 64);  // ghosts too; FirstCollision may drop them
  // The reach tests of FirstCollision, on the same values (a car is kept unless it fails).
  const bool new_lon = SampleSteps(ws_.lon[i].traj, i, lon_key_, lon_have_, lon_s_, lon_sd_);
  LonNearKey& lk = lon_near_key_[i];
  // No branch on which cars pass (ReachMasks).
  if (new_lon || lk.stamp != ws_.traffic_stamp || lk.margin_scale != margin_scale ||
      lk.behind_scale != behind_scale) {
    for (int j = 1; j <= ws_.n_steps; ++j) {
      reach_[j] = ReachS(lon_sd_[i * w + j], margin_scale, behind_scale);
    }
    ReachMasks(&lon_s_[i * w], reach_.data(), ws_.step_s.data(), w, ws_.n_steps, num_cars,
               ws_.car_reach_s.data(), &lon_near_[i * w]);
    lk = {ws_.traffic_stamp, margin_scale, behind_scale};
    lon_tight_stamp_[i] = 0;
  }
  const bool new_lat = SampleSteps(ws_.lat[k].traj, k, lat_key_, lat_have_, lat_d_, lat_dd_);
  if (new_lat || lat_near_stamp_[k] != ws_.traffic_stamp) {
    if (lat_reach_[1] != ws_.reach_d) std::fill(lat_reach_.begin(), lat_reach_.end(), ws_.reach_d);
    ReachMasks(&lat_d_[k * w], lat_reach_.data(), ws_.step_d.data(), w, ws_.n_steps, num_cars,
               ws_.car_reach_d.data(), &lat_near_[k * w]);
    lat_near_stamp_[k] = ws_.traffic_stamp;
    lat_tight_stamp_[k] = 0;
  }
  return {lon_s_.data() + i * w, lon_sd_.data() + i * w, lat_d_.data() + k * w,
          lat_dd_.data() + k * w, ws_.collision_step, lon_near_.data() + i * w,
          lat_near_.data() + k * w};
}

Checker::Rows Checker::StepRows(int c) {
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const int w = ws_.n_steps + 1;
  // A bundle sampled anew here has no reach tests yet (traffic_stamp is never 0 in a cycle).
  if (SampleSteps(ws_.lon[i].traj, i, lon_key_, lon_have_, lon_s_, lon_sd_)) {
    lon_near_key_[i].stamp = 0;
  }
  if (SampleSteps(ws_.lat[k].traj, k, lat_key_, lat_have_, lat_d_, lat_dd_)) {
    lat_near_stamp_[k] = 0;
  }
  return {lon_s_.data() + i * w, lat_d_.data() + k * w};
}

const std::uint64_t* Checker::TightLatNear(int i, int k) {
  const int w = ws_.n_steps + 1, n_steps = ws_.n_steps;
  const std::uint64_t stamp = ws_.traffic_stamp;
  const int num_cars = std::min(ws_.num_check_cars, 64);
  if (tight_stamp_ != stamp) {
    // A cap on the margins that holds for every lon slot of ordinary speeds (the margin grows
    // with the ego's s' ahead and shrinks with it behind: the ends of the range bound it).
    const double top = std::max(cfg_.max_speed, ws_.start.s_d) + 5.0;
    tight_margin_ = std::max(Widest(0.0, 1.0, 1.0), Widest(top, 1.0, 1.0));
    // The car's extent along d in HitsAt (its box's half length times |heading's d| plus its
    // half width times heading's s), with the margin at most tight_margin_.
    for (int car = 0; car < num_cars; ++car) {
      for (int j = 1; j <= n_steps; ++j) {
        const int at = car * w + j;
        car_extent_d_[at] = (ws_.car_hl[car] + tight_margin_) * std::abs(ws_.step_dir_d[at]) +
                            (ws_.car_hw[car] + cfg_.margin_d) * ws_.step_dir_s[at];
      }
    }
    tight_stamp_ = stamp;
  }
  if (!std::isfinite(tight_margin_)) return &lat_near_[k * w];
  if (lon_tight_stamp_[i] != stamp) {
    bool ok = true;
    for (int j = 1; j <= n_steps && ok; ++j) {
      const double s_d = lon_sd_[i * w + j];
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
    const double hl = 0.5 * cfg_.ego_length, hw = 0.5 * cfg_.ego_width;
    const double r = std::hypot(hl, hw);
    for (int j = 1; j <= n_steps; ++j) {
      const double vd = lat_dd_[k * w + j];
      double ego = std::numeric_limits<double>::infinity();
      if (std::isfinite(vd)) {
        const double u = std::abs(vd) < 1e6 ? std::abs(vd) / std::sqrt(0.25 + vd * vd) : 1.0;
        ego = u >= hl / r ? r : hl * u + hw * std::sqrt(std::max(0.0, 1.0 - u * u));
      }
      tight_reach_[j] = ego + 1e-3 + 1e-9;
      lat_tight_[k * w + j] = lat_near_[k * w + j];
    }
    // HitsAt's d-axis separation for every margin up to tight_margin_ (NaN keeps the car).
    NarrowMasks(&lat_d_[k * w], tight_reach_.data(), ws_.step_d.data(), car_extent_d_.data(), w,
                n_steps, num_cars, &lat_tight_[k * w]);
    lat_tight_stamp_[k] = stamp;
  }
  return &lat_tight_[k * w];
}

bool Checker::CandidateCollides(int c) {
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
    const traj::FrenetState st{lon_s_[i * w + j], lon_sd_[i * w + j], 0.0,
                               lat_d_[k * w + j], lat_dd_[k * w + j], 0.0};
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

void Checker::FillTicks(const traj::FrenetTrajectory& tr, double t0) {
  for (int i = 1; i <= ws_.n_ticks; ++i) {
    const traj::FrenetState st = tr.At(t0 + i * kTickSeconds);
    ws_.tk_s[i] = st.s;
    ws_.tk_sd[i] = st.s_d;
    ws_.tk_sdd[i] = st.s_dd;
    ws_.tk_d[i] = st.d;
    ws_.tk_dd[i] = st.d_d;
    ws_.tk_ddd[i] = st.d_dd;
  }
}

void Checker::FillTicksForLimits(const traj::FrenetTrajectory& tr) {
  const auto time = [](int t) { return 0.0 + t * kTickSeconds; };  // FillTicks' time
  tr.lon.Sample(1, ws_.n_ticks + 1, time, ws_.tk_s.data(), ws_.tk_sd.data(), nullptr);
  tr.lat.Sample(1, ws_.n_ticks + 1, time, ws_.tk_d.data(), ws_.tk_dd.data(), nullptr);
}

void Checker::SetXyPrefix(const double* hist_x, const double* hist_y, int hist_n,
                          const double* kept_x, const double* kept_y, int kept) {
  int n = 0;
  for (int i = 0; i < hist_n; ++i, ++n) {
    chk_x_[n] = hist_x[i];
    chk_y_[n] = hist_y[i];
  }
  for (int i = 0; i < kept; ++i, ++n) {
    chk_x_[n] = kept_x[i];
    chk_y_[n] = kept_y[i];
  }
  first_new_ = n;
  xy_.SetPrefix(chk_x_.data(), chk_y_.data(), n);
  ++prefix_stamp_;
}

Checker::ReadRange Checker::ReadBetween(const double* s, const double* d, int prev, int i) const {
  const double d_lo = std::min(d[prev], d[i]), d_hi = std::max(d[prev], d[i]);
  const map::ReferenceLine::OffsetRange r =
      line_.ChordOffset(std::min(s[prev], s[i]), std::max(s[prev], s[i]), 0.5 * (d_lo + d_hi));
  return {d_lo + r.lo, d_hi + r.hi};
}

double Checker::EdgeExcess(double s0, double s1, const ReadRange& read) const {
  // The bins of the workspace's edge table that [s0, s1] overlaps (clamped to the table).
  const int bins = static_cast<int>(ws_.edge_lo.size());
  const double x0 = (std::min(s0, s1) - ws_.edge_s0) / Workspace::kEdgeBin;
  const double x1 = (std::max(s0, s1) - ws_.edge_s0) / Workspace::kEdgeBin;
  if (!(x0 == x0) || !(x1 == x1)) return 1e9;  // NaN s: off any road
  const int b0 = static_cast<int>(std::clamp(std::floor(x0), 0.0, bins - 1.0));
  const int b1 = static_cast<int>(std::clamp(std::floor(x1), 0.0, bins - 1.0));
  double lo = -1e9, hi = 1e9;
  for (int b = b0; b <= b1; ++b) {
    if (!(ws_.edge_lo[b] == ws_.edge_lo[b])) return 1e9;  // no lane there
    lo = std::max(lo, ws_.edge_lo[b]);
    hi = std::min(hi, ws_.edge_hi[b]);
  }
  const double inset = 0.5 * cfg_.ego_width + cfg_.edge_margin;
  return std::max(lo + inset - read.lo, read.hi - (hi - inset));
}

double Checker::CandidateViolation(int c, Reject* reason) {
  return CandidateMeasure(c, reason, false);
}

bool Checker::CandidateBreaksLimits(int c) { return CandidateMeasure(c, nullptr, true) > 0; }

double Checker::CandidateMeasure(int c, Reject* reason, bool any) {
  const traj::FrenetTrajectory tr = ws_.Candidate(c);
  Verdict* v = c < static_cast<int>(verdicts_.size()) ? &verdicts_[c] : nullptr;
  if (v != nullptr && (any || !v->any) && v->prefix_stamp == prefix_stamp_ &&
      v->straddle == ws_.straddle_at_start && std::memcmp(&v->tr, &tr, sizeof(tr)) == 0) {
    if (reason != nullptr) *reason = v->why;
    return v->worst;
  }
  // FillTicks' values, from the bundles' rows: the candidates of a bundle share its ticks and
  // the centre line there.
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  if (SampleTicks(tr.lon, i, lon_ticks_)) lon_centre_have_[i] = 0;
  SampleTicks(tr.lat, k, lat_ticks_);
  const int w = ws_.n_ticks + 1;
  Reject why = Reject::kCount;
  const double worst = Measure(&why, true,
                               {&lon_ticks_.p[i * w], &lon_ticks_.v[i * w], &lat_ticks_.p[k * w],
                                nullptr, i, ws_.CheckTicks(c)},
                               any);
  // An early answer (worst > 0 before every limit was measured) is not the whole verdict.
  const bool partial = any && worst > 0;
  if (reason != nullptr) *reason = why;
  if (v != nullptr) *v = {tr, prefix_stamp_, ws_.straddle_at_start, why, worst, partial};
  return worst;
}

int Checker::BuildXyPath(const Ticks& ticks) {
  int n = first_new_;
  const int n_ticks = ticks.n > 0 ? ticks.n : ws_.n_ticks;
  for (int i = 1; i <= n_ticks; ++i, ++n) {
    // ToCartesian's x and y without its heading and curvature.
    const map::CentrePoint p = ticks.centre != nullptr ? ticks.centre[i] : line_.Centre(ticks.s[i]);
    chk_x_[n] = p.OffsetX(ticks.d[i]);
    chk_y_[n] = p.OffsetY(ticks.d[i]);
  }
  return n;
}

double Checker::Violation(Reject* reason, bool lane_line) {
  return Measure(reason, lane_line, {ws_.tk_s.data(), ws_.tk_sd.data(), ws_.tk_d.data(), nullptr});
}

double Checker::Measure(Reject* reason, bool lane_line, const Ticks& ticks, bool any) {
  const int n_ticks = ticks.n > 0 ? ticks.n : ws_.n_ticks;
  const double* tk_s = ticks.s;
  const double* tk_d = ticks.d;
  double worst = -1e9;
  Reject why = Reject::kCount;
  auto take = [&](double v, Reject r) {
    if (!(v <= worst)) {  // NaN counts as a violation
      worst = Finite(v) ? v : 1e9;
      why = r;
    }
  };
  // d as the simulator reads it (from chords), bounded every 5 ticks over the s swept since
  // the previous check point.
  // The lane-line timer runs on, from the start state's count, while the read d may be astride
  // a line; a trajectory still astride at its end would stay there.
  // On a uniform road, the range of d read against d_min / d_max; on another, the largest
  // excess over the road's edges (EdgeExcess).
  double dmin = 1e9, dmax = -1e9, sdmin = 1e9, off_road = -1e9;
  int straddle = ws_.straddle_at_start, worst_straddle = straddle;
  for (int i = 1; i <= n_ticks; ++i) sdmin = std::min(sdmin, ticks.sd[i]);
  for (int prev = 1, i = std::min(5, n_ticks); n_ticks >= 1;
       prev = i, i = std::min(i + 5, n_ticks)) {
    const ReadRange read = ReadBetween(tk_s, tk_d, prev, i);
    if (cfg_.uniform_road) {
      dmin = std::min(dmin, read.lo);
      dmax = std::max(dmax, read.hi);
      straddle = StraddlesRead(cfg_, read.lo, read.hi) ? straddle + (i - prev) + (prev == 1) : 0;
      worst_straddle = std::max(worst_straddle, straddle);
    } else {
      off_road = std::max(off_road, EdgeExcess(tk_s[prev], tk_s[i], read));
    }
    if (any && ((lane_line && worst_straddle > kMaxStraddleTicks) || cfg_.d_min - dmin > 0 ||
                dmax - cfg_.d_max > 0 || off_road > 0)) {
      if (reason != nullptr) *reason = Reject::kCount;  // unknown: not measured in full
      return 1.0;  // a limit is broken (which one is worst is not known)
    }
    if (i == n_ticks) break;
  }
  if (straddle > 0) worst_straddle = 1 << 20;
  if (cfg_.uniform_road) off_road = std::max(cfg_.d_min - dmin, dmax - cfg_.d_max);
  take(off_road / cfg_.lane_width, Reject::kOffRoad);
  if (lane_line) {
    take(static_cast<double>(worst_straddle - kMaxStraddleTicks) / kMaxStraddleTicks,
         Reject::kLaneLine);
  }
  take(-sdmin - 0.05, Reject::kSpeed);  // never backwards
  if (worst > 0) {                      // already infeasible: skip the XY conversion
    if (reason != nullptr) *reason = why;
    return worst;
  }
  Ticks xy_ticks = ticks;
  if (ticks.lon_slot >= 0) {
    const int i = ticks.lon_slot, w = ws_.n_ticks + 1;  // the whole row, for every candidate
    if (!lon_centre_have_[i]) {
      for (int t = 1; t <= ws_.n_ticks; ++t) lon_centre_[i * w + t] = line_.Centre(ticks.s[t]);
      lon_centre_have_[i] = 1;
    }
    xy_ticks.centre = &lon_centre_[i * w];
  }
  const int n = BuildXyPath(xy_ticks);
  const XyMeasure m = xy_.MeasureWithPrefix(chk_x_.data(), chk_y_.data(), n, first_new_);
  take(m.max_speed / cfg_.max_speed - 1.0, Reject::kSpeed);
  take(m.max_accel / cfg_.max_accel - 1.0, Reject::kAcceleration);
  take(m.max_jerk / cfg_.max_jerk - 1.0, Reject::kJerk);
  if (cfg_.vehicle.any()) {
    // A vehicle's limits count as acceleration (steering angle: lateral; forward) and jerk
    // (the steering rate) limits.
    if (cfg_.vehicle.max_steer > 0) take(m.steer_ratio - 1.0, Reject::kAcceleration);
    if (cfg_.vehicle.max_accel > 0) take(m.forward_accel_ratio - 1.0, Reject::kAcceleration);
    if (cfg_.vehicle.max_steer_rate > 0) take(m.steer_rate_ratio - 1.0, Reject::kJerk);
  }
  if (reason != nullptr) *reason = worst > 0 ? why : Reject::kCount;
  return worst;
}

}  // namespace frenetic::plan::search

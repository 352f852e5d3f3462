// The search planner's choice when no candidate is feasible and clear of traffic with the
// safety margins: the least harmful feasible one, judged on bare car boxes (but still never
// cutting in front of a car behind in another lane) — among the collision-free ones the one that
// keeps farthest from every car, else the one whose first contact comes latest (more time for
// the others to react, and for the next cycles to find a way out).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "frenetic/traj/frenet.h"
#include "plan/search/collisions.h"
#include "plan/search/limits.h"
#include "plan/search/scoring.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// The part across the road of a separation as least harm's clearance counts it: a car at least
// side_clear to the side (Settings::Check::side_clear) is clear at that step whatever the gap
// along the road (1e9, as with no car), since it keeps its lane as the ego keeps its own.
inline double SidePart(double lat, double side_clear) { return lat < side_clear ? lat : 1e9; }

// The smallest separation (m) of the bare boxes of `tr` from any car of ws over the check
// horizon, in the Frenet frame with the boxes aligned to the lane: max(|ds| - ws.car_sep_s,
// |dd| - ws.car_sep_d), < 0 on overlap.
double Clearance(const Workspace& ws, const traj::FrenetTrajectory& tr);
// The same from the states at the collision-check steps (state_at(tick),
// CollisionChecker::StepsOf).
template <typename StateAt>
double ClearanceAt(const Workspace& ws, StateAt state_at) {
  double worst = 1e9;
  for (int j = 1; j <= ws.n_steps; ++j) {
    const traj::FrenetState st = state_at(j * ws.collision_step);
    for (int c = 0; c < ws.ctx.num_cars; ++c) {
      const int at = c * (ws.n_steps + 1) + j;
      const double sep =
          std::max(std::abs(ws.step_s[at] - st.s) - ws.car_sep_s[c],
                   SidePart(std::abs(ws.step_d[at] - st.d) - ws.car_sep_d[c], ws.side_clear));
      worst = std::min(worst, sep);
    }
  }
  return worst;
}

// The same from StepStates' rows, car by car over contiguous steps (the loops vectorise): the
// minimum of the same separations, and a minimum taken with `<` ignores NaN in any order (no
// separation is -0), so the same value.
inline double ClearanceAt(const Workspace& ws, const StepStates& steps) {
  constexpr int kMaxSteps = 256;
  const int n_steps = ws.n_steps;
  if (n_steps >= kMaxSteps) {
    return ClearanceAt(ws, [&steps](int i) { return steps(i); });
  }
  double col[kMaxSteps];  // per step, the smallest separation so far
  for (int j = 1; j <= n_steps; ++j) col[j] = 1e9;
  const double* s = steps.s();
  const double* d = steps.d();
  for (int c = 0; c < ws.ctx.num_cars; ++c) {
    const double* cs = ws.step_s.data() + c * (n_steps + 1);
    const double* cd = ws.step_d.data() + c * (n_steps + 1);
    const double len = ws.car_sep_s[c], wid = ws.car_sep_d[c], side = ws.side_clear;
    for (int j = 1; j <= n_steps; ++j) {
      const double sep =
          std::max(std::abs(cs[j] - s[j]) - len, SidePart(std::abs(cd[j] - d[j]) - wid, side));
      col[j] = sep < col[j] ? sep : col[j];
    }
  }
  double worst = 1e9;
  for (int j = 1; j <= n_steps; ++j) worst = std::min(worst, col[j]);
  return worst;
}

// The smallest of v[0, n), ignoring NaN (1e9 when none is smaller): four running minima, so
// that the comparisons do not wait for each other; the order does not change a minimum that
// ignores NaN (and no value here is -0).
inline double MinOf(const double* v, int n) {
  double m[4] = {1e9, 1e9, 1e9, 1e9};
  int q = 0;
  for (; q + 4 <= n; q += 4) {
    for (int u = 0; u < 4; ++u) m[u] = v[q + u] < m[u] ? v[q + u] : m[u];
  }
  for (; q < n; ++q) m[0] = v[q] < m[0] ? v[q] : m[0];
  const double a = m[1] < m[0] ? m[1] : m[0], b = m[3] < m[2] ? m[3] : m[2];
  return b < a ? b : a;
}

// MinOf(max(a[q], b[q]) for q in [0, n)), in one pass. A minimum that ignores NaN (a NaN
// separation never replaces a running minimum) does not depend on the order, so the SSE2 lanes
// give the same value: _mm_max_pd(y, x) is std::max(x, y) ((x < y) ? y : x, also for NaN) and
// _mm_min_pd(v, m) is (v < m) ? v : m.
inline double MinOfMax(const double* a, const double* b, int n) {
  int q = 0;
  double r = 1e9;
#if defined(__SSE2__)
  __m128d m0 = _mm_set1_pd(1e9), m1 = m0;
  for (; q + 4 <= n; q += 4) {
    const __m128d v0 = _mm_max_pd(_mm_loadu_pd(b + q), _mm_loadu_pd(a + q));
    const __m128d v1 = _mm_max_pd(_mm_loadu_pd(b + q + 2), _mm_loadu_pd(a + q + 2));
    m0 = _mm_min_pd(v0, m0);
    m1 = _mm_min_pd(v1, m1);
  }
  double lanes[4];
  _mm_storeu_pd(lanes, m0);
  _mm_storeu_pd(lanes + 2, m1);
  for (const double v : lanes) r = v < r ? v : r;
#endif
  for (; q < n; ++q) {
    const double v = std::max(a[q], b[q]);
    r = v < r ? v : r;
  }
  return r;
}

// ClearanceAt's value from the rows s, d at the collision-check steps when it is at least
// `floor`; else a value below `floor` (it stops at the first car that takes it there). The same
// minimum, car by car: the order does not change a minimum that ignores NaN.
inline double ClearanceAbove(const Workspace& ws, const double* s, const double* d, double floor) {
  constexpr int kMaxSteps = 256;
  const int n_steps = ws.n_steps;
  if (n_steps >= kMaxSteps) {
    return ClearanceAt(ws, [s, d, &ws](int i) {
      const int j = i / ws.collision_step;
      return traj::FrenetState{s[j], 0.0, 0.0, d[j], 0.0, 0.0};
    });
  }
  double sep[kMaxSteps];
  double worst = 1e9;
  for (int c = 0; c < ws.ctx.num_cars; ++c) {
    const double* cs = ws.step_s.data() + c * (n_steps + 1);
    const double* cd = ws.step_d.data() + c * (n_steps + 1);
    const double len = ws.car_sep_s[c], wid = ws.car_sep_d[c], side = ws.side_clear;
    for (int j = 1; j <= n_steps; ++j) {
      sep[j - 1] =
          std::max(std::abs(cs[j] - s[j]) - len, SidePart(std::abs(cd[j] - d[j]) - wid, side));
    }
    const double row = MinOf(sep, n_steps);
    worst = row < worst ? row : worst;
    if (worst < floor) break;
  }
  return worst;
}

class LeastHarm {
 public:
  // `ws`, `scorer`, the checkers and `clock` must outlive this; sized for ws's largest candidate
  // set.
  LeastHarm(const Settings& cfg, Workspace& ws, Scorer& scorer, LimitChecker& limits,
            CollisionChecker& collisions, const CycleClock& clock);

  // Makes the least harmful candidate the winner: the candidates ranked by harm (latest
  // contact, then most clearance, then cost), the first feasible one, else the first feasible
  // but for the lane-line timer. Costs are made exact as the ranking needs them
  // (Scorer::ExactCost; all of them for the whole ranking). When a candidate is feasible only
  // the ones that could rank before it are examined and ws.order is left as it is; else every
  // candidate is ranked and ws.order is left in harm order. False when
  // none is even feasible but for the timer, or when the deadline (85% of budget_ms) cut it
  // short: then *over_budget is set.
  // none_passed_before: the last cycle's search found no candidate passing either (its Choose
  // was the last call): a hint for the work, and with check.keep_lane the latest contact keeps
  // the last winner's lane (KeepSide) off a line too.
  // With check.clear_enough > 0 the cheapest feasible candidate whose bare boxes keep that far
  // from every car comes first (CheapestClearEnough); the harm ranking only when none does.
  // Astride a line with the timer running: the clear tests once more with the simulator's
  // count less a little (check.last_resort_ticks), and the latest contact keeps the last winner's
  // side (KeepSide, check.keep_side).
  bool Choose(bool* over_budget, bool none_passed_before = false);

 private:
  // The first candidate in cost order that collides with no car on bare boxes (the room behind
  // kept, the predictor's ghosts left out, as BestClear tests), keeps at least
  // cfg.check.clear_enough from every car (Clearance) and breaks no limit; -1 when none does (or
  // the deadline cut it short: then *over_budget is set). Where the predictions are the traffic's
  // own future (recorded traffic), more room than enough buys nothing, and the clearest
  // candidate is mostly the one braking hardest, away from the goal.
  int CheapestClearEnough(bool* over_budget);
  // The first feasible collision-free candidate in harm order, -1 when there is none (or the
  // deadline cut it short: then *over_budget is set). *all_known: none is, and every
  // candidate's clearance is in clearance_ and its contact in first_hit_ (known_ 1), or for
  // one that hits before the latest contact latest_, a step it hits at (known_ 2: its exact
  // contact is needed only when no candidate of the latest contact is feasible).
  // unbounded: none may be clear (nothing passed last cycle either): in cost order without
  // bounds until a clear one is found, then the rest by bound. After a CheapestClearEnough that
  // tested every candidate, their contacts are read from it (exact, known_ 1), and when every
  // candidate collides nothing is visited.
  int BestClear(bool* over_budget, bool* all_known, bool unbounded);
  // Candidate c's contact on bare boxes as far as the ranking needs it: a step before latest_
  // at which it collides (known_ 2, counted in bounded_), else its first collision step, from
  // latest_ on (known_ 1; n_steps + 1 when none), raising latest_ to it. The steps before
  // latest_ are tried where its bundles' last candidates hit first (the candidates of a bundle
  // mostly run into the same car at about the same time), then from latest_ - 1 down (a
  // contact mostly lasts: an early one often still holds there).
  void Contact(int c);
  // After BestClear found none with every candidate known: the first feasible colliding
  // candidate in harm order, -1 when there is none (or the deadline cut it short). Makes every
  // contact exact (known_ 1) unless it returns a candidate of a contact from latest_ on or is
  // cut short.
  int LatestContact(bool* over_budget);
  // After LatestContact chose `best`, astride a line with the timer running (margin:
  // check.keep_side) or after a cycle in which none passed either (check.keep_lane): the last
  // winner's lane (ws.prev_lat_lane) when a feasible move there meets a car at most margin s
  // sooner (the latest such, then the cheapest), else best. When no candidate passes, the
  // latest contact's choice can swing between lanes from cycle to cycle as the predictions
  // move; each new move first spends its start reversing the last one's motion across, so the
  // ego stays on the line until the timer runs out, or brakes half as hard as either move
  // would. Out of time (the checks' deadline), best.
  int KeepSide(int best, double margin);
  // The cheapest feasible candidate (by exact cost, then index) of the (cost bound, index)
  // pairs [first, last), taken by bound from a heap there; -1 when none is (or the deadline cut
  // it short). *k counts the candidates taken, for the deadline checks.
  using BoundIndex = std::pair<double, int>;
  int CheapestFeasible(std::vector<BoundIndex>::iterator first,
                       std::vector<BoundIndex>::iterator last, int* k, bool* over_budget);
  // The whole ranking: every candidate's contact and clearance (unless all_known), ws.order
  // sorted by harm, the first feasible one (unless all_known: none is), else the first
  // feasible but for the lane-line timer.
  bool ChooseByRanking(bool* over_budget, bool all_known);

  const Settings& cfg_;
  Workspace& ws_;
  Scorer& scorer_;
  LimitChecker& limits_;
  CollisionChecker& collisions_;
  const CycleClock& clock_;
  // Per candidate: first collision step and clearance on bare boxes (ChooseByRanking; known_:
  // BestClear measured them already), and an upper bound of the clearance (BestClear).
  std::vector<char> known_;
  std::vector<int> first_hit_;
  std::vector<double> clearance_, bound_;
  // LatestContact's colliding candidates (cost bound, index), grouped by contact step, latest
  // first: group h starts at group_start_[h] and ends where group h - 1 starts (group 1 ends at
  // group_start_[0]).
  std::vector<BoundIndex> contact_;
  std::vector<int> group_start_, group_fill_;
  // BestClear: the latest contact step of a candidate known so far (0: none), how many
  // candidates have known_ 2, and per lon / lat bundle slot the step its last candidate
  // visited was found hitting at (0: none).
  int latest_ = 0;
  int bounded_ = 0;
  std::vector<int> lon_hit_, lat_hit_;
  std::vector<int> heap_;  // BestClear's candidates, a heap by bound
  // CheapestClearEnough: the candidates not taken yet (a heap by cost bound) and the ones
  // that passed its cheap tests (a heap by a bound raised until it is the exact cost).
  std::vector<BoundIndex> rest_, clear_;
  std::vector<char> visited_;  // BestClear: taken from the heap
  // CheapestClearEnough's test of a clearance of at least check.clear_enough, by parts: per lon
  // (lat) bundle slot and car, bit j - 1 set where step j's separation along s (d) alone keeps
  // it (ClearEnough), filled once a cycle per slot (the done flags).
  bool ClearEnough(int c);
  std::vector<std::uint64_t> lon_clear_, lat_clear_;
  std::vector<char> lon_clear_done_, lat_clear_done_;
  // Whether CheapestClearEnough tested every candidate on bare boxes (then BestClear reads
  // their contacts, CollisionChecker::BareContact, instead of visiting).
  bool bare_known_ = false;
  // BestClear's bound: its steps, and the separations' parts there per bundle.
  static constexpr int kProbes = 8;
  static constexpr int kHeapVisits = 48;  // BestClear: candidates taken best bound first
  std::vector<char> lon_done_, lat_done_;
  std::vector<double> lon_sep_, lat_sep_;
};

}  // namespace frenetic::plan::search

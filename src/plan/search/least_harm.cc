#include "plan/search/least_harm.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "frenetic/plan/planner.h"
#include "plan/search/scoring.h"

namespace frenetic::plan::search {

double Clearance(const Workspace& ws, const traj::FrenetTrajectory& tr) {
  return ClearanceAt(ws, [&](int i) { return tr.At(i * kTickSeconds); });
}

LeastHarm::LeastHarm(const Settings& cfg, Workspace& ws, Scorer& scorer, LimitChecker& limits,
                     CollisionChecker& collisions, const CycleClock& clock)
    : cfg_(cfg), ws_(ws), scorer_(scorer), limits_(limits), collisions_(collisions), clock_(clock) {
  known_.reserve(ws_.order.capacity());
  rest_.reserve(ws_.order.capacity());
  clear_.reserve(ws_.order.capacity());
  first_hit_.reserve(ws_.order.capacity());
  lon_clear_.assign(ws_.lon.capacity() * kMaxCars, 0);
  lat_clear_.assign(ws_.lat.capacity() * kMaxCars, 0);
  lon_clear_done_.reserve(ws_.lon.capacity());
  lat_clear_done_.reserve(ws_.lat.capacity());
  clearance_.reserve(ws_.order.capacity());
  contact_.reserve(ws_.order.capacity());
  group_start_.reserve(ws_.n_steps + 2);
  group_fill_.reserve(ws_.n_steps + 2);
  bound_.reserve(ws_.order.capacity());
  heap_.reserve(ws_.order.capacity());
  visited_.reserve(ws_.order.capacity());
  lon_hit_.reserve(ws_.lon.capacity());
  lat_hit_.reserve(ws_.lat.capacity());
  lon_done_.reserve(ws_.lon.capacity());
  lat_done_.reserve(ws_.lat.capacity());
  lon_sep_.assign(ws_.lon.capacity() * kProbes * kMaxCars, 0.0);
  lat_sep_.assign(ws_.lat.capacity() * kProbes * kMaxCars, 0.0);
}

bool LeastHarm::Choose(bool* over_budget, bool none_passed_before) {
  bare_known_ = false;
  // The clear tests with the planner's lane-line limit, then, astride a line with the timer
  // running, once more with the simulator's own count less a little: a clear way off the line
  // that leaves it a few ticks later than the margin asks beats one that stays on it (the
  // latest contact and the ranking below drop the timer).
  int best = -1;
  bool all_known = false;
  const bool astride = ws_.straddle_at_start > 0;
  const bool last_resort = astride && cfg_.check.last_resort_ticks > 0;
  for (int pass = 0; pass < (last_resort ? 2 : 1) && best < 0; ++pass) {
    limits_.SetStraddleLimit(pass == 0 ? kMaxStraddleTicks : cfg_.check.last_resort_ticks);
    if (cfg_.check.clear_enough > 0) best = CheapestClearEnough(over_budget);
    if (best < 0 && !*over_budget) best = BestClear(over_budget, &all_known, none_passed_before);
    if (*over_budget || (best < 0 && !all_known)) break;
  }
  limits_.SetStraddleLimit(kMaxStraddleTicks);
  if (*over_budget) return false;
  if (best < 0 && all_known) {
    best = LatestContact(over_budget);
    // Astride a line keep_side (when on), else after a cycle with none passing keep_lane.
    const double margin = astride && cfg_.check.keep_side > 0 ? cfg_.check.keep_side
                          : none_passed_before                ? cfg_.check.keep_lane
                                                              : 0.0;
    if (best >= 0 && margin > 0) best = KeepSide(best, margin);
  }
  if (best >= 0) {
    ws_.TakeWinner(best);
    return true;
  }
  return !*over_budget && ChooseByRanking(over_budget, all_known);
}

int LeastHarm::KeepSide(int best, double margin) {
  const int lane = ws_.prev_lat_lane;
  if (lane < 0 || ws_.lat[ws_.cand_lat[best]].lane == lane) return best;
  const int steps = static_cast<int>(std::lround(margin / (ws_.collision_step * kTickSeconds)));
  const int floor = collisions_.BareContact(best) - steps;
  int keep = -1, keep_hit = 0, k = 0;
  for (const int c : ws_.order) {
    // Out of time: the latest contact's own choice.
    if ((++k & 31) == 0 && clock_.ChecksOver(cfg_.budget_ms)) return best;
    if (ws_.lat[ws_.cand_lat[c]].lane != lane) continue;
    const int hit = collisions_.BareContact(c);
    if (hit < floor || (keep >= 0 && hit < keep_hit)) continue;
    scorer_.ExactCost(c);
    if (keep >= 0 && hit == keep_hit && !Cheaper(ws_, c, keep)) continue;
    if (limits_.CandidateBreaksLimits(c)) continue;
    keep = c;
    keep_hit = hit;
  }
  return keep >= 0 ? keep : best;
}

int LeastHarm::CheapestClearEnough(bool* over_budget) {
  // The cheapest candidate (exact cost, then index) that passes the three tests, found as
  // Selection::CheapestPassing finds the cheapest feasible one: the candidates come off a heap by
  // cost bound, the cheap tests first (bare boxes, clearance), and one that passes them waits in a
  // second heap, by a bound raised one term at a time until it is its exact cost; the top of that
  // heap, once no bound left ranks before it, is tested for the limits (the dearest test) and
  // is the answer when it passes. The same candidate as walking the cost order, with no exact
  // cost for one that collides.
  const int n = static_cast<int>(ws_.order.size());
  rest_.clear();
  clear_.clear();
  for (int r = 0; r < n; ++r) {
    const int c = ws_.order[r];
    rest_.push_back({scorer_.KnownBound(c), c});
  }
  const auto later = std::greater<BoundIndex>();
  std::make_heap(rest_.begin(), rest_.end(), later);
  lon_clear_done_.assign(ws_.lon.size(), 0);
  lat_clear_done_.assign(ws_.lat.size(), 0);
  for (int k = 0;; ++k) {
    if ((k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return -1;
    }
    if (!clear_.empty() && (rest_.empty() || clear_.front() < rest_.front())) {
      if (const int c = clear_.front().second;
          !scorer_.Resolved(c) || clear_.front().first != ws_.cand_cost[c]) {
        clear_.front().first = scorer_.Advance(c);
        SiftDownTop(clear_.begin(), clear_.end(), later);
        continue;
      }
      std::pop_heap(clear_.begin(), clear_.end(), later);
      const int c = clear_.back().second;
      clear_.pop_back();
      if (!limits_.CandidateBreaksLimits(c)) return c;
      continue;
    }
    if (rest_.empty()) {
      bare_known_ = true;  // every candidate was tested
      return -1;
    }
    // By the bounds as they are (any lower bound gives the same answer): the cheap tests
    // first, the bound completed (Advance) only for a candidate that passes them.
    const int c = rest_.front().second;
    std::pop_heap(rest_.begin(), rest_.end(), later);
    rest_.pop_back();
    if (collisions_.BareContact(c) <= ws_.n_steps) continue;
    if (!ClearEnough(c)) continue;
    clear_.push_back({scorer_.KnownBound(c), c});
    std::push_heap(clear_.begin(), clear_.end(), later);
  }
}

// ClearanceAbove(rows of c, floor) >= floor, the floor check.clear_enough: no separation
// std::max(a, b) below it, a the separation along s and b along d at a step (a NaN one is
// ignored). A step keeps it when !(a < floor) (a NaN: ignored) or b >= floor; a keeps it or not
// whatever the lat bundle, b whatever the lon bundle: one bit per step and car for each part,
// once a cycle per bundle, and a candidate's test is an or per car.
bool LeastHarm::ClearEnough(int c) {
  const double floor = cfg_.check.clear_enough;
  const int n_steps = ws_.n_steps, num_cars = ws_.ctx.num_cars;
  const CollisionChecker::Rows rows = collisions_.StepRows(c);
  if (n_steps > 64 || num_cars > kMaxCars || !(floor <= 1e9)) {
    return ClearanceAbove(ws_, rows.s, rows.d, floor) >= floor;
  }
  const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
  const int w = n_steps + 1;
  // Per car, bit j - 1 where keeps(|the car's p - row p| - its size) at step j.
  const auto fill = [&](const double* p, const std::vector<double>& car_p,
                        const std::vector<double>& size, auto keeps, std::uint64_t* bits) {
    for (int car = 0; car < num_cars; ++car) {
      const double* cp = car_p.data() + car * w;
      std::uint64_t b = 0;
      for (int j = 1; j <= n_steps; ++j) {
        b |= static_cast<std::uint64_t>(keeps(std::abs(cp[j] - p[j]) - size[car])) << (j - 1);
      }
      bits[car] = b;
    }
  };
  if (!lon_clear_done_[i]) {
    fill(rows.s, ws_.step_s, ws_.car_sep_s, [floor](double a) { return !(a < floor); },
         &lon_clear_[i * kMaxCars]);
    lon_clear_done_[i] = 1;
  }
  if (!lat_clear_done_[k]) {
    const double side = ws_.side_clear;
    fill(
        rows.d, ws_.step_d, ws_.car_sep_d,
        [floor, side](double b) { return SidePart(b, side) >= floor; }, &lat_clear_[k * kMaxCars]);
    lat_clear_done_[k] = 1;
  }
  const std::uint64_t all = n_steps == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n_steps) - 1;
  for (int car = 0; car < num_cars; ++car) {
    if ((lon_clear_[i * kMaxCars + car] | lat_clear_[k * kMaxCars + car]) != all) return false;
  }
  return true;
}

// In harm order the collision-free candidates come first, by clearance, then cost: when one
// of them is feasible the winner is the feasible collision-free one with the most clearance
// (then the least cost, then the smallest index), a maximum found without ranking the others.
// The candidates are visited by an upper bound of their clearance, the minimum over a few
// steps only (a minimum over fewer separations is never smaller), best first, so that the
// visit ends once no bound can reach the best clearance found; the clearance itself stops as
// soon as it falls below that, and only a candidate that would rank before the best one is
// tested for collision, then for feasibility.
int LeastHarm::BestClear(bool* over_budget, bool* all_known, bool unbounded) {
  const std::vector<int>& order = ws_.order;
  const int n = static_cast<int>(order.size());
  const int n_steps = ws_.n_steps;
  const int num_cars = ws_.ctx.num_cars;
  *all_known = false;
  if (n_steps < 1) return -1;  // nothing to bound: the whole ranking
  known_.assign(n, 0);
  first_hit_.resize(n);
  clearance_.resize(n);
  latest_ = 0;
  bounded_ = 0;
  if (bare_known_ && std::none_of(order.begin(), order.end(), [&](int c) {
        return collisions_.BareContact(c) > n_steps;
      })) {
    // Every candidate collides, each contact known exactly (CheapestClearEnough): what the
    // visits below would find, with no test.
    for (const int c : order) {
      known_[c] = 1;
      first_hit_[c] = collisions_.BareContact(c);
      clearance_[c] = 0.0;
      latest_ = std::max(latest_, first_hit_[c]);
    }
    *all_known = true;
    return -1;
  }
  // The bound's steps: the first ones (where every candidate is still near the start, and the
  // clearance is often smallest) and a few spread over the horizon.
  const int probe[kProbes] = {1, 2, 4, 8, n_steps / 4, n_steps / 2, (3 * n_steps) / 4, n_steps};
  // The two parts of each separation at those steps, per bundle (computed at its first
  // candidate): |ds| - length per lon bundle, |dd| - width per lat bundle, [probe][car].
  const int row = kProbes * num_cars;
  lon_done_.assign(ws_.lon.size(), 0);
  lat_done_.assign(ws_.lat.size(), 0);
  // (The part across through SidePart, as the clearance counts it.)
  const auto fill = [&](const double* p, const std::vector<double>& car_p,
                        const std::vector<double>& size, bool across, double* out) {
    for (int q = 0; q < kProbes; ++q) {
      const int j = std::clamp(probe[q], 1, n_steps);
      for (int car = 0; car < num_cars; ++car) {
        const double sep = std::abs(car_p[car * (n_steps + 1) + j] - p[j]) - size[car];
        out[q * num_cars + car] = across ? SidePart(sep, ws_.side_clear) : sep;
      }
    }
  };
  bound_.resize(ws_.cand_cost.size());
  const auto bound_of = [&](int c) {
    const int i = ws_.cand_lon[c], k = ws_.cand_lat[c];
    if (!lon_done_[i] || !lat_done_[k]) {
      const CollisionChecker::Rows rows = collisions_.StepRows(c);
      if (!lon_done_[i]) fill(rows.s, ws_.step_s, ws_.car_sep_s, false, &lon_sep_[i * row]);
      if (!lat_done_[k]) fill(rows.d, ws_.step_d, ws_.car_sep_d, true, &lat_sep_[k * row]);
      lon_done_[i] = lat_done_[k] = 1;
    }
    return MinOfMax(&lon_sep_[i * row], &lat_sep_[k * row], row);
  };
  // Largest bound first, then the smallest index (any order gives the same maximum; this one
  // is deterministic).
  const auto lower = [this](int a, int b) {
    return bound_[a] < bound_[b] || (bound_[a] == bound_[b] && a > b);
  };
  int best = -1;
  double best_clr = 0;
  lon_hit_.assign(ws_.lon.size(), 0);
  lat_hit_.assign(ws_.lat.size(), 0);
  // Visits c: whether it beats the best one so far.
  const auto visit = [&](int c) {
    if (best < 0) {
      // Nothing to beat yet: whether it collides first (most do, and then its clearance is
      // not needed: the ranking counts it as 0), and what ChooseByRanking would measure; of
      // one that hits before the latest contact so far, only a step it hits at (LatestContact
      // finds its contact if that is ever needed).
      clearance_[c] = 0.0;
      Contact(c);
      if (first_hit_[c] <= n_steps) return;
      const CollisionChecker::Rows rows = collisions_.StepRows(c);
      clearance_[c] = ClearanceAbove(ws_, rows.s, rows.d, -std::numeric_limits<double>::infinity());
      if (limits_.CandidateBreaksLimits(c)) return;
      scorer_.ExactCost(c);
      best = c;
      best_clr = clearance_[c];
      return;
    }
    // Known to collide (measured before): it cannot win.
    if (collisions_.BareContactKnown(c) && collisions_.BareContact(c) <= n_steps) return;
    const CollisionChecker::Rows rows = collisions_.StepRows(c);
    const double clr = ClearanceAbove(ws_, rows.s, rows.d, best_clr);
    if (clr < best_clr) return;
    if (clr == best_clr) {  // the cost decides (both exact), then the index
      scorer_.ExactCost(c);
      if (!Cheaper(ws_, c, best)) return;
    }
    if (collisions_.BareContact(c) <= n_steps) return;
    if (limits_.CandidateBreaksLimits(c)) return;
    scorer_.ExactCost(c);
    best = c;
    best_clr = clr;
  };
  // Unbounded: in cost order, without bounds, until a clear one is found (mostly none is);
  // then the rest as below.
  heap_.clear();
  int r = 0;
  for (; unbounded && r < n && best < 0; ++r) {
    if ((r & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return -1;
    }
    visit(order[r]);
  }
  const int r0 = r;  // order[r0, n): not visited yet
  for (; r < n; ++r) heap_.push_back(order[r]);
  for (const int c : heap_) bound_[c] = bound_of(c);
  std::make_heap(heap_.begin(), heap_.end(), lower);
  // Best bound first: a clear candidate is mostly among the first few. After kHeapVisits
  // without one, the rest in the heap's array order (popping each would cost more than the
  // order saves: none may be clear at all), each skipped when its bound cannot beat the best.
  int k = 0;
  bool done = false;
  visited_.assign(n, 0);
  for (; !heap_.empty() && k < kHeapVisits; ++k) {
    if ((k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return -1;
    }
    const int c = heap_.front();
    if (best >= 0 && bound_[c] < best_clr) {
      done = true;
      break;
    }
    std::pop_heap(heap_.begin(), heap_.end(), lower);
    heap_.pop_back();
    visited_[c] = 1;
    visit(c);
  }
  // The rest in cost order (the candidates of a bundle are neighbours there: their rows stay
  // in cache), skipping the ones visited.
  for (int e = r0; !done && !heap_.empty() && e < n; ++e, ++k) {
    if ((k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return -1;
    }
    const int c = order[e];
    if (visited_[c] || (best >= 0 && bound_[c] < best_clr)) continue;
    visit(c);
  }
  // With no winner every candidate was visited before the best one was found.
  *all_known = best < 0;
  return best;
}

void LeastHarm::Contact(int c) {
  int& lon_hit = lon_hit_[ws_.cand_lon[c]];
  int& lat_hit = lat_hit_[ws_.cand_lat[c]];
  if (collisions_.BareContactKnown(c)) {  // measured already (Selection, CheapestClearEnough)
    first_hit_[c] = collisions_.BareContact(c);
    known_[c] = 1;
    if (first_hit_[c] > ws_.n_steps) return;
    latest_ = std::max(latest_, first_hit_[c]);
    lon_hit = lat_hit = first_hit_[c];
    return;
  }
  const StepStates steps = collisions_.StepsOf(c, 0.0, 1.0);
  // A step before latest_ that collides: the ones its bundles' last candidates hit at first.
  int hit = 0;
  if (latest_ > 1) {
    for (const int j : {lon_hit, lat_hit}) {
      if (j >= 1 && j < latest_ && collisions_.CollidesAt(steps, j, 0.0, 1.0, false)) {
        hit = j;
        break;
      }
    }
    for (int j = latest_ - 1; hit == 0 && j >= 1; --j) {
      if (collisions_.CollidesAt(steps, j, 0.0, 1.0, false)) hit = j;
    }
  }
  if (hit > 0) {
    first_hit_[c] = hit;
    known_[c] = 2;
    ++bounded_;
  } else {  // none before latest_: the first one from there on
    first_hit_[c] = collisions_.FirstCollision(steps, 0.0, 1.0, nullptr, false, latest_);
    known_[c] = 1;
    if (first_hit_[c] > ws_.n_steps) return;
    latest_ = std::max(latest_, first_hit_[c]);
  }
  lon_hit = lat_hit = first_hit_[c];
}

int LeastHarm::CheapestFeasible(std::vector<BoundIndex>::iterator first,
                                std::vector<BoundIndex>::iterator last, int* k, bool* over_budget) {
  // A min-heap by bound, then index (a strict order: popping gives the sorted order), so that
  // only the candidates taken are ordered: a group may hold nearly all of them (every one in
  // contact at the first step) and few are taken.
  const auto later = std::greater<BoundIndex>();
  std::make_heap(first, last, later);
  int best = -1;
  for (; first != last; ++*k) {
    if ((*k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return -1;
    }
    const auto [bound, c] = *first;
    std::pop_heap(first, last--, later);
    if (best >= 0) {
      // The cost first once there is one to beat (the limits cost more); before, the limits.
      const double cost = ws_.cand_cost[best];
      if (bound > cost || (bound == cost && c > best)) break;  // none cheaper is left
      // Its cost a term at a time, until its bound ranks it after the best one (the group's
      // candidates mostly lose so, on their first terms) or the cost is exact.
      bool behind = false;
      while (!behind && !scorer_.Resolved(c)) {
        const double b = scorer_.Advance(c);
        behind = b > cost || (b == cost && c > best);
      }
      if (behind || !Cheaper(ws_, c, best)) continue;
    }
    if (limits_.CandidateBreaksLimits(c)) continue;
    scorer_.ExactCost(c);
    best = c;
  }
  return best;
}

// No collision-free candidate is feasible (BestClear visited them all): in harm order the
// colliding ones come next, latest contact first, and at equal contact their clearance is 0,
// so the cost decides. The contact groups are taken latest first; in each, the candidates by
// cost bound, feasible ones only, until no bound is below the cheapest feasible one's cost.
// The groups from latest_ on are known as they are (every candidate that reached latest_
// without contact was scanned on); only when none of them is feasible are the next ones
// searched for among the others, the same way (Contact).
int LeastHarm::LatestContact(bool* over_budget) {
  const std::vector<int>& order = ws_.order;
  const int n = static_cast<int>(order.size());
  const int n_steps = ws_.n_steps;
  int k = 0;
  for (int top = n_steps;;) {
    // The exact contacts in [floor, top] grouped by step, latest first (a counting sort).
    const int floor = bounded_ > 0 ? latest_ : 1;
    group_start_.assign(n_steps + 2, 0);
    for (int r = 0; r < n; ++r) {
      const int c = order[r];
      if (known_[c] == 1 && first_hit_[c] >= floor && first_hit_[c] <= top) {
        ++group_start_[first_hit_[c]];
      }
    }
    int at = 0;
    for (int h = n_steps; h >= 1; --h) {
      const int count = group_start_[h];
      group_start_[h] = at;
      at += count;
    }
    group_start_[0] = at;  // the end of the last group (h = 1)
    contact_.resize(at);
    group_fill_.assign(group_start_.begin(), group_start_.end());
    for (int r = 0; r < n; ++r) {
      const int c = order[r];
      const int h = first_hit_[c];
      if (known_[c] == 1 && h >= floor && h <= top) {
        contact_[group_fill_[h]++] = {scorer_.Bound(c), c};
      }
    }
    for (int h = top; h >= floor; --h) {
      const auto first = contact_.begin() + group_start_[h];
      const auto last = contact_.begin() + (h > 1 ? group_start_[h - 1] : group_start_[0]);
      const int best = CheapestFeasible(first, last, &k, over_budget);
      if (best >= 0 || *over_budget) return best;  // an earlier contact ranks after it
    }
    if (floor <= 1) return -1;
    // None from latest_ on is feasible: the latest contact before, as BestClear found it, from
    // the latest exact one before (an exact contact, so that group is not empty); a candidate
    // known to hit before that needs nothing more.
    top = floor - 1;
    latest_ = 0;
    for (int r = 0; r < n; ++r) {
      const int c = order[r];
      if (known_[c] == 1 && first_hit_[c] <= top) latest_ = std::max(latest_, first_hit_[c]);
    }
    bounded_ = 0;
    for (int r = 0; r < n; ++r, ++k) {
      if ((k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
        *over_budget = true;
        return -1;
      }
      const int c = order[r];
      if (known_[c] != 2) continue;
      if (first_hit_[c] < latest_) {
        ++bounded_;
      } else {
        Contact(c);
      }
    }
  }
}

bool LeastHarm::ChooseByRanking(bool* over_budget, bool all_known) {
  if (!scorer_.ResolveAll()) {
    *over_budget = true;
    return false;
  }
  std::vector<int>& order = ws_.order;
  const int n = static_cast<int>(order.size());
  if (!all_known) known_.assign(n, 0);
  first_hit_.resize(n);
  clearance_.resize(n);
  for (int r = 0; r < n; ++r) {
    if ((r & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return false;
    }
    const int c = order[r];
    if (known_[c]) continue;
    first_hit_[c] = collisions_.BareContact(c);
    clearance_[c] =
        first_hit_[c] > ws_.n_steps ? ClearanceAt(ws_, collisions_.StepsOf(c, 0.0, 1.0)) : 0.0;
  }
  // Latest contact first, then most room; the cost order breaks ties (a strict total order:
  // std::stable_sort would allocate).
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (first_hit_[a] != first_hit_[b]) return first_hit_[a] > first_hit_[b];
    if (clearance_[a] != clearance_[b]) return clearance_[a] > clearance_[b];
    return Cheaper(ws_, a, b);
  });
  ws_.sorted = n;
  // Feasible first (none is when every candidate was known: LatestContact found none); then
  // ignoring the lane-line timer (an incident, but not a crash).
  for (const bool lane_line : {true, false}) {
    if (lane_line && all_known) continue;
    for (int r = 0; r < n; ++r) {
      if ((r & 7) == 7 && clock_.ChecksOver(cfg_.budget_ms)) {
        *over_budget = true;
        return false;
      }
      const int c = order[r];
      if (lane_line) {
        if (limits_.CandidateBreaksLimits(c)) continue;
      } else if (limits_.CandidateBreaksLimitsBesidesTheLaneLine(c)) {
        // (Its bundles' ticks, not ws_.tk_*: the candidates of a bundle share them.)
        continue;
      }
      ws_.TakeWinner(c);
      return true;
    }
  }
  return false;
}

}  // namespace frenetic::plan::search

#include "plan/search/selection.h"

#include <algorithm>
#include <functional>
#include <utility>

namespace frenetic::plan::search {

Selection::Selection(const Settings& cfg, Workspace& ws, Scorer& scorer, LimitChecker& limits,
                     CollisionChecker& collisions, Tracer& tracer, const CycleClock& clock)
    : cfg_(cfg),
      ws_(ws),
      scorer_(scorer),
      limits_(limits),
      collisions_(collisions),
      tracer_(tracer),
      clock_(clock) {
  rest_.reserve(ws_.order.capacity());
  clear_.reserve(ws_.order.capacity());
  popped_.assign(ws_.order.capacity(), 0);
}

bool Selection::Select(bool none_passed_before, PlanSummary* summary, bool* over_budget) {
  PlanSummary& sum = *summary;
  const int n = static_cast<int>(ws_.order.size());
  const int traced = tracer_.on() ? tracer_.max_candidates() : 0;
  const int rest_at = tracer_.on() ? std::max(kTracedRanksMin, traced) : 0;
  for (int r = 0; r < n; ++r) {
    if ((r & 7) == 7 && clock_.ChecksOver(cfg_.budget_ms)) {
      *over_budget = true;
      return false;
    }
    if (r == rest_at) {
      bool cut = false;
      const int best = CheapestPassing(r, none_passed_before, &sum, &cut);
      if (cut) *over_budget = true;
      if (best < 0) return false;
      ws_.TakeWinner(best);
      return true;
    }
    if (!scorer_.SortUpTo(r)) {  // costing the next candidates ran into the deadline
      *over_budget = true;
      return false;
    }
    const int c = ws_.order[r];
    if (LeastHarmOnly(c)) continue;
    ++sum.candidates_checked;
    // Cheapest first: the Frenet-only collision test skips the tick sampling and the XY
    // conversion for the many candidates that run into traffic. Past the traced ranks, whether
    // it collides is all the walk needs.
    int hit_car = -1, hit = ws_.n_steps + 1;
    if (r < traced) {
      hit = collisions_.FirstCollision(collisions_.StepsOf(c), 1.0, 1.0, &hit_car, true, 1,
                                       ws_.CheckSteps(c));
    } else {
      hit = collisions_.CandidateCollides(c) ? 1 : hit;
    }
    if (hit <= ws_.n_steps) {
      ++sum.rejections[static_cast<int>(Reject::kCollision)];
      tracer_.Add(r, false, static_cast<int>(Reject::kCollision), hit_car,
                  hit * ws_.collision_step * kTickSeconds);
      continue;
    }
    Reject why = Reject::kCount;
    if (limits_.CandidateViolation(c, &why) > 0) {
      ++sum.rejections[static_cast<int>(why)];
      tracer_.Add(r, false, static_cast<int>(why));
      continue;
    }
    ++sum.candidates_feasible;
    ws_.TakeWinner(c);
    tracer_.Add(r, true, -1);
    for (int rr = r + 1; rr < n && !tracer_.full(); ++rr) {
      if (!scorer_.SortUpTo(rr)) break;
      tracer_.Add(rr, false, -1);
    }
    return true;
  }
  return false;
}

int Selection::CheapestPassing(int r0, bool none_passed_before, PlanSummary* summary, bool* cut) {
  PlanSummary& sum = *summary;
  const int n = static_cast<int>(ws_.order.size());
  rest_.clear();
  clear_.clear();
  for (int k = r0; k < n; ++k) {
    const int c = ws_.order[k];
    popped_[c] = 0;
    if (LeastHarmOnly(c)) {
      popped_[c] = 1;  // the rank walk below skips it too
      continue;
    }
    rest_.push_back({scorer_.KnownBound(c), c});
  }
  // Min-heaps by (bound, index) and (cost, index): Cheaper's order on exact costs.
  const auto later = std::greater<std::pair<double, int>>();
  std::make_heap(rest_.begin(), rest_.end(), later);
  // Whether c passes the hard limits (counted as feasible, or rejected for the first limit
  // found broken: measuring them all for the worst would cost more than the answer).
  const auto within_limits = [&](int c) {
    Reject why = Reject::kCount;
    if (limits_.CandidateBreaksLimits(c, &why)) {
      ++sum.rejections[static_cast<int>(why == Reject::kCount ? Reject::kAcceleration : why)];
      return false;
    }
    ++sum.candidates_feasible;
    return true;
  };
  // Nothing passed last cycle, and the least-harm choice will want every candidate's contact
  // on bare boxes (CheapestClearEnough tests them all when none passes): that contact first,
  // and the inflated test only for a candidate clear of the bare boxes over its check steps
  // (one that touches them there collides with the inflated boxes too).
  const bool bare_first = none_passed_before && cfg_.check.clear_enough > 0 &&
                          collisions_.BareContactImpliesCollision();
  // Whether c collides (counted as checked, and as rejected when it does).
  const auto collides = [&](int c) {
    ++sum.candidates_checked;
    if (!(bare_first && collisions_.BareContact(c) <= ws_.CheckSteps(c)) &&
        !collisions_.CandidateCollides(c)) {
      return false;
    }
    ++sum.rejections[static_cast<int>(Reject::kCollision)];
    return true;
  };
  // Popped in bound order to the end, unless the last search found none passing either.
  const int heap_tests = none_passed_before ? kRestHeapTests : n;
  int k = 0;
  while (k < heap_tests) {
    if ((k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *cut = true;
      return -1;
    }
    if (!clear_.empty() && (rest_.empty() || clear_.front() < rest_.front())) {
      // A bound until the key is the exact cost (a candidate the traced ranks' sort costed
      // may wait by its bound too).
      if (const int c = clear_.front().second;
          !scorer_.Resolved(c) || clear_.front().first != ws_.cand_cost[c]) {
        clear_.front().first = scorer_.Advance(c);
        SiftDownTop(clear_.begin(), clear_.end(), later);
        continue;
      }
      std::pop_heap(clear_.begin(), clear_.end(), later);
      const int c = clear_.back().second;
      clear_.pop_back();
      if (within_limits(c)) return c;
      continue;
    }
    if (rest_.empty()) return -1;  // every candidate collides or breaks a limit
    const int c = rest_.front().second;
    // A coarse bound is completed before the collision test (the tests then come in a
    // better order), unless nothing passed last cycle: then mostly every candidate collides,
    // and the ones that do need no complete bound (any lower bound gives the same answer).
    if (!none_passed_before && !scorer_.BoundComplete(c)) {
      rest_.front().first = scorer_.Bound(c);
      SiftDownTop(rest_.begin(), rest_.end(), later);
      continue;
    }
    std::pop_heap(rest_.begin(), rest_.end(), later);
    rest_.pop_back();
    popped_[c] = 1;
    ++k;
    if (collides(c)) continue;
    clear_.push_back({scorer_.KnownBound(c), c});  // advanced when it comes up
    std::push_heap(clear_.begin(), clear_.end(), later);
  }
  // None of the cheapest passed, and none did last cycle: mostly none will (a box-in). The
  // clear ones taken so far in cost order until one passes, then the rest in rank order
  // (popping each costs more than the order saves; the candidates of a bundle are neighbours
  // there), each skipped when its bound cannot beat the cheapest that passed.
  int best = -1;
  for (auto& e : clear_) e.first = scorer_.ExactCost(e.second);
  std::sort(clear_.begin(), clear_.end(), later);  // descending: the cheapest last
  for (; !clear_.empty() && best < 0; clear_.pop_back()) {
    if (within_limits(clear_.back().second)) best = clear_.back().second;
  }
  const auto beaten = [&](double bc, int c) {
    if (best < 0) return false;
    const double cost = ws_.cand_cost[best];
    return bc > cost || (bc == cost && c > best);
  };
  for (int e = r0; !rest_.empty() && e < n; ++e, ++k) {
    if ((k & 31) == 31 && clock_.ChecksOver(cfg_.budget_ms)) {
      *cut = true;
      return -1;
    }
    const int c = ws_.order[e];
    if (popped_[c] || beaten(scorer_.KnownBound(c), c) || beaten(scorer_.Bound(c), c)) continue;
    if (collides(c)) continue;
    if (best >= 0) {  // the cost first once there is one to beat (the limits cost more)
      scorer_.ExactCost(c);
      if (!Cheaper(ws_, c, best)) continue;
    }
    if (!within_limits(c)) continue;
    scorer_.ExactCost(c);
    best = c;
  }
  return best;
}

}  // namespace frenetic::plan::search

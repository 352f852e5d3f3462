// The heart of the search's lazy best-first: of the candidates in scorer order, the cheapest
// that passes every hard check, found with as few exact costs and XY checks as the answer needs.
// Traced, the traced ranks are walked in cost order first, each with why it was rejected.
#pragma once

#include <utility>
#include <vector>

#include "frenetic/plan/planner.h"
#include "plan/search/collisions.h"
#include "plan/search/limits.h"
#include "plan/search/scoring.h"
#include "plan/search/settings.h"
#include "plan/search/tracer.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// Candidates taken cheapest bound first, then the rest in any order, when none passed in the
// last search either.
inline constexpr int kRestHeapTests = 64;
// Traced, Select walks at least this many ranks in cost order (more when more are traced).
inline constexpr int kTracedRanksMin = 4;

class Selection {
 public:
  // `ws`, `scorer`, the checkers, `tracer` and `clock` must outlive this; sized for ws's largest
  // candidate set.
  Selection(const Settings& cfg, Workspace& ws, Scorer& scorer, LimitChecker& limits,
            CollisionChecker& collisions, Tracer& tracer, const CycleClock& clock);

  // The hard checks of a cycle: the cheapest candidate that passes every check is taken as
  // ws's winner (Workspace::TakeWinner) and true returned. False when none passes, or when the
  // deadline (CycleClock::ChecksOver) cut it short: then *over_budget is set. Untraced, every
  // candidate goes through CheapestPassing; traced, the traced ranks (at least
  // kTracedRanksMin) are checked in cost order first (Scorer::SortUpTo), the Frenet-only
  // collision test before the limits, each traced with why it was rejected, and the rest
  // through CheapestPassing: the same winner. Counts go to *summary.
  bool Select(bool none_passed_before, PlanSummary* summary, bool* over_budget);

  // The cheapest candidate of ranks [r0, n) that passes every check, -1 when none does (or the
  // deadline cut it short: then *cut is set). They are taken by cost bound, smallest first
  // (a heap: only the ones taken are ordered; a coarse bound that comes up is completed and
  // queued again, so they come up in the order of complete bounds, Scorer::SortUpTo's
  // argument), and tested for collision; one that does not collide waits in a second heap,
  // by its bound until it comes up there, then by its exact cost (the same laziness: a clear
  // one that never comes up is never costed in full). The cheapest waiting one is the
  // cheapest candidate that does not collide once no bound left ranks before its cost: it is
  // tested for the hard limits then, and is the answer when it passes (every cheaper one
  // collides or breaks a limit). So no candidate that collides is costed in full, and only
  // the cheapest clear ones are converted to XY. After kRestHeapTests the rest are taken in any
  // order, each skipped when its bound is not below the cost of the cheapest that passed: the same
  // cheapest one. Every one tested counts as checked, and as rejected when it collides or
  // breaks a limit (one outranked by a passing one is neither).
  // none_passed_before: the last search found no candidate passing either (a hint: the same
  // answer, less work). Counts go to *summary (checked, feasible, rejections).
  int CheapestPassing(int r0, bool none_passed_before, PlanSummary* summary, bool* cut);

 private:
  // Whether candidate c is for the least harm alone (LatTraj::least_harm_only): only ever so
  // with grid.escape_lat_least_harm, so without it no candidate's move is read.
  bool LeastHarmOnly(int c) const {
    return cfg_.lat.escape_least_harm && ws_.lat[ws_.cand_lat[c]].least_harm_only;
  }
  const Settings& cfg_;
  Workspace& ws_;
  Scorer& scorer_;
  LimitChecker& limits_;
  CollisionChecker& collisions_;
  Tracer& tracer_;
  const CycleClock& clock_;
  std::vector<std::pair<double, int>> rest_;   // candidates: a heap by bound
  std::vector<std::pair<double, int>> clear_;  // collision-free ones: a heap by cost (by a
                                               // bound until they come up)
  std::vector<char> popped_;                   // taken from the heap
};

}  // namespace frenetic::plan::search

#include "plan/search/refiner.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "frenetic/plan/scratch_heap.h"

namespace frenetic::plan::search {
namespace {

nlopt_algorithm AlgorithmFromName(const std::string& name) {
  const nlopt_algorithm a = nlopt_algorithm_from_string(name.c_str());
  return static_cast<int>(a) < 0 ? NLOPT_LN_COBYLA : a;
}

}  // namespace

Refiner::Refiner(const Settings& cfg, const std::string& algorithm, Workspace& ws,
                 const Lattice& lattice, Scorer& scorer, LimitChecker& limits,
                 CollisionChecker& collisions, const CycleClock& clock)
    : cfg_(cfg),
      ws_(ws),
      lattice_(lattice),
      scorer_(scorer),
      limits_(limits),
      collisions_(collisions),
      clock_(clock),
      opt_(nlopt_create(AlgorithmFromName(algorithm), 4)) {
  // NLopt evaluates at most refine.max_iterations points; one more for the start.
  evals_seen_.reserve(std::max(cfg_.refine.iterations, 0) + 2);
  if (opt_ != nullptr) {
    nlopt_set_min_objective(opt_, &Refiner::Objective, this);
    constraints_ok_ =
        nlopt_add_inequality_constraint(opt_, &Refiner::Constraint, this, 1e-6) == NLOPT_SUCCESS;
    nlopt_set_maxeval(opt_, cfg_.refine.iterations);
    // NLopt allocates its step array at the first call: here, not in the first refined cycle
    // (which may come long after warm-up, e.g. after a constant-acceleration start).
    const double step[4] = {1.0, 1.0, 1.0, 1.0};
    nlopt_set_initial_step(opt_, step);
  }
}

Refiner::~Refiner() {
  if (opt_ != nullptr) nlopt_destroy(opt_);
}

traj::FrenetTrajectory Refiner::FromParams(const double* x) const {
  const LonTraj& base = ws_.lon[ws_.winner_lon];
  const LatTraj& lbase = ws_.lat[ws_.winner_lat];
  LonTraj l = lattice_.MakeLon(base.kind, base.lane, x[0], x[1], base.lead);
  LatTraj d = lattice_.MakeLat(lbase.lane, x[3], x[2]);
  return {l.traj, d.traj};
}

Refiner::Eval* Refiner::Find(const double* x) {
  for (Eval& e : evals_seen_) {
    if (std::memcmp(e.x, x, sizeof(e.x)) == 0) return &e;
  }
  return nullptr;
}

Refiner::Eval& Refiner::Entry(const double* x) {
  if (Eval* e = Find(x)) return *e;
  // Past the reserved capacity (an algorithm that overruns maxeval), the oldest is reused
  // rather than allocating.
  if (evals_seen_.size() == evals_seen_.capacity()) evals_seen_.erase(evals_seen_.begin());
  Eval& e = evals_seen_.emplace_back();
  std::memcpy(e.x, x, sizeof(e.x));
  e.has_f = e.has_g = false;
  return e;
}

double Refiner::Objective(unsigned n, const double* x, double* grad, void* data) {
  (void)n;
  (void)grad;  // derivative-free
  // The planner's own buffers outlive the refinement: not from the scratch slot.
  const heap::ScratchPause ours;
  auto* self = static_cast<Refiner*>(data);
  ++self->evals_;
  Eval& seen = self->Entry(x);
  if (seen.has_f) return seen.f;
  const traj::FrenetTrajectory tr = self->FromParams(x);
  const Workspace& ws = self->ws_;
  double v = self->scorer_.CostOf(tr, ws.lon[ws.winner_lon], ws.lat[ws.winner_lat]);
  if (!self->constraints_ok_) {
    // Algorithms without constraint support get the limits as a steep penalty.
    self->ws_.FillTicks(tr);
    v += 1e3 * std::max(0.0, self->limits_.Violation(nullptr));
  }
  seen.f = v;
  seen.has_f = true;
  return v;
}

double Refiner::Constraint(unsigned n, const double* x, double* grad, void* data) {
  (void)n;
  (void)grad;
  const heap::ScratchPause ours;
  auto* self = static_cast<Refiner*>(data);
  Eval& seen = self->Entry(x);
  if (seen.has_g) return seen.g;
  self->ws_.FillTicksForLimits(self->FromParams(x));
  seen.g = self->limits_.Violation(nullptr);
  seen.has_g = true;
  return seen.g;
}

void Refiner::Refine(PlanSummary& sum) {
  const LonTraj& lb = ws_.lon[ws_.winner_lon];
  const LatTraj& db = ws_.lat[ws_.winner_lat];
  // Braking is the emergency family, and a constant acceleration already the quickest run up:
  // both are sent as sampled.
  if (lb.kind == cost::LonKind::kBraking || lb.kind == cost::LonKind::kAccelerating) return;
  double x[4] = {lb.param, lb.traj.duration, db.traj.duration, db.offset};
  double lo[4], hi[4];
  switch (lb.kind) {
    case cost::LonKind::kVelocityKeeping:
      lo[0] = 0;
      hi[0] = ws_.ctx.lane_speed_limit[db.lane];
      break;
    case cost::LonKind::kFollowing:
      lo[0] = -5;
      hi[0] = 30;
      break;
    case cost::LonKind::kStopping:
      lo[0] = 0;
      hi[0] = std::max(1.0, ws_.start.s_d * cfg_.grid.max_duration);
      break;
    case cost::LonKind::kBraking:
    case cost::LonKind::kAccelerating:
      return;
  }
  lo[1] = cfg_.grid.min_duration;
  hi[1] = cfg_.grid.max_duration;
  lo[2] = std::min(cfg_.lat.min_duration, db.traj.duration);
  hi[2] = std::max(cfg_.lat.max_duration, db.traj.duration);
  lo[3] = -0.5;
  hi[3] = 0.5;
  for (int i = 0; i < 4; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
  const double before = scorer_.CostOf(ws_.winner, lb, db);
  sum.refine_cost_before = before;
  sum.refine_cost_after = before;
  nlopt_set_lower_bounds(opt_, lo);
  nlopt_set_upper_bounds(opt_, hi);
  // The first steps: a tenth of each range. Explicit, or NLopt would keep the step it derived
  // from the first refinement ever run (state carried across cycles and episodes).
  double step[4];
  for (int i = 0; i < 4; ++i) step[i] = std::max(1e-3, 0.1 * (hi[i] - lo[i]));
  nlopt_set_initial_step(opt_, step);
  const double remaining = 0.8 * cfg_.budget_ms - clock_.Elapsed();
  const double maxtime_ms = std::min(cfg_.refine.budget_ms, remaining);
  // 0 switches NLopt's clock off: pinned deadlines leave refine.max_iterations as the bound.
  nlopt_set_maxtime(opt_, std::isfinite(maxtime_ms) ? std::max(1e-3, maxtime_ms) * 1e-3 : 0.0);
  evals_ = 0;
  evals_seen_.clear();
  // The start is mostly the winner itself (its parameters within the bounds): its cost is
  // `before` and its limits were measured by the check (CandidateViolation measures the same
  // ticks as FillTicks and Violation).
  if (constraints_ok_) {
    const traj::FrenetTrajectory start = FromParams(x);
    if (std::memcmp(&start, &ws_.winner, sizeof(start)) == 0) {
      Eval& e = Entry(x);
      e.f = before;
      e.g = limits_.CandidateViolation(ws_.winner_index, nullptr);
      e.has_f = e.has_g = true;
    }
  }
  double best = 0;
  nlopt_result r;
  {
    // NLopt mallocs its work arrays on every call: from the thread's scratch slot, so that a
    // refined cycle makes no heap allocation after warm-up.
    const heap::ScratchScope scratch;
    r = nlopt_optimize(opt_, x, &best);
  }
  sum.refine_iterations = evals_;
  if (r < 0 || !Finite(best) || best >= before) return;
  // Safety re-check of the refined trajectory; keep the unrefined winner if it fails.
  const traj::FrenetTrajectory refined = FromParams(x);
  ws_.FillTicks(refined);
  const Eval* seen = Find(x);  // the result is a point NLopt evaluated
  const double violation = seen != nullptr && seen->has_g ? seen->g : limits_.Violation(nullptr);
  if (violation > 0 || collisions_.Collides()) return;
  ws_.winner = refined;
  sum.refine_cost_after =
      seen != nullptr && seen->has_f && constraints_ok_ ? seen->f : scorer_.CostOf(refined, lb, db);
}

}  // namespace frenetic::plan::search

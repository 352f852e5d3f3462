// Local refinement of the search planner's winner with NLopt (COBYLA by default: derivative-free,
// with the hard limits as an inequality constraint): the continuous parameters of the winner's
// family — its lon parameter, lon and lat durations, lateral offset — are optimised for the
// weighted cost within bounds around the lattice, then the result is checked again; the
// unrefined winner stays whenever the refined one is not cheaper, feasible and collision-free.
#pragma once

#include <nlopt.h>

#include <string>
#include <vector>

#include "frenetic/plan/planner.h"
#include "frenetic/traj/frenet.h"
#include "plan/search/collisions.h"
#include "plan/search/lattice.h"
#include "plan/search/limits.h"
#include "plan/search/scoring.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

class Refiner {
 public:
  // `algorithm`: an NLopt algorithm name (nlopt_algorithm_from_string); unknown names fall back
  // to NLOPT_LN_COBYLA. Everything referenced must outlive the refiner.
  Refiner(const Settings& cfg, const std::string& algorithm, Workspace& ws, const Lattice& lattice,
          Scorer& scorer, LimitChecker& limits, CollisionChecker& collisions,
          const CycleClock& clock);
  ~Refiner();
  Refiner(const Refiner&) = delete;
  Refiner& operator=(const Refiner&) = delete;

  // False when NLopt could not create the optimiser: Plan() then skips refinement.
  bool available() const { return opt_ != nullptr; }

  // Refines ws.winner in place (braking winners are sent as sampled) within the time left of
  // 80% of budget_ms and refine.budget_ms; fills sum.refine_iterations and refine_cost_*.
  // Leaves ws.tk_* overwritten.
  void Refine(PlanSummary& sum);

  // The trajectory for refinement parameters x = [param, T, T_lat, offset] of the winner's
  // families.
  traj::FrenetTrajectory FromParams(const double* x) const;

 private:
  static double Objective(unsigned n, const double* x, double* grad, void* data);
  static double Constraint(unsigned n, const double* x, double* grad, void* data);

  // The objective and constraint values at the parameters evaluated in this refinement (the
  // start, when it is the winner itself, and every point NLopt asked for), so that a point asked
  // for again, the start and the result's re-check reuse them: the same values, the trajectory
  // being a function of x and the cost and the limits of the trajectory.
  struct Eval {
    double x[4];
    double f, g;
    bool has_f, has_g;
  };
  Eval* Find(const double* x);
  Eval& Entry(const double* x);

  const Settings& cfg_;
  Workspace& ws_;
  const Lattice& lattice_;
  Scorer& scorer_;
  LimitChecker& limits_;
  CollisionChecker& collisions_;
  const CycleClock& clock_;
  nlopt_opt opt_ = nullptr;
  bool constraints_ok_ = false;
  int evals_ = 0;
  std::vector<Eval> evals_seen_;  // capacity fixed at construction
};

}  // namespace frenetic::plan::search

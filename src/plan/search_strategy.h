// The strategic layer above the lattice: which lane to aim for over the next strategy.horizon
// seconds (20), and through which gap. The lattice sees 6 s; a free lane beyond a neighbour
// whose car drives alongside, or a neighbour lane that will be a queue, shows only later.
//
// The traffic is rolled out once per decision on the predictor's cars (their braking and lane
// changes, the traffic's own lane-change rule as ghosts), every car held behind the one ahead
// in its lane (a queue forms behind a slow car). Then each plan is rolled out for the ego, in
// the manner of the prediction- and cost-function-based (PCB) behavioural planner of Wei,
// Snider, Gu, Dolan and Litkouhi (IEEE IV 2014): a lane sequence (stay; the next lane; the
// lane beyond it; there and back after a pass) and, for the first change, how to reach a gap:
// as soon as one opens, after dropping back behind a car of the next lane, or after getting
// ahead of one. The ego follows its leaders by the intelligent driver model (Treiber, Hennecke,
// Helbing, Phys. Rev. E 2000); a lane change starts when the gap passes the hard checks'
// rules (room ahead for the headway and the closing speed, room behind for a faster car),
// takes strategy.change_time and holds the ego behind the leaders of both lanes meanwhile. A
// plan is worth the distance it covers, plus the end speed kept for strategy.terminal_time,
// less strategy.change_cost per lane change (plus strategy.hold for the lane the last
// decision aimed at).
//
// The choice enters the lattice only as costs (cost::StrategyGoal, read by the `strategy`
// term): every plan's regret against the best, for the lanes a candidate can follow it in,
// and, for a plan that must drop back or get ahead first, where along s the candidate has to
// be when that plan changes lanes. The hard checks still decide what is feasible.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frenetic/cost/cost_term.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/predictor.h"
#include "plan/search_settings.h"

namespace frenetic::plan::search {

struct Workspace;

class Strategy {
 public:
  // Reads the cycle's context from `ws` and the traffic from `predictor`; both must outlive it.
  Strategy(const Settings& cfg, const Predictor& predictor, Workspace& ws);

  // Forgets the last decision and the cars' cruising speeds (a new episode).
  void Reset() {
    last_final_lane_ = last_car_ = -1;
    last_mode_ = StrategyPlan::Mode::kKeep;
    num_cruise_ = 0;
  }

  // Weighs the plans from the cycle's start state (ws.start, ws.t_keep, the lanes and limits of
  // ws.ctx; BuildContext first) on the predictor's cars; `elapsed` is the time since the last
  // decision (s; 0 when unknown). Writes the options to ws.strategy_goal and points
  // ws.ctx.strategy at it; *summary receives the plans weighed (the best of each kind) and the
  // one chosen. Deterministic; does not allocate.
  void Decide(double elapsed, StrategySummary* summary);

  // The rollouts' step (strategy.dt) and number of steps (over strategy.horizon).
  double dt() const { return dt_; }
  int steps() const { return steps_; }

 private:
  static constexpr int kMaxPolicies = 32;
  // One plan: the lanes it changes to in order, and how it reaches the first gap.
  struct Policy {
    std::array<int, 2> lanes{-1, -1};
    int count = 0;  // lane changes in the plan
    StrategyPlan::Mode mode = StrategyPlan::Mode::kKeep;
    int car = -1;  // traffic index of the car it drops back behind or gets ahead of
  };
  // What a rollout gives: the value and what the options need.
  struct Outcome {
    double value = 0, progress = 0;
    double t_change[2] = {-1, -1};  // s when each lane change starts (-1: never)
    int changes = 0;
    double s_ref = 0, t_ref = 0;  // the ego's s at the first change (or the horizon's end)
  };

  // Each car's cruising speed: the fastest it went lately (kCruiseDecay m/s less per second).
  void UpdateCruise(double elapsed);
  double CruiseOf(int id) const;
  void RollOutTraffic();
  // The lanes whose lists hold a car of lateral offset d and half width hw: its lane, and the
  // neighbour its body reaches into mid lane change (-1 when none).
  void LanesOf(double d, double hw, int* primary, int* secondary) const;
  void Simulate(const Policy& p, Outcome* out) const;
  // The IDM acceleration of the ego at speed v toward v0 behind a leader `gap` m ahead (bumper
  // to bumper) at speed v_lead; gap = inf for none.
  double Idm(double v, double v0, double gap, double v_lead) const;
  // Whether the ego at (s, v) may start a lane change into `lane` at step k under plan p.
  bool Accept(const Policy& p, bool first, int k, int lane, int from, double s, double v) const;
  // The nearest car ahead of s in `lane` at step k (traffic index, -1: none), by its rear.
  int LeaderAt(int k, int lane, double s) const;
  // Adds the options of plan p (its outcome o, its regret in m) to scratch_.
  void Emit(const Policy& p, const Outcome& o, double regret);

  const Settings& cfg_;
  const Predictor& predictor_;
  Workspace& ws_;
  double dt_ = 0.5;
  int steps_ = 40;
  int current_lane_ = 0;  // the lane the plans start from (the committed one)
  // The last decision: the lane it aimed at, and how it reached its first gap.
  int last_final_lane_ = -1, last_car_ = -1;  // last_car_: sensor id
  StrategyPlan::Mode last_mode_ = StrategyPlan::Mode::kKeep;
  struct Cruise {
    int id;
    double v;  // m/s
  };
  std::array<Cruise, kMaxCars> cruise_{}, cruise_next_{};
  int num_cruise_ = 0;
  // The traffic at step k (strategy.dt apart from the start state), [k * kMaxCars + c]: s
  // (unwrapped, the start's frame) and speed; per lane, its cars in s order,
  // [(k * kMaxLanes + l) * kMaxCars + j], lane_count_[k * kMaxLanes + l] of them.
  int num_cars_ = 0;
  std::vector<double> tr_s_, tr_v_;
  std::vector<std::uint8_t> tr_lane_;  // the primary lane of each car (0xff: none)
  std::vector<std::int8_t> lane_list_;
  std::vector<int> lane_count_;
  std::array<double, kMaxCars> half_length_{}, half_width_{};
  std::array<int, kMaxCars> car_id_{};
  std::array<double, kMaxCars> disp_{};  // RollOutTraffic: the predicted s of the last step
  std::array<Policy, kMaxPolicies> policies_{};
  std::array<Outcome, kMaxPolicies> outcomes_{};
  std::array<cost::StrategyOption, 3 * kMaxPolicies> scratch_{};  // every plan's options
  int scratch_count_ = 0;
};

}  // namespace frenetic::plan::search

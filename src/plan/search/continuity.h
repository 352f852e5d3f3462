// Continuity of the search planner's output with what the simulator drives: the stored plan
// (Frenet states and XY points), how many of its points were consumed and whether
// previous_path is still ours, the kept points a new search starts after, the driven history
// the jerk windows need, the lane-line timer over driven points, the shift that keeps s in
// [0, L), and plan reuse: re-sending the stored plan minus the consumed points between searches
// while the traffic does what was predicted.
#pragma once

#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/plan/planner.h"
#include "frenetic/traj/frenet.h"
#include "plan/search/limits.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

class Continuity {
 public:
  // Everything referenced must outlive this.
  Continuity(const Settings& cfg, const map::ReferenceLine& line, Workspace& ws,
             const CycleClock& clock);

  // Forgets the stored plan, the history and the reuse state (a new episode).
  void Reset();

  // How the telemetry relates to the stored plan: `consumed` points were driven, and
  // `synced` when previous_path is the rest of the stored plan (its first and last points
  // within continuity.resync_tolerance). prev_ok / ego_ok: previous_path / the ego pose are
  // finite and plausible. With an unusable pose the plan is followed as if one tick passed.
  struct Sync {
    int consumed = 0;
    bool synced = false;
  };
  Sync Synchronise(const Telemetry& t, bool prev_ok, bool ego_ok) const;

  // Whether the stored plan may be re-sent minus the consumed points instead of searching.
  bool CanReuse(const Telemetry& t, int consumed) const;
  // Re-sends the stored plan minus the consumed points into `result`: O(path), no allocation.
  void ReusePlan(int consumed, PlanResult& result);

  // Drops the consumed points into the history, moves the next `kept` points to the front and
  // returns the last kept one's state: the search's start. Sets ws.straddle_at_start; *elapsed
  // receives the time (s) from the stored plan's start state to this one.
  traj::FrenetState KeepPoints(int consumed, int kept, double* elapsed);
  // After losing sync: no history, the lane-line timer restarts.
  void Desync();
  // The start state when previous_path is not the stored plan's rest: from the measured pose
  // and speed (ego_ok), the lateral rate clamped to +-2 m/s and s' to [0, max_speed]; with an
  // unusable pose, at rest in the middle lane.
  traj::FrenetState MeasuredStart(const Telemetry& t, bool ego_ok) const;
  // Keeps start.s in [0, L): shifts it, the kept points and ws.prev_traj by whole loops.
  void Rebase(traj::FrenetState& start, int kept);
  // Gives the limit checks the XY prefix of every candidate: history, then the kept points.
  void SetXyPrefix(LimitChecker& limits) const;

  // Stores the kept points plus ws.tk_* as the new plan and writes it to result (x, y), a
  // non-finite point replaced by the last finite one.
  void Store(PlanResult& result);
  // After a search: whether its plan may be reused, and the traffic it saw (telemetry `t`).
  void SearchDone(const Telemetry& t, bool can_reuse);
  // The search winner's summary fields, reported again by reused cycles.
  void RememberWinner(int lane, double end_speed, double duration) {
    reuse_lane_ = lane;
    reuse_end_speed_ = end_speed;
    reuse_duration_ = duration;
  }

  bool have_plan() const { return have_plan_; }
  int plan_n() const { return plan_n_; }
  double plan_s(int i) const { return plan_s_[i]; }

 private:
  void PushHistory(int consumed);
  void Snapshot(const Telemetry& t);
  bool Relevant(double x, double y, double ego_x, double ego_y) const;

  const Settings& cfg_;
  const map::ReferenceLine& line_;
  Workspace& ws_;
  const CycleClock& clock_;

  bool have_plan_ = false;
  int plan_n_ = 0;
  int plan_start_index_ = 0;  // index of the start state of the stored plan's new part
  std::vector<double> plan_s_, plan_sd_, plan_sdd_, plan_d_, plan_dd_, plan_ddd_, plan_x_, plan_y_;
  std::vector<double> hist_x_, hist_y_;  // the last kHistory driven points, oldest first
  int hist_n_ = 0;
  // Consecutive ticks the simulator may have read the ego astride a lane line, up to the last
  // driven point.
  int straddle_ticks_ = 0;

  // Plan reuse between full searches (see CanReuse): the traffic the last search saw.
  struct SnapCar {
    int id;
    double x, y, vx, vy;
  };
  static constexpr int kMaxSnap = 64;
  SnapCar snap_[kMaxSnap] = {};
  int snap_n_ = 0;
  double snap_ego_x_ = 0, snap_ego_y_ = 0;
  int ticks_since_search_ = 0;
  bool can_reuse_ = false;
  int reuse_lane_ = -1;
  double reuse_end_speed_ = 0, reuse_duration_ = 0;
};

}  // namespace frenetic::plan::search

// The search planner's limit checks (filters with a named reason, never costs): a candidate
// sampled at every 0.02 s tick of the check horizon must stay on the road and never go
// backwards, keep the simulator's lane-line timer on d as the simulator reads it, and keep its
// speed, acceleration and jerk limits on the XY path (history | kept points | the ticks,
// feasibility.h). The collision checks are collisions.h.
#pragma once

#include <cstdint>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/plan/feasibility.h"
#include "frenetic/plan/planner.h"
#include "frenetic/traj/frenet.h"
#include "plan/search/bundle_rows.h"
#include "plan/search/settings.h"
#include "plan/search/workspace.h"

namespace frenetic::plan::search {

// Whether read d in [lo, hi] (m) comes within kStraddle of a lane line: the simulator's
// lane-line timer runs then.
inline bool StraddlesRead(const Settings& cfg, double lo, double hi) {
  for (int l = 1; l < cfg.road.num_lanes; ++l) {
    const double line = l * cfg.road.lane_width;
    if (hi > line - kStraddle && lo < line + kStraddle) return true;
  }
  return false;
}
// Whether the simulator may read d within kStraddle of a lane line for a point with s in
// [s0, s1] and d in [d0, d1] (it reads d from chords: ReferenceLine::ChordOffset). Never on a
// road that is not uniform: the lane-line timer is the Udacity simulator's.
inline bool Straddles(const Settings& cfg, const map::ReferenceLine& line, double s0, double s1,
                      double d0, double d1) {
  if (!cfg.road.uniform) return false;  // the Udacity simulator's timer only
  const map::ReferenceLine::OffsetRange r = line.ChordOffset(s0, s1, 0.5 * (d0 + d1));
  return StraddlesRead(cfg, d0 + r.lo, d1 + r.hi);
}

class LimitChecker {
 public:
  // `line` and `ws` must outlive the checker; it reads the start state of ws and the ticks
  // ws.tk_* (Workspace::FillTicks).
  LimitChecker(const Settings& cfg, const map::ReferenceLine& line, Workspace& ws);

  // The XY path's part common to every candidate of the cycle, the driven history then the
  // kept points (oldest first), measured once.
  void SetXyPrefix(const double* hist_x, const double* hist_y, int hist_n, const double* kept_x,
                   const double* kept_y, int kept);

  // The worst normalised excess over all limits of the ticks ws.tk_* (<= 0: feasible), and the
  // first reason (kCount when feasible; reason may be null). lane_line: include the lane-line
  // timer (the least-harm choice may drop it: a collision is worse). NaN counts as a violation.
  double Violation(Reject* reason, bool lane_line = true);

  // Candidate c's Violation(reason) (lane-line timer included) after Workspace::FillTicks of
  // it, remembered for its trajectory until the next SetXyPrefix: the least-harm choice asks
  // again about candidates the lazy check has measured. Measured on its bundles' ticks: ws.tk_*
  // are left as they are.
  double CandidateViolation(int c, Reject* reason);
  // Whether candidate c breaks a limit: CandidateViolation(c, nullptr) > 0, the same answer,
  // but the checks stop at the first limit found broken (the lane-line timer of a car long
  // astride a line, say, or the speeds braking harder than the acceleration limit), so that
  // no worst excess is known then (a later CandidateViolation measures it all). first
  // (optional): a limit it breaks, the first one found (the worst one when a whole verdict
  // was remembered).
  bool CandidateBreaksLimits(int c, Reject* first = nullptr);
  // Whether candidate c breaks a limit other than the lane-line timer over every tick of the
  // check horizon (Violation(nullptr, false) > 0 after Workspace::FillTicks of it, the same
  // answer): measured on its bundles' ticks, not remembered, ws.tk_* left as they are.
  bool CandidateBreaksLimitsBesidesTheLaneLine(int c);

  // The lane-line timer's limit (ticks astride a line, from the start's count) the checks hold
  // a trajectory to: kMaxStraddleTicks unless set. The least-harm choice, when no candidate
  // keeps it, asks for the simulator's own count less a little (check.last_resort_ticks)
  // before it drops the timer.
  void SetStraddleLimit(int ticks) { straddle_limit_ = ticks; }

 private:
  // Violation's read-d window from tick prev to tick i of the ticks s, d: the range of d as the
  // simulator may read it there.
  struct ReadRange {
    double lo, hi;
  };
  ReadRange ReadBetween(const double* s, const double* d, int prev, int i) const;
  // On a road that is not uniform: how far (m) the read d range of ticks with s from s0 to s1
  // comes past the road's edges there, less the ego's half width and edge_margin (> 0: off the
  // road; no lane there counts as far off).
  double EdgeExcess(double s0, double s1, const ReadRange& read) const;

  // What Violation reads of the ticks [1, n_ticks]: s, s', d, and the centre line at s when
  // known (null: from the line, or from lon bundle slot lon_slot's row when that is >= 0,
  // sampled there on first use: a candidate the Frenet checks reject does not need it).
  struct Ticks {
    const double *s, *sd, *d;
    const map::CentrePoint* centre;
    int lon_slot = -1;
    int n = 0;  // the ticks [1, n] are measured (0: all, n_ticks)
  };
  // Appends the ticks to the XY prefix; returns the path length.
  int BuildXyPath(const Ticks& ticks);
  // Violation of `ticks` (ws.tk_*, or a candidate's bundle rows). any: a positive value as soon
  // as one limit is found broken (not the worst, and no reason).
  double Measure(Reject* reason, bool lane_line, const Ticks& ticks, bool any = false);
  // CandidateViolation's work: Measure of candidate c's bundle ticks, through the verdicts.
  double CandidateMeasure(int c, Reject* reason, bool any);
  // Its bundles' ticks (sampled anew when the slots hold other trajectories).
  Ticks CandidateTicks(int c, const traj::FrenetTrajectory& tr, int n);
  // Settings::curve_prefilter: how far (a share of limits.max_accel, > 0: over) a lower bound
  // of the XY check's lateral acceleration on the ticks [1, n_ticks] lies above
  // (1 + kCurveSlack) x the limit, from the line's curvature and each tick's own d; <= 0 when
  // it says nothing. The lattice's curve prefilter must assume any d within the road, which
  // on a hairpin lets through bundles that every lateral move of the cycle takes too fast.
  double CurveExcess(const Ticks& ticks, int n_ticks) const;

  const Settings& cfg_;
  const map::ReferenceLine& line_;
  Workspace& ws_;
  XyChecker xy_;
  std::vector<double> chk_x_, chk_y_;  // the XY path: prefix | ticks
  int first_new_ = 0;                  // the first tick's index in chk_x_ / chk_y_
  // CandidateViolation's verdicts per candidate index, with what they were measured for: the
  // trajectory, the XY prefix (prefix_stamp_, counted by SetXyPrefix) and the start's
  // lane-line count.
  struct Verdict {
    traj::FrenetTrajectory tr;
    std::uint64_t prefix_stamp = 0;
    int straddle = 0, straddle_limit = 0;
    Reject why = Reject::kCount;
    double worst = 0;
    bool any = false;  // measured with Measure(..., any): only worst > 0 is known
  };
  std::vector<Verdict> verdicts_;
  // CandidateViolation's ticks per bundle slot (Workspace::FillTicks' values), and the centre
  // line at the lon ones.
  BundleRows lon_ticks_, lat_ticks_;
  std::vector<map::CentrePoint> lon_centre_;
  std::vector<char> lon_centre_have_;  // lon_centre_'s row is the one of lon_ticks_' row
  std::uint64_t prefix_stamp_ = 1;
  int straddle_limit_ = kMaxStraddleTicks;
};

}  // namespace frenetic::plan::search

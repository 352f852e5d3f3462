// The search planner's lattice (Werling et al., ICRA 2010, §III): from the cycle's start state,
// a bundle of 1-D longitudinal trajectories (velocity keeping, following a lane's leader or
// yielding to the car alongside, stopping, constant-deceleration braking) and one of lateral
// moves to lane centres (with small offsets, and delayed starts), sampled on the scoring grid;
// the candidates are every compatible lon x lat pair.
#pragma once

#include "frenetic/cost/cost_term.h"
#include "frenetic/traj/frenet.h"
#include "plan/predictor.h"
#include "plan/search/settings.h"

namespace frenetic::plan::search {

struct Workspace;

// One longitudinal trajectory of the bundle.
struct LonTraj {
  traj::Trajectory1d traj;
  cost::LonKind kind = cost::LonKind::kVelocityKeeping;
  int lane = -1;  // -1: usable in every lane; else only with this lane's lateral moves
  // End speed (velocity keeping), extra gap (following), distance (stop), deceleration (braking),
  // acceleration (accelerating).
  double param = 0;
  int lead = -1;  // following: the leader's index in the predictor's cars of this cycle
  double jerk2 = 0;
  // Faster along s than the vehicle's top speed allows within the check horizon (Lattice::
  // TooFastForTheVehicle): paired with no lane move, whose checks reach that far.
  bool too_fast = false;
};

// What a lateral move of the bundle is.
enum class LatKind {
  kLane,    // to `lane`'s centre plus `offset` (m); keeping the lane is one (Lattice::MakeLat)
  kSwerve,  // into goal region `goal`, crossing it turned at the move's end (AddSwerves)
  kPass,    // out into the oncoming lane and back to `lane`: the trajectory's second move
            // (back_duration > 0; AddPasses)
};

// One lateral move of the bundle.
struct LatTraj {
  traj::Trajectory1d traj;
  LatKind kind = LatKind::kLane;
  int lane = 0;       // the lane it ends in (a swerve: the lane nearest its end)
  double offset = 0;  // m from that lane's centre at the end
  double jerk2 = 0;
  int goal = -1;  // a swerve's goal region (its index in the cycle's goals); -1 otherwise
  // Offered to the least harm only (an escape after a box-in:
  // Settings::Lateral::escape_least_harm); the selection skips it.
  bool least_harm_only = false;
  bool swerve() const { return kind == LatKind::kSwerve; }
  bool pass() const { return kind == LatKind::kPass; }
};

// m/s: the fastest a vehicle can be T s after v0 at its forward acceleration limit: the
// vehicle's (VehicleLimits::max_accel up to switch_speed, max_accel switch_speed / v above it,
// CommonRoad's rule) when it has one, else `max_accel` throughout.
double ReachableSpeed(const VehicleLimits& vehicle, double max_accel, double v0, double T);

class Lattice {
 public:
  // Reads the context (start state, lanes, traffic) from `ws`, which must outlive the lattice.
  Lattice(const Settings& cfg, const Predictor& predictor, Workspace& ws)
      : cfg_(cfg), predictor_(predictor), ws_(ws) {}

  // Fills ws.lon, ws.lat with their samples and masks, and ws.cand_lon / cand_lat with every
  // compatible pair, in a fixed order (the order ties break by). Needs the cycle's context.
  void Generate();

  // One trajectory of a family from the start state over T s; `param` as in LonTraj, `lead` the
  // leader's predictor index (following only). The result may be non-finite.
  LonTraj MakeLon(cost::LonKind kind, int lane, double param, double T, int lead = -1) const;
  // A quintic move to lane's centre + offset over T s, after `delay` s holding still.
  LatTraj MakeLat(int lane, double offset, double T, double delay = 0) const;
  // A quintic move into goal region `goal` over T s, ending at d with d' = d_d and d'' = d_dd
  // (a swerve).
  LatTraj MakeSwerve(int goal, double d, double d_d, double T, double d_dd) const;

 private:
  void AddLon(const LonTraj& l);
  void AddLat(const LatTraj& l);
  void AddBraking();
  void AddGapTargets(int lane, double T);
  void AddAccelerating(const bool reachable[], double vmax);
  void AddLimitRamps(double vgrid);
  // Astride a lane line with the lane-line timer nearly out: moves off it in time
  // (AddLineExits in lattice.cc says how long).
  void AddLineExits(const bool reachable[]);
  void AddSwerves();
  void AddSwerveUnderWay();
  void AddPasses();
  int Leader(int lane) const;
  int Alongside(int lane) const;
  // Settings::curve_prefilter: whether lon bundle i's v^2 kappa along the line rules out every
  // candidate of it (the XY check would reject them all).
  bool TooFastForTheCurve(int i) const;
  // Whether lon bundle i's s' at a scoring sample within the check horizon, times
  // Workspace::speed_share, is kSpeedSlack over limits.max_speed: its XY speed is then over the
  // limit whatever the lateral move, and the XY check rejects every candidate of it whose checks
  // reach that sample (all but a swerve's, which end at its goal region). Following or merging
  // behind a car of recorded traffic faster than the ego can drive (highD's move at twice their
  // stated speed) made a fifth of a highD box-in's candidates such ones, and four fifths of its
  // XY limit checks.
  bool TooFastForTheVehicle(int i) const;
  static constexpr double kSpeedSlack = 0.05;

  const Settings& cfg_;
  const Predictor& predictor_;
  Workspace& ws_;
};

}  // namespace frenetic::plan::search

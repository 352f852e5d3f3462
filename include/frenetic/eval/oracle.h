// How fast could any planner have driven an episode? After the drive, a search over the ego's
// lane, position and speed on a coarse grid (dynamic programming, one stage per `step` s)
// against the traffic as it moved (each exchange's sensor_fusion): the greatest distance along
// the road in the drive's time, without ever running into a car.
//
// The rules are those of a planner with frenetic's margins, and lean optimistic besides the
// foresight, so that a planner's shortfall from the result bounds what a lane strategy could
// still gain:
// - speeds on a grid of `speed_bin` up to `top_speed` along the road in every lane (on a bend
//   the outer lanes' real limit is lower), changing by at most max_accel / max_decel x step
//   per stage (+4 / -6 m/s^2 on the default grid); jerk is not limited;
// - a lane change takes `change` s: its first third in its lane, the middle astride both, the
//   last in the next; the next change may start one stage after it ends;
// - a car ahead is kept `gap` + headway x speed away; moving in front of a car in another lane
//   needs `room_behind` more, plus closing_time of the speed it closes in with;
// - cars behind the ego in its lane brake for it (the traffic's follow rule, udacity-sim.md
//   §8.3), and so do not block it; nor does a car ahead there moving away at least as fast;
// - a car is ignored for `spawn_grace` s after it (re)appears, and the road farther ahead than
//   the traffic reaches is empty.
// It is pessimistic in one way: the traffic moves as it did, not as it would have reacted to a
// different ego (the simulator respawns cars around the ego). Each window of `horizon` s starts
// again from the ego's state as it drove, which keeps that small.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "frenetic/plan/telemetry.h"
#include "frenetic/status.h"
#include "frenetic/units.h"

namespace frenetic::sim {

struct OracleOptions {
  double step = 0.5;         // s per stage
  double top_speed = 22.2;   // m/s along the road: the planner's straight-road target (49.7 mph)
  double speed_bin = 1.0;    // m/s between the speeds searched (plus top_speed itself)
  double max_accel = 5.0;    // m/s^2
  double max_decel = 7.0;    // m/s^2
  double s_bin = 0.5;        // m: of the states at one speed this near, the farthest is kept
  double gap = 4.6;          // m along the road between the ego's centre and a car's (a car length)
  double headway = 0.5;      // s: plus this long at the ego's speed to a car ahead (the planner's)
  double room_behind = 5.0;  // m: moving in front of a car in another lane, plus `gap`...
  double closing_time = 1.0; // s: ...plus this long at the speed it closes in with (the planner's)
  double change = 3.0;       // s a lane change takes: a third in its lane, a third astride, a
                             // third in the next (the planner's lateral moves take 2-4 s)
  double lane_width = 4.0;   // m
  int lanes = 3;
  double lane_reach = 2.9;   // m: a car whose d is this near a lane's centre is in that lane
  double spawn_grace = 1.0;  // s a car is ignored after it appears or jumps (a respawn)
  double behind = 60.0;      // m: states this far behind the ego as it drove are dropped
  double horizon = 20.0;     // s: each window's search starts from the ego's state as it drove
  // s: 0, the search knows the traffic over the whole window. Else a receding search: at each
  // stage it plans this far ahead (in whole stages) against the traffic as it will move and
  // takes the plan's first stage; what a planner that foresaw the traffic this long (and only
  // that long) could have driven, within the window, from the same start. It keeps no reserve
  // for what it cannot see: a plan may end where no way on is left (the window is then stuck).
  double foresight = 0.0;

  // Ok, or a one-line message naming the first invalid field.
  Status Validate() const;
};

// The traffic and the ego along one episode, one row per exchange.
class OracleTrace {
 public:
  explicit OracleTrace(double max_s) : max_s_(max_s) {}
  // One exchange's view: simulated time (s, increasing), the ego's s and d and speed (m/s) as
  // the simulator reports them (s wraps at max_s) and the traffic's rows.
  void Add(double t, double ego_s, double ego_d, double ego_speed,
           std::span<const plan::SensorCar> cars);

  struct Car {
    int id = 0;
    double s = 0, d = 0;  // s unwrapped like the ego's
    double since = 0;     // s since the car appeared or last jumped
  };
  struct Row {
    double t = 0, ego_s = 0, ego_d = 0, ego_speed = 0;  // ego_s unwrapped from the first row
    std::size_t first = 0, count = 0;                   // into cars()
  };
  const std::vector<Row>& rows() const { return rows_; }
  const std::vector<Car>& cars() const { return cars_; }

 private:
  double max_s_, raw_ego_s_ = 0;
  std::vector<Row> rows_;
  std::vector<Car> cars_;
  struct Last {
    bool seen = false;
    double t = 0, s = 0, d = 0, appeared = 0;
  };
  std::vector<Last> last_;  // by car id
};

// One window of the search.
struct OracleWindow {
  double t = 0;          // s, its start
  double driven_m = 0;   // the ego's distance along the road in it
  double best_m = 0;     // the search's, at least the ego's (the ego did drive it)
  // The search's own distance, before that floor: for the whole-window search -1 when it found
  // no way through; for a stuck receding search the distance it drove before it stopped.
  double search_m = 0;
  std::string lanes;     // the search's lane at each stage: a digit, '/' astride ('?' when it
                         // found no way through)
  std::vector<double> speeds;  // the search's speed at each stage, m/s
  std::string driven_lanes;  // the ego's lane at each stage (its d's)
  // With a foresight: the stage at which a receding search found no way on and stopped
  // (search_m then holds the distance it had driven), or -1.
  int stuck_stage = -1;
};

struct OracleResult {
  double seconds = 0;     // the time searched: the drive's, in whole stages
  double distance_m = 0;  // the best distance along the road in that time
  double driven_m = 0;    // the ego's own in the same time, as the trace has it
  std::vector<OracleWindow> windows;
  double foresight = 0;   // s: the foresight searched, in whole stages (0: each whole window)
  int stuck_windows = 0;  // with a foresight: windows where the receding search found no way on
  double mph() const { return seconds > 0 ? distance_m / seconds * units::kMpsToMph13 : 0; }
  double driven_mph() const { return seconds > 0 ? driven_m / seconds * units::kMpsToMph13 : 0; }
  // Over the windows the search went through (not stuck, a way found): its own distance, with
  // no floor, and the ego's, in their time. The fair figures of a receding search, whose
  // floored best_m credits it the ego's distance wherever the ego did better or it got stuck.
  double through_seconds = 0, through_search_m = 0, through_driven_m = 0;
  double through_search_mph() const {
    return through_seconds > 0 ? through_search_m / through_seconds * units::kMpsToMph13 : 0;
  }
  double through_driven_mph() const {
    return through_seconds > 0 ? through_driven_m / through_seconds * units::kMpsToMph13 : 0;
  }
};

// The search; an empty or one-row trace gives a zero result.
OracleResult SearchOracle(const OracleTrace& trace, const OracleOptions& options);

}  // namespace frenetic::sim

// Where a drive's time went, lap by lap: at the speed limit, following a slower car (and how
// much of that with a neighbour lane open, where a pass was there to take), passes made and
// missed. Measured from the simulator's own state every tick, so it is the same for an
// in-process planner and for any planner driven over the WebSocket.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "frenetic/map/reference_line.h"
#include "frenetic/sim/traffic.h"

namespace frenetic::sim {

// The thresholds of the breakdown (defaults are what the report uses).
struct BreakdownOptions {
  // mph: at or above this the ego is "at the limit" (the simulator flags 50 mph; planners aim
  // at 49.5 per tick, and XY speed on curves differs from s-speed by a few percent).
  double at_limit_mph = 48.0;
  // Following: below the limit with a car ahead in the ego's lane within
  // max(follow_min_gap, follow_time x ego speed), bumper to bumper.
  double follow_min_gap = 30.0;  // m
  double follow_time = 3.0;      // s
  // A neighbour lane is open when no car in it (by its d) is within [-open_behind, open_room]
  // of the ego's s (room to move in) and its nearest car farther ahead, within open_ahead, is
  // faster than the ego's leader by at least open_gain (the lane is the quicker way on).
  double open_behind = 12.0;  // m behind the ego
  double open_room = 20.0;    // m ahead of the ego
  double open_ahead = 100.0;  // m
  double open_gain = 1.0;     // m/s
  // A missed pass: while following, a neighbour lane stays open this long and the ego keeps its
  // lane (counted once per open spell).
  double missed_open_seconds = 3.0;  // s
};

struct LapBreakdown {
  int lap = 0;             // 0-based lap of the track (by distance driven)
  double seconds = 0;      // simulated s in this lap
  double distance_m = 0;
  double at_limit_s = 0;
  double at_limit_m = 0;   // distance driven at the limit (its mean speed: how close to it)
  double following_s = 0;
  double following_open_s = 0;  // part of following_s with a neighbour lane open
  int passes = 0;               // cars the ego overtook (ahead in any lane -> behind)
  int passed_by = 0;            // cars that overtook the ego
  int missed_passes = 0;
  int lane_changes = 0;

  double avg_speed_mph() const;
  double at_limit_mph() const;  // mean speed while at the limit (0 if never)
  void Add(const LapBreakdown& other);  // sums every count and time (lap is kept)
  nlohmann::json ToJson() const;
};

// Accumulates a LapBreakdown per lap from per-tick samples.
class DriveBreakdown {
 public:
  explicit DriveBreakdown(const BreakdownOptions& options = {}) : opt_(options) {}

  // One tick of `dt` s: the ego after the tick, its lane (0..2, -1 off the carriageway) and
  // whether it just changed lane, the distance driven so far (m), the leader's bumper gap in the
  // ego's lane (+inf: none), the traffic and the line (for s differences and the lap length).
  void Update(double dt, const EgoView& ego, int ego_lane, bool lane_changed, double distance_m,
              double leader_gap, std::span<const TrafficCar> cars,
              const map::ReferenceLine& line);

  const std::vector<LapBreakdown>& laps() const { return laps_; }
  LapBreakdown Total() const;  // lap = number of laps started

 private:
  BreakdownOptions opt_;
  std::vector<LapBreakdown> laps_;
  struct Seen {
    int id = -1;
    double ds = 0;  // car s - ego s last tick
  };
  std::vector<Seen> seen_;  // by traffic slot
  double open_for_[3] = {0, 0, 0};  // s each neighbour lane has been open while following
  bool counted_[3] = {false, false, false};
};

}  // namespace frenetic::sim

// A road: lanes side by side along a reference line, the engine's model of any multi-lane
// carriageway. Lane 0 is the leftmost. Each lane has a left and a right border, as d (m,
// positive to the right of the line, ReferenceLine's convention), over the stretch of s where it
// exists, linear between stations: lanes may widen, shift, begin (an on-ramp) or end (a lane
// drop). The Udacity track is Road::Uniform: 3 lanes of 4 m from d = 0, the whole loop round; a
// CommonRoad lanelet network becomes a Road with commonroad::BuildRoad.
#pragma once

#include <limits>
#include <memory>
#include <string_view>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/status.h"

namespace frenetic::map {

// One lane's borders at stations along s (increasing, at least 2; left < right at each). The
// lane exists on [s.front(), s.back()].
struct LaneProfile {
  std::vector<double> s, left, right;  // m
  double speed_limit = std::numeric_limits<double>::infinity();  // m/s
  // Driven the other way (a two-way road's opposite lane): only for passing, against oncoming
  // traffic.
  bool oncoming = false;
  // m: where the lane's surface ends at a wall the planner stops before (a lanelet network's
  // closed end, past which the stations run on for the planner's horizons only); +inf: none.
  // A lane's own end before the road's end (a lane drop) is a wall anyway.
  double wall = std::numeric_limits<double>::infinity();
  // The lane's end is a lane drop: its traffic has to move into a lane beside before it (a
  // lanelet ending with no successor before the map's end, a zipper's half leading into the
  // other), not a lane that leaves the road there (an exit's lanes, seen from its ramp), nor
  // the map's end. Traffic predictions use it.
  bool drops = false;
};

class Road {
 public:
  // A lane's borders at some s; exists is false outside the lane's stretch (borders then NaN).
  struct Span {
    double left = 0, right = 0;  // m
    bool exists = false;
    double centre() const { return 0.5 * (left + right); }
    double width() const { return right - left; }
  };

  // `num_lanes` lanes of `lane_width` m from d = 0 to the right, the whole line long (on a loop:
  // every s). num_lanes in [1, 16], lane_width > 0 (CHECKed: callers validate their config).
  static std::shared_ptr<const Road> Uniform(std::shared_ptr<const ReferenceLine> line,
                                             int num_lanes, double lane_width);
  // Lanes from their profiles, left to right. Fails (naming `source` and the lane) on no lanes,
  // more than 16, fewer than 2 stations, stations not increasing, non-finite values or a right
  // border not right of the left one.
  static StatusOr<std::shared_ptr<const Road>> Make(std::shared_ptr<const ReferenceLine> line,
                                                    std::vector<LaneProfile> lanes,
                                                    std::string_view source);

  const ReferenceLine& line() const { return *line_; }
  const std::shared_ptr<const ReferenceLine>& line_ptr() const { return line_; }
  int num_lanes() const { return static_cast<int>(lanes_.size()); }
  // Whether this is the Uniform layout (equal lanes from d = 0, everywhere): the planner keeps
  // the Udacity simulator's conventions on it (d read from the map's chords, lane lines at
  // multiples of the width).
  bool uniform() const { return uniform_; }
  // The lanes' typical width, m: Uniform's width, else the median over lanes and stations (a
  // scale for costs and tolerances).
  double lane_width() const { return lane_width_; }

  // Lane `lane`'s borders at s (wrapped on a loop). A lane index outside [0, num_lanes()) does
  // not exist.
  Span LaneAt(int lane, double s) const;
  // The stretch where the lane exists (on a loop: the whole real line).
  double LaneBegin(int lane) const;
  double LaneEnd(int lane) const;
  double SpeedLimit(int lane) const;  // m/s, +inf when none
  double Wall(int lane) const;        // LaneProfile::wall (NaN outside the lanes)
  bool Oncoming(int lane) const;      // LaneProfile::oncoming (false outside the lanes)
  bool Drops(int lane) const;         // LaneProfile::drops (false outside the lanes)
  // The road's edges at s: the leftmost existing lane's left border and the rightmost's right
  // border (exists false when no lane exists there).
  Span EdgesAt(double s) const;
  // The lane whose borders hold (s, d), the nearest centre's when several do; -1 when none.
  int LaneOf(double s, double d) const;
  // Where a move across from (s, d) in the direction of `toward`'s sign (a car changing lanes)
  // ends: the centre at s of the lane holding the point half a lane width on (of the lane
  // holding d when no lane does); NaN when that lane does not exist there or its centre does
  // not lie in the move's direction.
  double CentreToward(double s, double d, double toward) const;

 private:
  Road() = default;
  std::shared_ptr<const ReferenceLine> line_;
  std::vector<LaneProfile> lanes_;
  bool uniform_ = false;
  double lane_width_ = 0;
};

}  // namespace frenetic::map

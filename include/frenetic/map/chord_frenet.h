// The simulator's own Frenet conversion (udacity-sim.md §5.3): chord polyline through the
// waypoints, nearest waypoint of the *owner* position, float32 arithmetic. The headless
// simulator reports every s and d with it, exactly as the Unity simulator does. The §10 validation
// vectors reproduce to 1e-3 m (the spawned car's to 4e-3 m: its logged position is rounded).
// Sign of d: negative when p is at least as close to (1000, 2000) as its foot on the chord.
#pragma once

#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"

namespace frenetic::map {

class ChordFrenet {
 public:
  explicit ChordFrenet(const Track& track);

  // Frenet of p = (px, py) with the segment chosen from the owner position (ox, oy): the
  // end_path quirk. Results may be NaN, as in the simulator; callers substitute 0 where it does.
  FrenetPoint Convert(double px, double py, double ox, double oy) const;
  FrenetPoint Convert(double x, double y) const { return Convert(x, y, x, y); }

 private:
  std::vector<float> x_, y_, dx_, dy_, cum_s_;
};

}  // namespace frenetic::map

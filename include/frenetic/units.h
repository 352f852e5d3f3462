// Unit factors, in one place. Inside, everything is SI (STYLE.md §2); the simulator's mph and
// degrees are converted at the edges with these constants and no others.
//
// Two mph factors are in use and both are kept, because every output depends on their exact
// double values: the exact one (kMphToMps and its inverse) for configuration and reports, and the
// simulator's own (kSimMpsToMph), rounded to 8 decimals, for whatever must match its numbers.
#pragma once

#include <numbers>

namespace frenetic::units {

// The international mile: 1609.344 m exactly, so 1 mph = 0.44704 m/s exactly.
inline constexpr double kMetersPerMile = 1609.344;
inline constexpr double kMphToMps = 0.44704;
// m/s -> mph, the exact inverse to the double (2.2369362920544025).
inline constexpr double kMpsToMph = 1.0 / kMphToMps;
// kMpsToMph cut to 13 decimals, 6 ulps below it: the factor the predictor (its spawn-glitch undo)
// and the oracle's averages were written with. Kept so that their outputs do not move.
inline constexpr double kMpsToMph13 = 2.2369362920544;

// The Udacity simulator reports speed as |v| (m/s) times this factor (udacity-sim.md §3.3): the
// wire, the headless simulator, its traffic and its monitors use it, so that their mph values
// are the simulator's.
inline constexpr double kSimMpsToMph = 2.23693629;

inline constexpr double kDegToRad = std::numbers::pi / 180.0;
inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;

}  // namespace frenetic::units

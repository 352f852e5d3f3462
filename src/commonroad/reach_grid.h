// The grid the reachability searches (way_through.cc, rescue.cc) merge their states on, and the
// hash that orders their checks.
#pragma once

#include <cmath>
#include <cstdint>

namespace frenetic::commonroad::reach {

// The cell of a state of five values, packed in 64 bits (the first two, the position, 14 bits
// each, the others 12, wrapping: two states that far apart never meet in one step's set).
inline std::uint64_t CellOf(double x, double y, double c, double d, double e, const double cell[5]) {
  const auto bits = [](double value, double size, int width) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(value / size))) &
           ((std::uint64_t{1} << width) - 1);
  };
  return bits(x, cell[0], 14) << 50 | bits(y, cell[1], 14) << 36 | bits(c, cell[2], 12) << 24 |
         bits(d, cell[3], 12) << 12 | bits(e, cell[4], 12);
}

// splitmix64's finaliser: a cell's place in the checking order.
inline std::uint64_t Mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return z ^ (z >> 31);
}

}  // namespace frenetic::commonroad::reach

// Per bundle slot (a longitudinal or lateral trajectory of the lattice), the trajectory sampled
// at fixed times into rows, sampled again only when the slot's trajectory changes (compared
// bytewise): the many candidates that share a bundle sample it once. The limit checks keep rows
// at every tick, the collision checks at every collision step.
#pragma once

#include <cstddef>
#include <cstring>
#include <vector>

#include "frenetic/traj/frenet.h"

namespace frenetic::plan::search {

struct BundleRows {
  // `slots` rows of `width` samples (index 0 unused: samples [1, width)).
  void Resize(std::size_t slots, int width) {
    w = width;
    key.resize(slots);
    have.assign(slots, 0);
    p.assign(slots * w, 0.0);
    v.assign(slots * w, 0.0);
  }
  // Row i holds `tr` at time_of(j) for j in [1, w) (value and first derivative); true when
  // sampled anew, false when it already held it.
  template <typename TimeOf>
  bool Sample(const traj::Trajectory1d& tr, int i, TimeOf time_of) {
    if (have[i] && std::memcmp(&key[i], &tr, sizeof(tr)) == 0) return false;
    tr.Sample(1, w, time_of, &p[i * w], &v[i * w], nullptr);
    std::memcpy(&key[i], &tr, sizeof(tr));
    have[i] = 1;
    return true;
  }

  int w = 0;                            // samples per row
  std::vector<traj::Trajectory1d> key;  // the trajectory each row holds
  std::vector<char> have;               // whether it holds one
  std::vector<double> p, v;             // [slot * w + j]
};

}  // namespace frenetic::plan::search

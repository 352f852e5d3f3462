// The processes of one tuning run: a single process, or the ranks of an `mpirun` launch when
// frenetic was built with MPI (FRENETIC_HAVE_MPI). Rank 0 runs the search; the others evaluate
// their share of each evaluation's episodes. No MPI type appears here.
#pragma once

#include <string>
#include <vector>

namespace frenetic::tune {

class Cluster {
 public:
  // Initialises MPI only when built with it and launched by mpirun (OMPI_COMM_WORLD_SIZE or
  // PMI_SIZE in the environment), so a plain run needs no MPI runtime. At most one Cluster may
  // be created per process (MPI cannot be re-initialised).
  Cluster();
  ~Cluster();  // finalises MPI if this object initialised it
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

  // A single-process cluster without touching MPI (tests, tools).
  static const Cluster& Local();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool distributed() const { return size_ > 1; }

  // Collective operations (every rank must call them in the same order). Broadcast copies rank
  // 0's `data` to every rank (the size is sent too). SumToRoot adds every rank's `data`
  // (same size everywhere) element-wise into rank 0's; the sum runs in rank order, so a value
  // that only one rank sets (others 0) arrives exactly.
  void Broadcast(std::vector<double>* data) const;
  void SumToRoot(std::vector<double>* data) const;
  // Every rank's `data` (bytes, any length) on rank 0, in rank order (its own first); an empty
  // vector on the other ranks.
  std::vector<std::string> GatherToRoot(const std::string& data) const;

 private:
  struct LocalTag {};
  explicit Cluster(LocalTag) {}
  int rank_ = 0, size_ = 1;
  bool initialised_mpi_ = false;
};

}  // namespace frenetic::tune

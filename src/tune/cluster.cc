#include "frenetic/tune/cluster.h"

#include <algorithm>
#include <cstdlib>

#ifdef FRENETIC_HAVE_MPI
#include <mpi.h>
#endif

namespace frenetic::tune {

Cluster::Cluster() {
#ifdef FRENETIC_HAVE_MPI
  // Only under a launcher: MPI_Init in a plain run would try to reach a runtime that is not
  // there (and singleton start-up is slow and noisy).
  const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr ||
                        std::getenv("PMI_SIZE") != nullptr;
  if (!launched) return;
  int already = 0;
  MPI_Initialized(&already);
  if (!already) {
    int provided = 0;
    // Only the main thread calls MPI; episode threads never do.
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    initialised_mpi_ = true;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#endif
}

Cluster::~Cluster() {
#ifdef FRENETIC_HAVE_MPI
  if (initialised_mpi_) MPI_Finalize();
#endif
}

const Cluster& Cluster::Local() {
  static const Cluster local{LocalTag{}};
  return local;
}

void Cluster::Broadcast(std::vector<double>* data) const {
  if (size_ <= 1) return;
#ifdef FRENETIC_HAVE_MPI
  long long n = static_cast<long long>(data->size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  data->resize(static_cast<std::size_t>(n));
  if (n > 0) MPI_Bcast(data->data(), static_cast<int>(n), MPI_DOUBLE, 0, MPI_COMM_WORLD);
#endif
}

void Cluster::SumToRoot(std::vector<double>* data) const {
  if (size_ <= 1) return;
#ifdef FRENETIC_HAVE_MPI
  // Gather every rank's vector and add them on rank 0 in rank order: MPI_Reduce may combine in
  // any order, and a fixed order keeps the result independent of the launch.
  const int n = static_cast<int>(data->size());
  std::vector<double> all(rank_ == 0 ? static_cast<std::size_t>(n) * size_ : 0);
  MPI_Gather(data->data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank_ != 0) return;
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int r = 0; r < size_; ++r) sum += all[static_cast<std::size_t>(r) * n + i];
    (*data)[i] = sum;
  }
#endif
}

std::vector<std::string> Cluster::GatherToRoot(const std::string& data) const {
  if (size_ <= 1) return {data};
  std::vector<std::string> all;
#ifdef FRENETIC_HAVE_MPI
  // The lengths first, then each rank's bytes from rank 0 in rank order, in pieces that fit an
  // int count (a report of many files may exceed one).
  constexpr long long kPiece = 1 << 30;
  long long n = static_cast<long long>(data.size());
  std::vector<long long> sizes(rank_ == 0 ? static_cast<std::size_t>(size_) : 0);
  MPI_Gather(&n, 1, MPI_LONG_LONG, sizes.data(), 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  if (rank_ != 0) {
    for (long long at = 0; at < n; at += kPiece) {
      MPI_Send(data.data() + at, static_cast<int>(std::min(kPiece, n - at)), MPI_BYTE, 0, 0,
               MPI_COMM_WORLD);
    }
    return all;
  }
  all.resize(static_cast<std::size_t>(size_));
  all[0] = data;
  for (int r = 1; r < size_; ++r) {
    std::string& s = all[static_cast<std::size_t>(r)];
    s.resize(static_cast<std::size_t>(sizes[static_cast<std::size_t>(r)]));
    for (long long at = 0; at < static_cast<long long>(s.size()); at += kPiece) {
      MPI_Recv(s.data() + at,
               static_cast<int>(std::min(kPiece, static_cast<long long>(s.size()) - at)), MPI_BYTE,
               r, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
  }
#else
  (void)data;
#endif
  return all;
}

}  // namespace frenetic::tune

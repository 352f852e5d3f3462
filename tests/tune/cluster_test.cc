// Cluster on one process, and its byte gather across ranks: this test binary run again by
// `mpirun -n 3`, one test of it in each rank (skipped when frenetic was built without MPI or
// mpirun is not installed).
#include "frenetic/tune/cluster.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace frenetic::tune {
namespace {

// Rank r's bytes: none for rank 1, a short text for rank 0, megabytes with zero bytes in them
// for the others (lengths that differ per rank).
std::string Payload(int rank) {
  if (rank == 0) return "rank 0";
  if (rank == 1) return "";
  std::string s(3'000'000 + rank, '\0');
  for (size_t i = 0; i < s.size(); ++i) s[i] = static_cast<char>((i * 31 + rank) % 251);
  return s;
}

TEST(ClusterTest, LocalIsOneRankAndItsCollectivesAreIdentities) {
  const Cluster& c = Cluster::Local();
  EXPECT_EQ(c.rank(), 0);
  EXPECT_EQ(c.size(), 1);
  EXPECT_FALSE(c.distributed());
  EXPECT_EQ(c.GatherToRoot(Payload(2)), std::vector<std::string>{Payload(2)});
  EXPECT_EQ(c.GatherToRoot(""), std::vector<std::string>{""});
  std::vector<double> v = {1.5, -2};
  c.SumToRoot(&v);
  c.Broadcast(&v);
  EXPECT_EQ(v, (std::vector<double>{1.5, -2}));
}

// Runs only under a launcher (ClusterTest.GatherToRootUnderMpirun starts it).
TEST(ClusterMpiRank, GatherToRootInRankOrder) {
  if (std::getenv("OMPI_COMM_WORLD_SIZE") == nullptr && std::getenv("PMI_SIZE") == nullptr) {
    GTEST_SKIP() << "runs in the ranks that ClusterTest.GatherToRootUnderMpirun starts";
  }
  Cluster cluster;
  ASSERT_GT(cluster.size(), 1);
  const std::vector<std::string> all = cluster.GatherToRoot(Payload(cluster.rank()));
  if (cluster.rank() != 0) {
    EXPECT_TRUE(all.empty());
    return;
  }
  ASSERT_EQ(static_cast<int>(all.size()), cluster.size());
  int same = 0;
  for (int r = 0; r < cluster.size(); ++r) same += all[r] == Payload(r);
  EXPECT_EQ(same, cluster.size());
  std::printf("rank 0 gathered %d of %d ranks' bytes intact\n", same, cluster.size());
}

TEST(ClusterTest, GatherToRootUnderMpirun) {
#ifndef FRENETIC_HAVE_MPI
  GTEST_SKIP() << "frenetic was built without MPI (FRENETIC_HAVE_MPI unset)";
#else
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string command = "mpirun --allow-run-as-root --oversubscribe -n 3 " + self +
                              " --gtest_filter=ClusterMpiRank.* 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 4096> buf;
  for (size_t n; (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) out.append(buf.data(), n);
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  EXPECT_THAT(out, ::testing::HasSubstr("rank 0 gathered 3 of 3 ranks' bytes intact")) << out;
#endif
}

}  // namespace
}  // namespace frenetic::tune

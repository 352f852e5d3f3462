// `frenetic tune` end to end: the executable on the smoke suite, single-process and under
// `mpirun -n 2` (same best parameters and objective), and a bad suite's one-line error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct ShellResult {
  int exit_code = -1;
  std::string out;  // stdout
};

// Runs a shell command, capturing stdout (stderr goes to `err_file` when given).
ShellResult Shell(const std::string& command) {
  ShellResult run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buf;
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) {
    run.out.append(buf.data(), n);
  }
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string Smoke() { return std::string(FRENETIC_SOURCE_DIR "/config/tune/smoke.yaml"); }

class TuneCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(FRENETIC_BINARY)) GTEST_SKIP() << "no executable at " << FRENETIC_BINARY;
    dir_ = fs::temp_directory_path() / ("frenetic_tune_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

TEST_F(TuneCliTest, MpiRunMatchesSingleProcess) {
#ifndef FRENETIC_HAVE_MPI
  GTEST_SKIP() << "frenetic was built without MPI (FRENETIC_HAVE_MPI unset)";
#else
  if (Shell("command -v mpirun >/dev/null 2>&1").exit_code != 0) {
    GTEST_SKIP() << "mpirun is not installed";
  }
  const std::string args = " tune --suite " + Smoke() + " --budget 4 --json";
  const ShellResult single = Shell(std::string(FRENETIC_BINARY) + args + " --jobs 2 -o " +
                           (dir_ / "single.yaml").string() + " 2>" + (dir_ / "single.err").string());
  ASSERT_EQ(single.exit_code, 0) << ReadFile(dir_ / "single.err");
  const ShellResult mpi = Shell("mpirun -n 2 --oversubscribe --allow-run-as-root " +
                        std::string(FRENETIC_BINARY) + args + " --jobs 1 -o " +
                        (dir_ / "mpi.yaml").string() + " 2>" + (dir_ / "mpi.err").string());
  ASSERT_EQ(mpi.exit_code, 0) << ReadFile(dir_ / "mpi.err");

  auto a = nlohmann::json::parse(single.out, nullptr, false);
  auto b = nlohmann::json::parse(mpi.out, nullptr, false);  // only rank 0 prints
  ASSERT_FALSE(a.is_discarded()) << single.out;
  ASSERT_FALSE(b.is_discarded()) << mpi.out;
  EXPECT_EQ(a.at("ranks"), 1);
  EXPECT_EQ(b.at("ranks"), 2);
  EXPECT_EQ(a.at("evaluations"), 4);
  // Same search path, so the same best point, parameters and objectives, exactly.
  EXPECT_EQ(a.at("best_x"), b.at("best_x"));
  EXPECT_EQ(a.at("params"), b.at("params"));
  EXPECT_EQ(a.at("train"), b.at("train"));
  EXPECT_EQ(a.at("holdout"), b.at("holdout"));
  EXPECT_EQ(ReadFile(dir_ / "single.yaml"), ReadFile(dir_ / "mpi.yaml"));
#endif
}

TEST_F(TuneCliTest, UnknownSuiteKeyFailsNamingIt) {
  const fs::path suite = dir_ / "bad.yaml";
  std::ofstream(suite) << "scenarios: [udacity]\ntrain_seeds: [1]\nholdout_seeds: [2]\n"
                          "params: {weights.efficiency: {lo: 0.1, hi: 10}}\nbudgets: 3\n";
  const ShellResult run = Shell(std::string(FRENETIC_BINARY " tune --suite ") + suite.string() +
                        " 2>&1");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.out, HasSubstr("bad.yaml"));
  EXPECT_THAT(run.out, HasSubstr("budgets"));

  std::ofstream(suite) << "scenarios: [udacity]\ntrain_seeds: [1]\nholdout_seeds: [2]\n"
                          "params: {weights.warp: {lo: 0.1, hi: 10}}\n";
  const ShellResult run2 = Shell(std::string(FRENETIC_BINARY " tune --suite ") + suite.string() +
                         " 2>&1");
  EXPECT_NE(run2.exit_code, 0);
  EXPECT_THAT(run2.out, HasSubstr("params.weights.warp"));
}

}  // namespace

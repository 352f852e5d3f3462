// End to end over a real WebSocket: `frenetic serve` on an ephemeral port, the headless
// simulator driving it with `frenetic drive --connect`, compared with the in-process drive.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "apps_test_util.h"

namespace frenetic::testing {
namespace {

// A `frenetic serve --port 0` child process; its first stdout line names the bound port.
class ServerProcess {
 public:
  explicit ServerProcess(const std::string& args) {
    int fds[2];
    if (pipe(fds) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      const std::string cmd = std::string("exec ") + FRENETIC_BINARY + " serve --port 0 " + args;
      execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    FILE* out = fdopen(fds[0], "r");
    char line[512];
    if (out != nullptr && fgets(line, sizeof line, out) != nullptr) {
      std::smatch m;
      const std::string text(line);
      if (std::regex_search(text, m, std::regex(R"(ws://127\.0\.0\.1:(\d+))"))) {
        port_ = std::stoi(m[1]);
      }
    }
    out_ = out;
  }
  ~ServerProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      int status = 0;
      waitpid(pid_, &status, 0);
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    if (out_ != nullptr) fclose(out_);
  }
  int port() const { return port_; }

  // Stops the server with SIGTERM and returns its exit status (0 = clean shutdown).
  int Stop() {
    if (pid_ <= 0) return -1;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  int port_ = -1;
  int exit_code_ = -1;
  FILE* out_ = nullptr;
};

// The planner's deadlines are wall-clock: on a loaded machine two drives could differ because
// of them alone. Both sides of the comparison use the default config with the deadline at its
// maximum and refinement (which has its own time budget) off, so only the wire differs.
std::string DeterministicConfig() {
  std::ifstream in(std::string(FRENETIC_SOURCE_DIR) + "/config/planner.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = std::regex_replace(text.str(), std::regex(R"(\nbudget_ms: [0-9.]+)"),
                                        "\nbudget_ms: 200");
  yaml = std::regex_replace(yaml, std::regex(R"(\n  enabled: 1)"), "\n  enabled: 0");
  EXPECT_NE(yaml.find("\nbudget_ms: 200"), std::string::npos);
  EXPECT_NE(yaml.find("\n  enabled: 0"), std::string::npos);
  const std::string path = ::testing::TempDir() + "/serve_drive_planner.yaml";
  std::ofstream(path) << yaml;
  return path;
}

TEST(ServeDrive, NetworkDriveMatchesInProcessDrive) {
  if (!HaveUdacityMap()) GTEST_SKIP() << "no " << UdacityMap();
  const std::string config = DeterministicConfig();
  ServerProcess server("--map " + UdacityMap() + " --config " + config +
                       " --status-interval 1000");
  ASSERT_GT(server.port(), 0) << "serve did not print its port";
  const std::string common = "drive --map " + UdacityMap() + " --config " + config +
                             " --scenario udacity --seed 7 --seconds 60 --json";
  const std::string url =
      "ws://127.0.0.1:" + std::to_string(server.port()) + "/socket.io/?EIO=4&transport=websocket";
  CommandResult remote = RunFrenetic(common + " --connect '" + url + "'");
  ASSERT_EQ(remote.exit_code, 0) << remote.out;
  CommandResult local = RunFrenetic(common);
  ASSERT_EQ(local.exit_code, 0) << local.out;
  EXPECT_EQ(server.Stop(), 0) << "serve did not shut down cleanly on SIGTERM";

  const auto r = nlohmann::json::parse(remote.out);
  const auto l = nlohmann::json::parse(local.out);
  // The same simulated time and exchange count, the same incidents, distance within 1% (the
  // wire's 7-digit numbers make the planner's input differ from the in-process float32 values).
  EXPECT_DOUBLE_EQ(r["sim_seconds"].get<double>(), l["sim_seconds"].get<double>());
  EXPECT_EQ(r["exchanges"], l["exchanges"]);
  EXPECT_EQ(r["incidents"], l["incidents"]);
  const double dr = r["distance_m"].get<double>(), dl = l["distance_m"].get<double>();
  EXPECT_GT(dl, 500.0) << "the drive should cover real distance in 60 s";
  EXPECT_NEAR(dr, dl, 0.01 * dl);
}

TEST(ServeDrive, ConnectToNothingFailsWithOneLine) {
  CommandResult r = RunFrenetic(
      "drive --seconds 5 --connect 'ws://127.0.0.1:9/socket.io/?EIO=4&transport=websocket' "
      "2>&1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("frenetic drive: ws://127.0.0.1:9"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace frenetic::testing

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

// The in-process drive rounds every telemetry number and every path point as the wire does
// (wire_precision.h), so the same seed gives the same drive through `serve` + `drive --connect`:
// the whole report is equal except what cannot be: planning times (round trips over the wire),
// the planner's name ("remote") and plan_fallbacks (in process: plans whose status was not ok;
// over the wire: manual replies).
TEST(ServeDrive, NetworkDriveEqualsInProcessDrive) {
  if (!HaveUdacityMap()) GTEST_SKIP() << "no " << UdacityMap();
  const std::string config = DeterministicConfig();
  ServerProcess server("--map " + UdacityMap() + " --config " + config +
                       " --status-interval 1000");
  ASSERT_GT(server.port(), 0) << "serve did not print its port";
  const std::string url =
      "ws://127.0.0.1:" + std::to_string(server.port()) + "/socket.io/?EIO=4&transport=websocket";
  for (const char* latency : {"lockstep", "random"}) {
    for (int seed = 1; seed <= 5; ++seed) {
      SCOPED_TRACE(std::string(latency) + " seed " + std::to_string(seed));
      const std::string common = "drive --map " + UdacityMap() + " --config " + config +
                                 " --scenario udacity --seconds 30 --json --latency " + latency +
                                 " --seed " + std::to_string(seed);
      CommandResult remote = RunFrenetic(common + " --connect '" + url + "'");
      ASSERT_EQ(remote.exit_code, 0) << remote.out;
      CommandResult local = RunFrenetic(common);
      ASSERT_EQ(local.exit_code, 0) << local.out;
      auto r = nlohmann::json::parse(remote.out);
      auto l = nlohmann::json::parse(local.out);
      EXPECT_EQ(r["planner"], "remote");
      EXPECT_GT(l["distance_m"].get<double>(), 300.0) << "the drive should cover real distance";
      for (const char* key : {"plan_ms", "planner", "plan_fallbacks"}) {
        r.erase(key);
        l.erase(key);
      }
      EXPECT_EQ(r, l) << "remote: " << r.dump() << "\nlocal:  " << l.dump();
    }
  }
  EXPECT_EQ(server.Stop(), 0) << "serve did not shut down cleanly on SIGTERM";
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

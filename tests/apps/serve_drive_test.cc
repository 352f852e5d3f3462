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
#include <vector>

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
// of them alone. `serve --no-deadlines` switches them off as `drive` does, so both sides run the
// shipped configuration in full (refinement included) and only the wire differs.
std::string DeterministicServeArgs() {
  return "--map " + UdacityMap() + " --no-deadlines --status-interval 1000";
}
std::string ClientUrl(int port) {
  return "ws://127.0.0.1:" + std::to_string(port) + "/socket.io/?EIO=4&transport=websocket";
}

// The in-process drive rounds every telemetry number and every path point as the wire does
// (wire/precision.h), so the same seed gives the same drive through `serve` + `drive --connect`:
// the whole report is equal except what cannot be: planning times (round trips over the wire),
// the planner's name ("remote") and plan_fallbacks (in process: plans whose status was not ok;
// over the wire: manual replies).
TEST(ServeDrive, NetworkDriveEqualsInProcessDrive) {
  if (!HaveUdacityMap()) GTEST_SKIP() << "no " << UdacityMap();
  ServerProcess server(DeterministicServeArgs());
  ASSERT_GT(server.port(), 0) << "serve did not print its port";
  const std::string url = ClientUrl(server.port());
  for (const char* latency : {"lockstep", "random"}) {
    for (int seed = 1; seed <= 5; ++seed) {
      SCOPED_TRACE(std::string(latency) + " seed " + std::to_string(seed));
      const std::string common = "drive --map " + UdacityMap() +
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
      for (auto* report : {&r, &l}) {  // judging times are wall times too
        for (auto& incident : (*report)["incident_log"]) incident["judgement"].erase("ms");
      }
      EXPECT_EQ(r, l) << "remote: " << r.dump() << "\nlocal:  " << l.dump();
    }
  }
  EXPECT_EQ(server.Stop(), 0) << "serve did not shut down cleanly on SIGTERM";
}

std::vector<nlohmann::json> ReadJsonLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<nlohmann::json> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

// `drive --connect --record` writes the record an in-process drive writes, without the planner's
// internals, and `frenetic report` makes the page from it.
TEST(ServeDrive, RemoteDriveIsRecordedAndReported) {
  if (!HaveUdacityMap()) GTEST_SKIP() << "no " << UdacityMap();
  ServerProcess server(DeterministicServeArgs());
  ASSERT_GT(server.port(), 0) << "serve did not print its port";
  const std::string url = ClientUrl(server.port());
  const std::string dir = ::testing::TempDir();
  const std::string common = "drive --map " + UdacityMap() +
                             " --seconds 10 --seed 3 --latency random --no-timing --json";
  CommandResult remote =
      RunFrenetic(common + " --connect '" + url + "' --record " + dir + "/remote.jsonl");
  ASSERT_EQ(remote.exit_code, 0) << remote.out;
  CommandResult local = RunFrenetic(common + " --record " + dir + "/local.jsonl");
  ASSERT_EQ(local.exit_code, 0) << local.out;

  const std::vector<nlohmann::json> r = ReadJsonLines(dir + "/remote.jsonl");
  const std::vector<nlohmann::json> l = ReadJsonLines(dir + "/local.jsonl");
  ASSERT_GT(r.size(), 100u);
  ASSERT_EQ(r.size(), l.size());
  EXPECT_EQ(r.front()["type"], "header");
  EXPECT_EQ(r.front()["planner"], "remote");
  EXPECT_EQ(r.front()["connect"], url);
  EXPECT_EQ(r.back()["type"], "footer");
  for (std::size_t i = 1; i + 1 < r.size(); ++i) {
    ASSERT_EQ(r[i]["type"], "exchange");
    // The same drive: what the simulator sent and measured is equal line by line.
    for (const char* key : {"i", "t", "telemetry", "metrics", "incidents"}) {
      EXPECT_EQ(r[i][key], l[i][key]) << "line " << i << ", " << key;
    }
    // What only an in-process planner knows is absent.
    EXPECT_EQ(r[i]["plan"], (nlohmann::json{{"status", "control"}, {"ms_total", 0.0}}));
    EXPECT_EQ(r[i]["path"]["x"].size(), l[i]["path"]["x"].size());
    if (HasFailure()) FAIL() << "line " << i;
  }

  CommandResult page = RunFrenetic("report " + dir + "/remote.jsonl -o " + dir +
                                   "/remote.html --json");
  ASSERT_EQ(page.exit_code, 0) << page.out;
  const auto summary = nlohmann::json::parse(page.out);
  EXPECT_EQ(summary["exchanges"], r.size() - 2);
  EXPECT_EQ(summary["skipped_lines"], 0);
  EXPECT_EQ(summary["footer"], true);
  std::ifstream html(dir + "/remote.html");
  std::stringstream text;
  text << html.rdbuf();
  EXPECT_EQ(text.str().rfind("<!doctype html>", 0), 0u);
  EXPECT_NE(text.str().find(R"("planner":"remote")"), std::string::npos);
  EXPECT_EQ(server.Stop(), 0);
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

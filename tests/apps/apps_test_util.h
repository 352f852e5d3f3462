// Helpers for end-to-end tests that run the `frenetic` executable.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace frenetic::testing {

inline std::string UdacityMap() { return std::string(FRENETIC_SHARED_DIR "/data/highway_map.csv"); }
inline bool HaveUdacityMap() { return std::filesystem::exists(UdacityMap()); }

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout (stderr goes to the test log unless redirected in `args`)
};

// Runs `frenetic ARGS` through the shell and captures stdout.
inline CommandResult RunFrenetic(const std::string& args) {
  CommandResult r;
  const std::string cmd = std::string(FRENETIC_BINARY " ") + args;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace frenetic::testing

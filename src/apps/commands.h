// The frenetic executable's subcommands. Each Register* adds one CLI11 subcommand whose callback
// runs it; a non-zero exit status is raised as CLI::RuntimeError(code).
#pragma once

#include <CLI/CLI.hpp>

namespace frenetic::apps {

void RegisterMapCheck(CLI::App& app);   // cmd_map.cc
void RegisterTrack(CLI::App& app);      // cmd_map.cc: track generate
void RegisterDrive(CLI::App& app);      // cmd_drive.cc
void RegisterServe(CLI::App& app);      // cmd_serve.cc
void RegisterTune(CLI::App& app);       // cmd_tune.cc
void RegisterReport(CLI::App& app);     // cmd_report.cc
void RegisterFidelity(CLI::App& app);   // cmd_fidelity.cc
void RegisterCommonRoad(CLI::App& app);  // cmd_commonroad.cc

// Exit with `code` from inside a subcommand callback (no-op for 0).
void ExitWith(int code);

}  // namespace frenetic::apps

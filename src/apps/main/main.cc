// frenetic: a cost-function trajectory planner for the Udacity Term 3 highway simulator.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <string>

#include "apps/commands.h"

int main(int argc, char** argv) {
  // Logs go to stderr so that stdout carries only results (tables, --json, serve's port line).
  spdlog::set_default_logger(spdlog::stderr_color_mt("frenetic"));
  CLI::App app{
      "frenetic: highway trajectory planner for the Udacity Term 3 simulator, with a headless\n"
      "simulator to drive, test, tune and benchmark it."};
  app.set_version_flag("--version", std::string("frenetic ") + FRENETIC_VERSION);
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "Log verbosity: trace, debug, info, warn, error, critical, off (default: info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.parse_complete_callback([&] { spdlog::set_level(spdlog::level::from_str(log_level)); });

  frenetic::apps::RegisterMapCheck(app);
  frenetic::apps::RegisterTrack(app);
  frenetic::apps::RegisterDrive(app);
  frenetic::apps::RegisterCommonRoad(app);
  frenetic::apps::RegisterServe(app);
  frenetic::apps::RegisterTune(app);
  frenetic::apps::RegisterReport(app);
  frenetic::apps::RegisterFidelity(app);

  CLI11_PARSE(app, argc, argv);
  return 0;
}

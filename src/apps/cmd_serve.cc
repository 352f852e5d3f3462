// frenetic serve: the planner as a WebSocket server for the Udacity simulator.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/net/server.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::apps {
namespace {

struct ServeArgs {
  std::string map_path;
  std::string planner = "search";
  std::string config_path;
  bool no_deadlines = false;
  net::ServerOptions server;
};

int Serve(const ServeArgs& args) {
  const std::string map_path = args.map_path.empty() ? map::DefaultTrackPath() : args.map_path;
  StatusOr<map::Track> track = map::LoadTrack(map_path);
  if (!track.ok()) {
    std::fprintf(stderr, "frenetic serve: %s\n", track.message().c_str());
    return 2;
  }
  auto line = map::ReferenceLine::Fit(*track);
  if (!line.ok()) {
    std::fprintf(stderr, "frenetic serve: reference line of %s: %s\n", map_path.c_str(),
                 line.message().c_str());
    return 2;
  }
  StatusOr<plan::PlannerConfig> config = args.config_path.empty()
                                             ? plan::PlannerConfig::LoadDefault()
                                             : plan::PlannerConfig::Load(args.config_path);
  if (!config.ok()) {
    std::fprintf(stderr, "frenetic serve: %s\n", config.message().c_str());
    return 2;
  }
  if (args.no_deadlines) config->PinDeadlines();
  // Shared by every connection's planner; the factory (and so the server) keeps it alive.
  auto shared_config = std::make_shared<const plan::PlannerConfig>(std::move(config).value());
  std::shared_ptr<const map::ReferenceLine> shared_line = *line;
  // Build one planner now so a bad name or configuration fails at start, not per connection.
  if (auto probe = plan::MakePlanner(args.planner, *shared_config, shared_line); !probe.ok()) {
    std::fprintf(stderr, "frenetic serve: planner \"%s\": %s\n", args.planner.c_str(),
                 probe.message().c_str());
    return 2;
  }
  const std::string planner_name = args.planner;
  net::PlannerFactory factory = [planner_name, shared_config,
                                 shared_line]() -> std::unique_ptr<plan::Planner> {
    auto planner = plan::MakePlanner(planner_name, *shared_config, shared_line);
    if (!planner.ok()) {
      spdlog::error("planner \"{}\": {}", planner_name, planner.message());
      return nullptr;
    }
    return std::move(planner).value();
  };
  net::ServerOptions options = args.server;
  options.handle_signals = true;
  auto server = net::Server::Create(options, std::move(factory));
  if (!server.ok()) {
    std::fprintf(stderr, "frenetic serve: %s\n", server.message().c_str());
    return 2;
  }
  std::printf("frenetic serve: listening on ws://%s:%d (any path), planner %s, map %s\n",
              options.bind_address.c_str(), (*server)->port(), planner_name.c_str(),
              map_path.c_str());
  std::fflush(stdout);
  (*server)->Run();
  return 0;
}

}  // namespace

void RegisterServe(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  auto* sub = app.add_subcommand(
      "serve",
      "Run the planner as a WebSocket server for the Udacity simulator (or `frenetic drive\n"
      "--connect`). Every 42[\"telemetry\",{...}] frame gets one 42[\"control\",{...}] reply from\n"
      "the connection's own planner; null telemetry and anything else get 42[\"manual\",{}].\n"
      "Telemetry over 64 sensor_fusion rows or 1000 path points is refused (manual).\n"
      "Stops cleanly on SIGINT/SIGTERM.");
  sub->add_option("--port", args->server.port,
                  "TCP port to listen on; 0 picks a free one and prints it (default: 4567, the "
                  "port the simulator connects to)")
      ->check(CLI::Range(0, 65535));
  sub->add_option("--bind", args->server.bind_address,
                  "IP address to listen on; 0.0.0.0 accepts other machines (default: 127.0.0.1)");
  sub->add_option("--map", args->map_path,
                  "Track waypoint file in the Udacity format (x y s dx dy per line), e.g. the "
                  "simulator's data/highway_map.csv (default: the bundled "
                  "config/tracks/frenetic_loop.csv)");
  sub->add_option("--planner", args->planner, "Planner: search or baseline (default: search)")
      ->check(CLI::IsMember({"search", "baseline"}));
  sub->add_option("--config", args->config_path,
                  "Planner configuration YAML (weights, limits, grid) (default: the bundled "
                  "config/planner.yaml)");
  sub->add_option("--status-interval", args->server.status_interval,
                  "Seconds between status log lines (cycles, planning time p50/p99, speed, lane, "
                  "incidents); 0 turns them off (default: 5)")
      ->check(CLI::Range(0.0, 86400.0));
  sub->add_option("--max-frame-bytes", args->server.max_frame_bytes,
                  "Largest incoming WebSocket message in bytes; a larger one closes that "
                  "connection (default: 1048576 = 1 MiB; a real telemetry frame is ~2-5 kB)")
      ->check(CLI::Range(std::size_t{1024}, std::size_t{1} << 30));
  sub->add_option("--max-connections", args->server.max_connections,
                  "Connections open at once (upgrading or upgraded); one more is answered HTTP "
                  "503 with the reason and closed (default: 8, room for a few simulators)")
      ->check(CLI::Range(1, 10000));
  sub->add_option("--planning-threads", args->server.planning_threads,
                  "Threads that convert frames and plan, shared by all connections (each "
                  "connection's planner is used by one thread at a time); 0 = one per core this "
                  "process may use (its CPU affinity: taskset), at least 2 and at most 8 "
                  "(default: 0)")
      ->check(CLI::Range(0, 256));
  sub->add_flag("--no-deadlines", args->no_deadlines,
                "Switch the planner's wall-clock deadlines (budget_ms, refine.budget_ms) off, as "
                "frenetic drive does, so every cycle searches and refines in full however long it "
                "takes: replies then depend only on the telemetry, and a `drive --connect` gives "
                "the in-process drive's report. Default: off - deadlines apply, as the real "
                "simulator needs");
  sub->add_flag("--answer-ping", args->server.answer_ping,
                "Answer the simulator's engine.io ping \"2\" with \"3\" (not needed; default: "
                "ignore it, as the starter server does)");
  sub->callback([args] { ExitWith(Serve(*args)); });
}

}  // namespace frenetic::apps

// The planner as a WebSocket server for the Udacity simulator (udacity-sim.md §3): plain RFC 6455
// on any URL path (the simulator asks for /socket.io/?EIO=4&transport=websocket), text frames,
// no engine.io handshake. Every 42 frame is answered with exactly one frame: telemetry with
// `42["control",{...}]` from the connection's own planner, anything else (null telemetry, other
// events, malformed frames) with `42["manual",{}]`. Hostile input (bad JSON, oversize or binary
// frames, abrupt disconnects) is logged in one line and never crashes the server. A connection
// silent for 150 s gets a WebSocket ping and is closed after 300 s without any data (Beast's
// suggested server timeouts), so half-open connections do not pile up. Replies go out as the
// simulator's own messages do: one unfragmented text frame each, whatever the size, on sockets
// with TCP_NODELAY set.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "frenetic/plan/planner.h"
#include "frenetic/status.h"

namespace frenetic::net {

// Makes the planner of one connection (called once per accepted connection, on the server's
// thread). Returning nullptr (or throwing) refuses the connection with a log line.
using PlannerFactory = std::function<std::unique_ptr<plan::Planner>()>;

struct ServerOptions {
  std::string bind_address = "127.0.0.1";  // IPv4 or IPv6 literal
  int port = 4567;                         // TCP port; 0 = an ephemeral port (see Server::port())
  std::size_t max_frame_bytes = 1 << 20;   // larger incoming messages close the connection
  double status_interval = 5.0;            // s between info status lines; 0 = none
  bool answer_ping = false;                // answer the engine.io ping "2" with "3" (not needed)
  bool handle_signals = false;             // SIGINT / SIGTERM stop Run() cleanly
  int max_logged_problems = 100;           // per connection; later problems are only counted
  double handshake_timeout = 30.0;         // s allowed for the WebSocket upgrade

  Status Validate() const;  // a message naming the bad option
};

// Counters since the server started (all connections).
struct ServerStats {
  std::int64_t connections = 0;       // accepted and upgraded
  // Accepted sockets on which TCP_NODELAY reads back as set (getsockopt); equals the accepted
  // count unless the option could not be set.
  std::int64_t nodelay_connections = 0;
  std::int64_t open_connections = 0;
  std::int64_t refused_connections = 0;  // the planner factory failed
  std::int64_t cycles = 0;            // telemetry answered with control
  std::int64_t manual_replies = 0;    // null telemetry, other events, malformed frames
  std::int64_t null_telemetry = 0;
  std::int64_t other_events = 0;
  std::int64_t malformed_frames = 0;  // 42 frames that could not be understood
  std::int64_t refused_frames = 0;    // 42 frames over net::FrameLimits (answered manual)
  std::int64_t repaired_frames = 0;   // telemetry with dropped rows / cut arrays, still planned
  std::int64_t binary_frames = 0;     // ignored
  std::int64_t oversize_frames = 0;   // connection closed
  std::int64_t pings = 0;
  std::int64_t ignored_frames = 0;
  // Incidents the planner could have caused.
  std::int64_t short_paths = 0;       // control with fewer than plan::kMinPathPoints points
  std::int64_t bad_plans = 0;         // unequal x/y or non-finite points (cut before sending)
  std::int64_t planner_exceptions = 0;  // Plan() threw (answered manual)
  std::int64_t fallback = 0, invalid_input = 0, over_budget = 0;  // PlanResult::status
};

class Server {
 public:
  // Validates the options, binds and listens (the port is known on return). Errors name the
  // option or the address that could not be bound.
  static StatusOr<std::unique_ptr<Server>> Create(const ServerOptions& options,
                                                  PlannerFactory factory);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  int port() const;  // the bound TCP port (the ephemeral one when options.port was 0)

  // Serves on the calling thread until Stop() or (with handle_signals) SIGINT/SIGTERM. Open
  // connections are closed on the way out. Call at most once.
  void Run();
  // Thread-safe; may be called before Run() (which then returns at once).
  void Stop();

  ServerStats stats() const;  // thread-safe snapshot

  // The status line logged (info) every options.status_interval: open connections, cycles
  // (total and in this interval), planning time p50/p99 in this interval (ms), the last ego
  // speed and lane, incident and frame counters. Starts a new interval. Thread-safe.
  std::string StatusLine();

  struct Impl;

 private:
  explicit Server(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace frenetic::net

// The planner as a WebSocket server for the Udacity simulator (udacity-sim.md §3): plain RFC 6455
// on any URL path (the simulator asks for /socket.io/?EIO=4&transport=websocket), text frames,
// no engine.io handshake. Every 42 frame is answered with exactly one frame: telemetry with
// `42["control",{...}]` from the connection's own planner, anything else (null telemetry, other
// events, malformed frames, frames over the limits) with `42["manual",{}]`. Hostile input (bad
// JSON, oversize or binary frames, invalid close codes, abrupt disconnects) is logged in one line
// and never crashes the server. Replies go out as the simulator's own messages do: one
// unfragmented text frame each, whatever the size, on sockets with TCP_NODELAY set.
//
// No connection can hold up another's reply: the sockets are served by one I/O thread that only
// moves bytes, and every frame is converted and planned on a small pool of planning threads. A
// connection has at most one frame in hand at a time (the next is read only once the reply is
// written), so its planner is used by one thread at a time and a client that floods or stops
// reading only slows itself; the pool takes the waiting connection that has used the least
// planning time lately (decayed over ~1 s), so a simulator that sends one frame per tick goes
// ahead of clients that keep the pool busy. A frame's conversion is bounded by wire::FrameLimits.
// At most max_connections connections are open (upgrading or upgraded); one more is answered
// `HTTP/1.1 503 Service Unavailable` with a one-line reason and closed. A connection's planner is
// built at its first telemetry and freed when it closes (memory is then given back to the system).
// A connection silent for 150 s gets a WebSocket ping and is closed after 300 s without any data
// (Beast's suggested server timeouts), one whose upgrade takes over handshake_timeout or whose
// reply cannot be written within write_timeout (the peer does not read) is closed, so stalled
// connections do not hold their place. A connection is read at most max_read_bytes_per_second,
// so megabyte frames sent back to back cost the I/O thread a bounded share of its time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "frenetic/plan/planner.h"
#include "frenetic/status.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::net {

// Makes the planner of one connection, at its first telemetry, on a planning thread: it may be
// called from several threads at once and must be thread-safe. Returning nullptr (or throwing)
// answers that telemetry manual and closes the connection, with a log line.
using PlannerFactory = std::function<std::unique_ptr<plan::Planner>()>;

struct ServerOptions {
  std::string bind_address = "127.0.0.1";  // IPv4 or IPv6 literal
  int port = 4567;                         // TCP port; 0 = an ephemeral port (see Server::port())
  std::size_t max_frame_bytes = 1 << 20;   // larger incoming messages close the connection
  double status_interval = 5.0;            // s between info status lines; 0 = none
  bool answer_ping = false;                // answer the engine.io ping "2" with "3" (not needed)
  bool handle_signals = false;             // SIGINT / SIGTERM stop Run() cleanly
  int max_logged_problems = 100;           // per connection; later problems are only counted
  double handshake_timeout = 10.0;         // s allowed for the WebSocket upgrade
  // Connections open at once (upgrading or upgraded); one more is refused with HTTP 503. Room
  // for a few simulators and `drive --connect` runs side by side.
  int max_connections = 8;
  // Threads that convert frames and plan; 0 = one per core, at least 2 and at most 8.
  int planning_threads = 0;
  double write_timeout = 10.0;  // s a reply may take to be written before the connection closes
  // Bytes a connection is read at, on average (bursts up to max_frame_bytes); 0 = no limit.
  // A simulator sends ~0.3 MB/s, `drive --connect` up to ~10 MB/s.
  double max_read_bytes_per_second = 16 << 20;
  wire::FrameLimits frame_limits;  // sensor_fusion rows and path points a telemetry frame may hold

  Status Validate() const;  // a message naming the bad option
};

// Counters since the server started (all connections).
struct ServerStats {
  std::int64_t connections = 0;       // accepted and upgraded
  // Accepted sockets on which TCP_NODELAY reads back as set (getsockopt); equals the accepted
  // count unless the option could not be set.
  std::int64_t nodelay_connections = 0;
  std::int64_t open_connections = 0;
  std::int64_t refused_connections = 0;  // the planner factory failed (at the first telemetry)
  std::int64_t capacity_refusals = 0;    // refused with 503 at max_connections
  std::int64_t planners_built = 0;
  std::int64_t stalled_connections = 0;  // closed: a reply not written within write_timeout
  std::int64_t bad_close_codes = 0;      // close frames with an invalid code: failed with 1002
  std::int64_t waiting_frames = 0;       // now: frames waiting for a planning thread
  std::int64_t cycles = 0;            // telemetry answered with control
  std::int64_t manual_replies = 0;    // null telemetry, other events, malformed frames
  std::int64_t null_telemetry = 0;
  std::int64_t other_events = 0;
  std::int64_t malformed_frames = 0;  // 42 frames that could not be understood
  std::int64_t refused_frames = 0;    // 42 frames over ServerOptions::frame_limits
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

  // Serves on the calling thread (the I/O thread; the planning threads are started here) until
  // Stop() or (with handle_signals) SIGINT/SIGTERM. Open connections are closed on the way out.
  // Call at most once.
  void Run();
  // Thread-safe; may be called before Run() (which then returns at once).
  void Stop();

  ServerStats stats() const;  // thread-safe snapshot

  // The status line logged (info) every options.status_interval: open connections, cycles
  // (total and in this interval), planning time p50/p99 in this interval (ms), the last ego
  // speed and lane, incident, frame and connection counters. Starts a new interval.
  // Thread-safe.
  std::string StatusLine();

  struct Impl;

 private:
  explicit Server(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace frenetic::net

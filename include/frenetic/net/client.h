// The simulator's side of the wire (udacity-sim.md §2, §3): a WebSocket client that plays the
// Unity simulator against a planner server. The headless simulator implements
// SimulatorEndpoint; this module only moves frames, so net does not depend on sim.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "frenetic/status.h"

namespace frenetic::net {

// What the simulator does when frames arrive. Every method returns the next frame to send
// (normally wire::FormatTelemetryFrame(...), or wire::kNullTelemetryFrame when no tick has elapsed
// since the last real telemetry: the endpoint decides). An empty string ends the run like Done().
class SimulatorEndpoint {
 public:
  virtual ~SimulatorEndpoint() = default;
  // The first frame, sent right after connecting (and after the engine.io ping "2").
  virtual std::string OnOpen() = 0;
  // A control reply arrived: apply the path (m, map frame; equal lengths, finite), tick, and
  // return the next frame.
  virtual std::string OnControl(std::span<const double> x, std::span<const double> y) = 0;
  // A manual reply arrived (or, with continue_on_protocol_error, a malformed one): keep the old
  // path, tick as the simulator would, and return the next frame.
  virtual std::string OnManual() = 0;
  // True when the run is over; checked after each reply, before sending the next frame.
  virtual bool Done() const = 0;
  // Simulated seconds so far; used only for ClientOptions::realtime pacing (< 0: unknown).
  virtual double SimSeconds() const { return -1; }
};

struct ClientOptions {
  bool realtime = false;       // hold each frame until wall time catches up with SimSeconds()
  double timeout = 10.0;       // s allowed for connecting and for each reply
  bool send_ping = true;       // the engine.io ping "2" right after connecting, as the sim does
  // The real simulator silently stalls on a malformed control (§3.2). By default the run stops
  // with an error naming it; with this set it is counted, treated as manual, and the run goes on.
  bool continue_on_protocol_error = false;
  std::size_t max_frame_bytes = 16 << 20;  // larger replies are a protocol error
};

struct ClientStats {
  std::int64_t frames_sent = 0;      // telemetry (real or null) frames
  std::int64_t controls = 0;
  std::int64_t manuals = 0;
  // Malformed replies (unequal arrays, NaN, bad JSON) and second replies to one frame.
  std::int64_t protocol_errors = 0;
  std::int64_t ignored_frames = 0;   // pongs, binary and other non-42 frames
  std::string first_protocol_error;  // one line, empty when none
  // TCP_NODELAY as read back (getsockopt) from the connected socket: the client sets it, so a
  // frame is not held back by Nagle's algorithm waiting for the server's delayed ACK.
  bool tcp_nodelay = false;
};

// Every message goes out as the Unity simulator sends it: one unfragmented, masked text frame,
// whatever its size (no continuation frames), on a socket with TCP_NODELAY set.
//
// Connects to `url` (ws://HOST[:PORT][/PATH], e.g.
// ws://127.0.0.1:4567/socket.io/?EIO=4&transport=websocket; port 80 when omitted) and runs the
// exchange until endpoint.Done(), then closes the connection cleanly. Errors: a bad URL, connect
// or handshake failure (a refused upgrade with the server's status and reason), a timeout
// waiting for a reply, the server closing (at once, with its close code and reason), a frame
// whose header announces more than max_frame_bytes (at once), or (unless
// continue_on_protocol_error) a malformed reply or a second reply to one frame (a 42 frame that
// has arrived when the next frame is due to be sent). *stats (optional) is filled in every case.
Status RunClient(const std::string& url, SimulatorEndpoint& endpoint, const ClientOptions& options,
                 ClientStats* stats = nullptr);

}  // namespace frenetic::net

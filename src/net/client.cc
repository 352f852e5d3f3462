// The client runs each asynchronous step on a private io_context until it completes, so every
// step has a timeout without a second thread: on expiry the socket is closed, which completes the
// pending operation with an error. Steps follow the simulator's pacing (§2): ping "2" and
// telemetry on open, then exactly one frame after each control or manual reply. Before each
// frame is sent, a read is started and whatever has already arrived is looked at: a 42 frame
// there is a second reply to the previous frame.
#include "frenetic/net/client.h"

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "frenetic/wire/protocol.h"

namespace frenetic::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

// Beast masks a client's message in chunks of its write buffer (one frame, one socket write per
// chunk). A buffer that holds a whole telemetry frame (~2-15 kB) makes that a single write.
constexpr std::size_t kWriteBufferBytes = 64 << 10;

struct Url {
  std::string host, port, target;
};

StatusOr<Url> ParseUrl(const std::string& url) {
  const std::string bad = "url \"" + url + "\": expected ws://HOST[:PORT][/PATH]";
  std::string_view rest = url;
  if (rest.substr(0, 5) != "ws://") return Status::Error(bad);
  rest.remove_prefix(5);
  const std::size_t slash = rest.find_first_of("/?");
  std::string_view authority = rest.substr(0, slash);
  Url out;
  out.target = slash == std::string_view::npos ? "/" : std::string(rest.substr(slash));
  if (!out.target.empty() && out.target[0] == '?') out.target = "/" + out.target;
  out.port = "80";
  if (!authority.empty() && authority[0] == '[') {  // [IPv6]:port
    const std::size_t close = authority.find(']');
    if (close == std::string_view::npos) return Status::Error(bad);
    out.host = std::string(authority.substr(1, close - 1));
    authority.remove_prefix(close + 1);
    if (!authority.empty()) {
      if (authority[0] != ':') return Status::Error(bad);
      out.port = std::string(authority.substr(1));
    }
  } else {
    const std::size_t colon = authority.rfind(':');
    out.host = std::string(authority.substr(0, colon));
    if (colon != std::string_view::npos) out.port = std::string(authority.substr(colon + 1));
  }
  if (out.host.empty() || out.port.empty() ||
      out.port.find_first_not_of("0123456789") != std::string::npos || out.port.size() > 5 ||
      std::stoi(out.port) > 65535) {
    return Status::Error(bad);
  }
  return out;
}

// A close frame or a frame over the limit puts Beast into its closing handshake, which for a
// client waits for the server to close TCP first; a server that never does would hold the run
// until the reply timeout. The stream is checked this often while an operation is pending...
constexpr auto kWatchPeriod = std::chrono::milliseconds(25);
// ...and once it has left the open state for this long, its reading side is shut, which ends
// the handshake at once with Beast's own error (closed, message too big).
constexpr auto kClosingGrace = std::chrono::milliseconds(100);
// The closing handshake after a protocol error: the run is failing anyway.
constexpr double kErrorCloseTimeout = 0.25;

class Connection {
 public:
  Connection(const ClientOptions& options) : options_(options), ws_(io_), watch_(io_) {}

  Status Open(const Url& url) {
    tcp::resolver resolver(io_);
    beast::error_code ec;
    const auto results = resolver.resolve(url.host, url.port, ec);
    if (ec) return Status::Error("cannot resolve " + url.host + ": " + ec.message());
    ec = Await(options_.timeout, [&](auto handler) {
      beast::get_lowest_layer(ws_).async_connect(
          results, [handler](beast::error_code e, const tcp::endpoint&) mutable { handler(e); });
    });
    if (ec) return Status::Error("cannot connect to " + url.host + ":" + url.port + ": " + ec.message());
    // Without TCP_NODELAY the telemetry written right after the ping waits for the ping's ACK,
    // which the server delays (~40 ms) because it has nothing to send back.
    tcp::socket& socket = beast::get_lowest_layer(ws_).socket();
    socket.set_option(tcp::no_delay(true), ec);
    tcp::no_delay nodelay;
    if (!ec) socket.get_option(nodelay, ec);
    if (ec) return Status::Error("cannot set TCP_NODELAY: " + ec.message());
    nodelay_ = nodelay.value();
    // One frame per message, as the simulator sends (Beast splits messages larger than its
    // write buffer into continuation frames by default). Set before the handshake, as Beast
    // requires for the buffer size.
    ws_.auto_fragment(false);
    ws_.write_buffer_bytes(kWriteBufferBytes);
    ws_.read_message_max(options_.max_frame_bytes);
    websocket::response_type response;
    ec = Await(options_.timeout, [&](auto handler) {
      ws_.async_handshake(response, url.host + ":" + url.port, url.target,
                          [handler](beast::error_code e) mutable { handler(e); });
    });
    if (ec) {
      std::string why = ec.message();
      // A server that answers but declines (e.g. frenetic serve at its connection limit: 503
      // with the reason in the body) says why.
      if (response.result_int() != 0 &&
          response.result() != beast::http::status::switching_protocols) {
        std::string body = response.body().substr(0, 200);
        body.erase(
            std::remove_if(body.begin(), body.end(), [](char c) { return c == '\n' || c == '\r'; }),
            body.end());
        why = "the server answered " + std::to_string(response.result_int()) + " " +
              std::string(response.reason()) + (body.empty() ? "" : ": " + body);
      }
      return Status::Error("WebSocket handshake with " + url.host + ":" + url.port + url.target +
                           " failed: " + why);
    }
    ws_.text(true);
    opened_ = true;
    return Status::Ok();
  }

  beast::error_code Write(std::string_view frame) {
    return Await(options_.timeout, [&](auto handler) {
      ws_.async_write(asio::buffer(frame.data(), frame.size()),
                      [handler](beast::error_code e, std::size_t) mutable { handler(e); });
    });
  }

  // Starts reading the next message into frame() (the previous one is dropped); at most one read
  // is pending. A write may be started while it is.
  void StartRead() {
    if (reading_) return;
    buffer_.consume(buffer_.size());
    read_result_.reset();
    reading_ = true;
    ws_.async_read(buffer_, [this](beast::error_code e, std::size_t) {
      reading_ = false;
      read_result_ = e;
    });
  }
  // Runs what is ready without waiting (a message already received completes the read).
  void Poll() {
    io_.restart();
    io_.poll();
  }
  bool read_done() const { return read_result_.has_value(); }
  // Waits for the pending read (StartRead first); timed_out when none completes in time.
  beast::error_code WaitRead() {
    if (!RunUntil(options_.timeout, [this] { return read_done(); })) {
      return asio::error::timed_out;
    }
    return *read_result_;
  }
  std::string_view frame() const {
    const auto d = buffer_.data();
    return {static_cast<const char*>(d.data()), d.size()};
  }
  bool binary() const { return !ws_.got_text(); }
  bool nodelay() const { return nodelay_; }

  // Why a read failed, in words: the server's close frame (code and reason) when there was one.
  std::string Describe(beast::error_code ec) const {
    if (ec == asio::error::timed_out) return "no reply within the timeout";
    if (ec == websocket::error::message_too_big) {
      return "a frame over the client's limit of " + std::to_string(options_.max_frame_bytes) +
             " bytes (connection failed with 1009)";
    }
    if (ec == websocket::error::closed) {
      const websocket::close_reason& r = ws_.reason();
      std::string what = "the server closed the connection with code " + std::to_string(r.code);
      if (!r.reason.empty()) {
        std::string reason(r.reason.data(), std::min<std::size_t>(r.reason.size(), 123));
        std::replace_if(
            reason.begin(), reason.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
        what += " (\"" + reason + "\")";
      }
      return what;
    }
    return ec.message();
  }

  // The closing handshake, for at most `timeout` seconds.
  void CloseGracefully(double timeout) {
    Await(timeout, [&](auto handler) {
      ws_.async_close(websocket::close_code::normal,
                      [handler](beast::error_code e) mutable { handler(e); });
    });
  }

 private:
  // Runs the io_context until done() or `timeout`; on timeout closes the socket (which completes
  // the pending operations with an error), lets them complete and returns false.
  template <typename Done>
  bool RunUntil(double timeout, Done done) {
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(timeout));
    closing_seen_.reset();
    Watch();
    io_.restart();
    while (!done()) {
      if (io_.run_one_until(deadline) == 0 && (Clock::now() >= deadline || io_.stopped())) break;
    }
    watch_.cancel();
    if (done()) return true;
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().close(ignored);
    io_.restart();
    io_.run();
    return false;
  }

  // Starts an operation and runs until it completes (or the timeout: timed_out).
  template <typename Start>
  beast::error_code Await(double timeout, Start start) {
    std::optional<beast::error_code> result;
    start([&result](beast::error_code ec) { result = ec; });
    if (RunUntil(timeout, [&result] { return result.has_value(); })) return *result;
    return asio::error::timed_out;
  }

  // The watchdog of kWatchPeriod / kClosingGrace.
  void Watch() {
    watch_.expires_after(kWatchPeriod);
    watch_.async_wait([this](beast::error_code ec) {
      if (ec) return;
      if (opened_ && !ws_.is_open()) {
        const auto now = Clock::now();
        if (!closing_seen_) {
          closing_seen_ = now;
        } else if (now - *closing_seen_ >= kClosingGrace) {
          beast::error_code ignored;
          beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_receive, ignored);
        }
      }
      Watch();
    });
  }

  using Clock = std::chrono::steady_clock;
  const ClientOptions& options_;
  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_;
  asio::steady_timer watch_;
  beast::flat_buffer buffer_;
  bool nodelay_ = false;
  bool opened_ = false;
  bool reading_ = false;
  std::optional<beast::error_code> read_result_;
  std::optional<Clock::time_point> closing_seen_;
};

}  // namespace

Status RunClient(const std::string& url, SimulatorEndpoint& endpoint,
                 const ClientOptions& options, ClientStats* stats_out) {
  ClientStats local;
  ClientStats& stats = stats_out ? *stats_out : local;
  stats = ClientStats();
  if (!std::isfinite(options.timeout) || options.timeout <= 0) {
    return Status::Error("client timeout: must be a finite number of seconds > 0");
  }
  StatusOr<Url> parsed_url = ParseUrl(url);
  if (!parsed_url.ok()) return parsed_url.status();
  Connection conn(options);
  if (Status s = conn.Open(*parsed_url); !s.ok()) return s;
  stats.tcp_nodelay = conn.nodelay();
  if (options.send_ping) {
    if (auto ec = conn.Write(wire::kPingFrame)) {
      return Status::Error("sending the ping: " + ec.message());
    }
  }
  const auto wall_start = std::chrono::steady_clock::now();
  std::string next = endpoint.OnOpen();
  wire::ParsedReply reply;
  // A message that needs no answer (pong, binary, other non-42 frames) is counted and skipped.
  const auto ignorable = [&] {
    if (conn.binary()) return true;
    wire::ParseReply(conn.frame(), &reply);
    return reply.kind == wire::ReplyKind::kPong || reply.kind == wire::ReplyKind::kIgnored;
  };
  const auto protocol_error = [&](const std::string& what) {
    ++stats.protocol_errors;
    if (stats.first_protocol_error.empty()) stats.first_protocol_error = what;
    if (options.continue_on_protocol_error) return Status::Ok();
    conn.CloseGracefully(kErrorCloseTimeout);
    return Status::Error(what + " (the real simulator would stall here)");
  };
  while (!next.empty()) {
    if (options.realtime && endpoint.SimSeconds() >= 0) {
      std::this_thread::sleep_until(
          wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                           std::chrono::duration<double>(endpoint.SimSeconds())));
    }
    // Whatever 42 frame has arrived before this one is sent answers nothing: a second reply to
    // the last frame (it would be taken for the reply to this one, and every later exchange
    // would use a stale path). The read stays pending for the real reply.
    for (;;) {
      conn.StartRead();
      conn.Poll();
      if (!conn.read_done()) break;
      if (auto ec = conn.WaitRead()) {
        return Status::Error("after the reply to frame " + std::to_string(stats.frames_sent) +
                             ": " + conn.Describe(ec));
      }
      if (ignorable()) {
        ++stats.ignored_frames;
        continue;
      }
      const std::string what =
          stats.frames_sent == 0
              ? std::string("protocol error: a reply before any telemetry was sent")
              : "protocol error: a second reply to frame " + std::to_string(stats.frames_sent) +
                    " arrived before frame " + std::to_string(stats.frames_sent + 1) + " was sent";
      if (Status s = protocol_error(what); !s.ok()) return s;
    }
    if (auto ec = conn.Write(next)) {
      return Status::Error("sending frame " + std::to_string(stats.frames_sent + 1) + ": " +
                           conn.Describe(ec));
    }
    ++stats.frames_sent;
    // Wait for the reply to this frame, skipping what needs no answer (pongs, binary).
    for (;;) {
      conn.StartRead();
      if (auto ec = conn.WaitRead()) {
        return Status::Error("waiting for the reply to frame " + std::to_string(stats.frames_sent) +
                             ": " + conn.Describe(ec));
      }
      if (ignorable()) {
        ++stats.ignored_frames;
        continue;
      }
      break;
    }
    switch (reply.kind) {
      case wire::ReplyKind::kControl:
        ++stats.controls;
        next = endpoint.OnControl(reply.x, reply.y);
        break;
      case wire::ReplyKind::kManual:
        ++stats.manuals;
        next = endpoint.OnManual();
        break;
      default: {  // kMalformed
        if (Status s = protocol_error("protocol error in the reply to frame " +
                                      std::to_string(stats.frames_sent) + ": " + reply.error);
            !s.ok()) {
          return s;
        }
        next = endpoint.OnManual();
        break;
      }
    }
    if (endpoint.Done()) break;
  }
  conn.CloseGracefully(options.timeout);
  return Status::Ok();
}

}  // namespace frenetic::net

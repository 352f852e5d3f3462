// The client runs each asynchronous step on a private io_context with run_for(), so every step
// has a timeout without a second thread: on expiry the socket is closed, which completes the
// pending operation with an error. Steps follow the simulator's pacing (§2): ping "2" and
// telemetry on open, then exactly one frame after each control or manual reply.
#include "frenetic/net/client.h"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "frenetic/net/protocol.h"

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

class Connection {
 public:
  Connection(const ClientOptions& options) : options_(options), ws_(io_) {}

  Status Open(const Url& url) {
    tcp::resolver resolver(io_);
    beast::error_code ec;
    const auto results = resolver.resolve(url.host, url.port, ec);
    if (ec) return Status::Error("cannot resolve " + url.host + ": " + ec.message());
    ec = Await([&](auto handler) {
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
    ec = Await([&](auto handler) {
      ws_.async_handshake(url.host + ":" + url.port, url.target,
                          [handler](beast::error_code e) mutable { handler(e); });
    });
    if (ec) return Status::Error("WebSocket handshake with " + url.host + ":" + url.port + url.target + " failed: " + ec.message());
    ws_.text(true);
    return Status::Ok();
  }

  beast::error_code Write(std::string_view frame) {
    return Await([&](auto handler) {
      ws_.async_write(asio::buffer(frame.data(), frame.size()),
                      [handler](beast::error_code e, std::size_t) mutable { handler(e); });
    });
  }

  // Reads one message into frame(); binary() tells its type.
  beast::error_code Read() {
    buffer_.consume(buffer_.size());
    return Await([&](auto handler) {
      ws_.async_read(buffer_, [handler](beast::error_code e, std::size_t) mutable { handler(e); });
    });
  }
  std::string_view frame() const {
    const auto d = buffer_.data();
    return {static_cast<const char*>(d.data()), d.size()};
  }
  bool binary() const { return !ws_.got_text(); }
  bool nodelay() const { return nodelay_; }

  void CloseGracefully() {
    Await([&](auto handler) {
      ws_.async_close(websocket::close_code::normal,
                      [handler](beast::error_code e) mutable { handler(e); });
    });
  }

 private:
  // Starts an operation and runs the io_context until it completes or the timeout expires.
  template <typename Start>
  beast::error_code Await(Start start) {
    std::optional<beast::error_code> result;
    start([&result](beast::error_code ec) { result = ec; });
    io_.restart();
    io_.run_for(std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(options_.timeout)));
    if (result) return *result;
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().close(ignored);
    io_.restart();
    io_.run();  // lets the cancelled operation complete before `result` goes out of scope
    return asio::error::timed_out;
  }

  const ClientOptions& options_;
  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  bool nodelay_ = false;
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
    if (auto ec = conn.Write(kPingFrame)) return Status::Error("sending the ping: " + ec.message());
  }
  const auto wall_start = std::chrono::steady_clock::now();
  std::string next = endpoint.OnOpen();
  ParsedReply reply;
  while (!next.empty()) {
    if (options.realtime && endpoint.SimSeconds() >= 0) {
      std::this_thread::sleep_until(
          wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                           std::chrono::duration<double>(endpoint.SimSeconds())));
    }
    if (auto ec = conn.Write(next)) {
      return Status::Error("sending frame " + std::to_string(stats.frames_sent + 1) + ": " +
                           ec.message());
    }
    ++stats.frames_sent;
    // Wait for the reply to this frame, skipping what needs no answer (pongs, binary).
    for (;;) {
      if (auto ec = conn.Read()) {
        return Status::Error("waiting for the reply to frame " +
                             std::to_string(stats.frames_sent) + ": " +
                             (ec == asio::error::timed_out ? "no reply within the timeout"
                                                           : ec.message()));
      }
      if (conn.binary()) {
        ++stats.ignored_frames;
        continue;
      }
      ParseReply(conn.frame(), &reply);
      if (reply.kind == ReplyKind::kPong || reply.kind == ReplyKind::kIgnored) {
        ++stats.ignored_frames;
        continue;
      }
      break;
    }
    switch (reply.kind) {
      case ReplyKind::kControl:
        ++stats.controls;
        next = endpoint.OnControl(reply.x, reply.y);
        break;
      case ReplyKind::kManual:
        ++stats.manuals;
        next = endpoint.OnManual();
        break;
      default: {  // kMalformed
        ++stats.protocol_errors;
        const std::string what = "protocol error in the reply to frame " +
                                  std::to_string(stats.frames_sent) + ": " + reply.error;
        if (stats.first_protocol_error.empty()) stats.first_protocol_error = what;
        if (!options.continue_on_protocol_error) {
          conn.CloseGracefully();
          return Status::Error(what + " (the real simulator would stall here)");
        }
        next = endpoint.OnManual();
        break;
      }
    }
    if (endpoint.Done()) break;
  }
  conn.CloseGracefully();
  return Status::Ok();
}

}  // namespace frenetic::net

#include "net/session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <exception>
#include <mutex>

namespace frenetic::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

namespace {

// A reply queued behind one the peer does not read is planned for nobody: a small send buffer
// (the kernel doubles it) stops a non-reading client after a few dozen replies, not thousands.
constexpr int kSendBufferBytes = 64 << 10;
// A frame buffer grown past this by a large frame is given back once the frame is handled.
constexpr std::size_t kKeptBufferBytes = 64 << 10;
// A session's first plans, counted as heavy work whatever its usage.
constexpr int kYoungPlans = 10;

}  // namespace

Session::Session(Server::Impl* server, int id, tcp::socket socket)
    : server_(server),
      id_(id),
      ws_(std::move(socket)),
      write_timer_(server->io),
      read_timer_(server->io),
      read_tokens_(static_cast<double>(server->options.max_frame_bytes)) {
  beast::error_code ec;
  const auto remote = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
  peer_ =
      ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
  ++server_->live_sessions;
}

void Session::Start() {
  server_->sessions[id_] = weak_from_this();
  // Replies are answers the simulator waits for: no Nagle delay.
  tcp::socket& socket = beast::get_lowest_layer(ws_).socket();
  beast::error_code ec;
  socket.set_option(tcp::no_delay(true), ec);
  tcp::no_delay nodelay;
  if (!ec) socket.get_option(nodelay, ec);
  if (ec || !nodelay.value()) {
    spdlog::warn("session {} from {}: TCP_NODELAY not set{}", id_, peer_,
                 ec ? ": " + ec.message() : std::string());
  } else {
    std::lock_guard lock(server_->mutex);
    ++server_->stats.nodelay_connections;
  }
  beast::error_code ignored;
  socket.set_option(asio::socket_base::send_buffer_size(kSendBufferBytes), ignored);
  // One frame per reply (Beast would split replies over its 4096-byte write buffer into
  // continuation frames, which some Udacity-template programs mishandle).
  ws_.auto_fragment(false);
  auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
  timeouts.handshake_timeout = std::chrono::milliseconds(
      static_cast<std::int64_t>(server_->options.handshake_timeout * 1000.0));
  ws_.set_option(timeouts);
  ws_.read_message_max(server_->options.max_frame_bytes);
  ws_.set_option(websocket::stream_base::decorator(
      [](websocket::response_type& res) { res.set(beast::http::field::server, "frenetic"); }));
  ws_.control_callback([this](websocket::frame_type kind, beast::string_view) {
    if (kind == websocket::frame_type::close) OnCloseFrame();
  });
  // Any request target is accepted: Beast does not look at the path.
  ws_.async_accept([self = shared_from_this()](beast::error_code ec) { self->OnAccept(ec); });
}

void Session::Close() {
  closing_ = true;
  beast::error_code ec;
  beast::get_lowest_layer(ws_).socket().close(ec);
}

void Session::OnAccept(beast::error_code ec) {
  if (ec) {
    spdlog::warn("session {} from {}: WebSocket upgrade failed: {}", id_, peer_, ec.message());
    ended_ = true;
    Forget();
    return;
  }
  {
    std::lock_guard lock(server_->mutex);
    ++server_->stats.connections;
    ++server_->stats.open_connections;
  }
  upgraded_ = true;
  spdlog::info("session {} from {}: connected", id_, peer_);
  read_refill_ = Clock::now();
  DoRead();
}

// Reads the next frame once the byte budget allows (ServerOptions::max_read_bytes_per_second,
// a bucket of max_frame_bytes): a client that sends megabytes as fast as it can is read at
// that rate, and the I/O thread's time goes to the others.
void Session::ReadNext() {
  const double rate = server_->options.max_read_bytes_per_second;
  if (rate <= 0) {
    DoRead();
    return;
  }
  const Clock::time_point now = Clock::now();
  read_tokens_ =
      std::min(static_cast<double>(server_->options.max_frame_bytes),
               read_tokens_ + rate * std::chrono::duration<double>(now - read_refill_).count());
  read_refill_ = now;
  if (read_tokens_ >= 0) {
    DoRead();
    return;
  }
  read_timer_.expires_after(
      std::chrono::microseconds(static_cast<std::int64_t>(-read_tokens_ / rate * 1e6) + 1));
  read_timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (ec || self->closing_ || self->server_->stopping) return;
    self->ReadNext();
  });
}

void Session::DoRead() {
  ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->OnRead(ec);
  });
}

void Session::OnRead(beast::error_code ec) {
  if (ec) {
    End(ec);
    return;
  }
  ++frames_;
  read_tokens_ -= static_cast<double>(buffer_.size());
  if (!ws_.got_text()) {
    {
      std::lock_guard lock(server_->mutex);
      ++server_->stats.binary_frames;
    }
    Problem("binary frame of " + std::to_string(buffer_.size()) + " bytes ignored");
    FrameDone();
    ReadNext();
    return;
  }
  const std::string_view frame = Frame();
  if (frame.substr(0, 2) != "42") {
    // engine.io packets need no JSON: answered (or not) here, without a trip to the pool.
    wire::ParsedFrame parsed = wire::ParseFrame(frame, server_->options.frame_limits);
    Finish(Handle(parsed));
    return;
  }
  // The buffer is left alone until the work is done: no read is pending meanwhile.
  Waiting(+1);
  // A session without a planner yet builds it first: heavy work (~20 ms) of its own, after
  // which the frame is planned in its turn. A young session's first plans are heavy work
  // too (a new planner's caches are cold): connections that come, plan and go cannot take
  // the thread kept for established ones.
  server_->pool.Submit(&usage_, /*heavy=*/Young(), shared_from_this(), [this] {
    Waiting(-1);
    auto parsed = std::make_shared<wire::ParsedFrame>(
        wire::ParseFrame(Frame(), server_->options.frame_limits));
    if (parsed->kind == wire::FrameKind::kTelemetry && !planner_ && EnsurePlanner()) {
      Waiting(+1);
      server_->pool.Submit(&usage_, /*heavy=*/true, shared_from_this(), [this, parsed] {
        Waiting(-1);
        Done(Handle(*parsed));
      });
      return;
    }
    Done(Handle(*parsed));
  });
}

bool Session::Young() const { return planner_ == nullptr || plans_ < kYoungPlans; }

void Session::Waiting(int change) {
  std::lock_guard lock(server_->mutex);
  server_->stats.waiting_frames += change;
}

// On a planning thread: the frame was handled; the I/O thread takes over.
void Session::Done(bool answer) {
  asio::post(server_->io, [self = shared_from_this(), answer] { self->Finish(answer); });
}

std::string_view Session::Frame() const {
  const auto data = buffer_.data();
  return {static_cast<const char*>(data.data()), data.size()};
}

void Session::FrameDone() {
  buffer_.consume(buffer_.size());
  if (buffer_.capacity() > kKeptBufferBytes) buffer_.shrink_to_fit();
}

// I/O thread: the frame was handled (reply_ filled when `answer`).
void Session::Finish(bool answer) {
  FrameDone();
  if (closing_ || server_->stopping) {
    End(asio::error::operation_aborted);
    return;
  }
  if (!answer) {
    ReadNext();
    return;
  }
  ws_.text(true);
  write_timer_.expires_after(std::chrono::milliseconds(
      static_cast<std::int64_t>(server_->options.write_timeout * 1000.0)));
  write_timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (ec) return;  // cancelled: the write completed
    self->stalled_ = true;
    self->Close();
  });
  ws_.async_write(asio::buffer(reply_),
                  [self = shared_from_this()](beast::error_code ec, std::size_t) {
                    self->write_timer_.cancel();
                    if (self->reply_.capacity() > kKeptBufferBytes) {
                      std::string().swap(self->reply_);
                    }
                    // Without a planner (the factory failed) the connection ends after the
                    // manual answer.
                    if (ec || self->close_connection_) {
                      self->End(ec);
                      return;
                    }
                    self->ReadNext();
                  });
}

// A close frame arrived (its code is in ws_.reason()). Beast refuses the reserved codes itself
// (1005, 1006, 1015, 0-999, 1016-2999) with 1002, but echoes codes from 5000 up, which RFC 6455
// §7.4 leaves undefined: answer those with 1002 too, written here before Beast's echo, whose
// write then fails on the shut socket.
void Session::OnCloseFrame() {
  const std::uint16_t code = ws_.reason().code;
  if (code < 5000) return;
  {
    std::lock_guard lock(server_->mutex);
    ++server_->stats.bad_close_codes;
  }
  Problem("close frame with code " + std::to_string(code) +
          ", which RFC 6455 §7.4 does not define: failed with 1002");
  const char frame[4] = {static_cast<char>(0x88), 2, 0x03, static_cast<char>(0xEA)};
  tcp::socket& socket = beast::get_lowest_layer(ws_).socket();
  beast::error_code ignored;
  asio::write(socket, asio::buffer(frame, sizeof frame), ignored);
  socket.shutdown(tcp::socket::shutdown_both, ignored);
}

// Fills reply_ and returns true when the frame needs an answer. On a planning thread for 42
// frames (the I/O thread leaves this session alone meanwhile), on the I/O thread otherwise.
// Telemetry is planned with the session's planner (built here if need be).
bool Session::Handle(const wire::ParsedFrame& parsed) {
  ServerStats& st = server_->stats;
  switch (parsed.kind) {
    case wire::FrameKind::kTelemetry:
      if (!parsed.error.empty()) {
        {
          std::lock_guard lock(server_->mutex);
          ++st.repaired_frames;
        }
        Problem("telemetry repaired: " + parsed.error);
      }
      return Plan(parsed.telemetry);
    case wire::FrameKind::kNullTelemetry: {
      std::lock_guard lock(server_->mutex);
      ++st.null_telemetry;
      ++st.manual_replies;
      reply_ = wire::kManualFrame;
      return true;
    }
    case wire::FrameKind::kOtherEvent:
    case wire::FrameKind::kMalformed:
    case wire::FrameKind::kRefused: {
      {
        std::lock_guard lock(server_->mutex);
        ++(parsed.kind == wire::FrameKind::kMalformed ? st.malformed_frames
           : parsed.kind == wire::FrameKind::kRefused ? st.refused_frames
                                                      : st.other_events);
        ++st.manual_replies;
      }
      Problem(std::string(parsed.kind == wire::FrameKind::kMalformed ? "malformed frame"
                          : parsed.kind == wire::FrameKind::kRefused ? "frame over the limits"
                                                                     : "unexpected event") +
              " answered manual: " + parsed.error);
      reply_ = wire::kManualFrame;
      return true;
    }
    case wire::FrameKind::kPing: {
      std::lock_guard lock(server_->mutex);
      ++st.pings;
      reply_ = wire::kPongFrame;
      return server_->options.answer_ping;
    }
    case wire::FrameKind::kIgnored: {
      std::lock_guard lock(server_->mutex);
      ++st.ignored_frames;
      return false;
    }
  }
  return false;
}

// Builds the planner at the first telemetry; false (reply_ manual, the connection to close)
// when the factory fails.
bool Session::EnsurePlanner() {
  if (planner_) return true;
  if (close_connection_) return false;  // the factory failed already
  std::string why = "the planner factory returned nothing";
  try {
    planner_ = server_->factory();
  } catch (const std::exception& e) {
    why = std::string("the planner factory threw: ") + e.what();
  }
  std::lock_guard lock(server_->mutex);
  if (planner_) {
    ++server_->stats.planners_built;
    return true;
  }
  ++server_->stats.refused_connections;
  ++server_->stats.manual_replies;
  spdlog::error("session {}: no planner, answered manual and closing: {}", id_, why);
  close_connection_ = true;
  return false;
}

bool Session::Plan(const plan::Telemetry& telemetry) {
  if (!EnsurePlanner()) {
    reply_ = wire::kManualFrame;
    return true;
  }
  ++plans_;
  const auto start = Clock::now();
  const plan::PlanResult* result = nullptr;
  try {  // Plan() never throws by contract; a planner that does must not take the server down.
    result = &planner_->Plan(telemetry);
  } catch (const std::exception& e) {
    {
      std::lock_guard lock(server_->mutex);
      ++server_->stats.planner_exceptions;
      ++server_->stats.manual_replies;
    }
    Problem(std::string("planner threw, answered manual: ") + e.what());
    reply_ = wire::kManualFrame;
    return true;
  }
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  const std::size_t written = wire::FormatControl(result->x, result->y, &reply_);
  const bool bad = written != result->x.size() || written != result->y.size();
  {
    std::lock_guard lock(server_->mutex);
    ServerStats& st = server_->stats;
    ++st.cycles;
    if (bad) ++st.bad_plans;
    if (written < static_cast<std::size_t>(plan::kMinPathPoints)) ++st.short_paths;
    if (result->status == plan::PlanStatus::kFallbackUsed) ++st.fallback;
    if (result->status == plan::PlanStatus::kInvalidInput) ++st.invalid_input;
    if (result->status == plan::PlanStatus::kOverBudget) ++st.over_budget;
    Interval& iv = server_->interval;
    if (iv.plan_ms.size() < 100000) iv.plan_ms.push_back(ms);
    iv.speed = telemetry.speed;
    iv.d = telemetry.d;
    iv.have_ego = true;
  }
  if (bad) {
    Problem("planner returned " + std::to_string(result->x.size()) + " x and " +
            std::to_string(result->y.size()) + " y values, sent " + std::to_string(written) +
            " finite points");
  }
  return true;
}

// One warning line per problem, up to the configured count per connection.
void Session::Problem(const std::string& what) {
  const int cap = server_->options.max_logged_problems;
  if (problems_ < cap) {
    spdlog::warn("session {}: {}", id_, what);
  } else if (problems_ == cap) {
    spdlog::warn("session {}: further problems are counted, not logged", id_);
  }
  ++problems_;
}

// I/O thread, once: the session no longer counts against max_connections nor gets closed by
// Stop().
void Session::Forget() {
  server_->sessions.erase(id_);
  --server_->live_sessions;
}

void Session::End(beast::error_code ec) {
  if (ended_) return;
  ended_ = true;
  Forget();
  if (ec == websocket::error::message_too_big) {
    {
      std::lock_guard lock(server_->mutex);
      ++server_->stats.oversize_frames;
    }
    spdlog::warn("session {}: frame over {} bytes, connection closed", id_,
                 server_->options.max_frame_bytes);
  } else if (stalled_) {
    {
      std::lock_guard lock(server_->mutex);
      ++server_->stats.stalled_connections;
    }
    spdlog::warn(
        "session {}: a reply was not taken within {} s (the peer does not read), "
        "connection closed after {} frames",
        id_, server_->options.write_timeout, frames_);
  } else if (ec == websocket::error::closed) {
    spdlog::info("session {}: closed by the peer after {} frames", id_, frames_);
  } else if (server_->stopping) {
    spdlog::info("session {}: closed on shutdown after {} frames", id_, frames_);
  } else if (close_connection_) {
    spdlog::info("session {}: closed after {} frames: no planner", id_, frames_);
  } else {
    spdlog::info("session {}: disconnected after {} frames ({})", id_, frames_, ec.message());
  }
  if (upgraded_) {
    upgraded_ = false;
    std::lock_guard lock(server_->mutex);
    --server_->stats.open_connections;
  }
  write_timer_.cancel();
  read_timer_.cancel();
  Close();
  // No work is in the pool (End runs only between frames): the planner can go now, and its
  // memory back to the system.
  if (planner_) {
    planner_.reset();
    server_->ScheduleTrim();
  }
}

}  // namespace frenetic::net

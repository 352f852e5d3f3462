// One io_context on the thread that calls Run() moves the bytes; every 42 frame is handed to a
// planning pool, which converts it, plans and formats the reply, then posts the write back to
// the I/O thread. A session reads its next frame only after its reply is written, so it has at
// most one frame in the pool: its planner is never used by two threads at once, and a session
// that floods or stops reading delays only itself (the simulator sends only after a reply, §2).
// The pool is a priority queue by recent planning time, so a session that keeps the pool busy
// cannot push a well-paced one behind a queue of its own frames.
#include "frenetic/net/server.h"

#include <malloc.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <memory>
#include <mutex>
#include <vector>

#include "frenetic/cores.h"
#include "frenetic/percentile.h"
#include "frenetic/units.h"
#include "net/refusal.h"
#include "net/server_impl.h"
#include "net/session.h"

namespace frenetic::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
using tcp = asio::ip::tcp;

Status ServerOptions::Validate() const {
  if (port < 0 || port > 65535) {
    return Status::Error("port: " + std::to_string(port) + " is not in [0, 65535]");
  }
  boost::system::error_code ec;
  asio::ip::make_address(bind_address, ec);
  if (ec) return Status::Error("bind address: \"" + bind_address + "\" is not an IP address");
  if (max_frame_bytes < 1024) {
    return Status::Error("max frame bytes: " + std::to_string(max_frame_bytes) +
                         " is below 1024");
  }
  if (!std::isfinite(status_interval) || status_interval < 0) {
    return Status::Error("status interval: must be a finite number of seconds >= 0");
  }
  if (!std::isfinite(handshake_timeout) || handshake_timeout <= 0) {
    return Status::Error("handshake timeout: must be a finite number of seconds > 0");
  }
  if (!std::isfinite(write_timeout) || write_timeout <= 0) {
    return Status::Error("write timeout: must be a finite number of seconds > 0");
  }
  if (!std::isfinite(max_read_bytes_per_second) || max_read_bytes_per_second < 0) {
    return Status::Error("max read bytes per second: must be a finite number >= 0 (0 = no limit)");
  }
  if (max_logged_problems < 0) return Status::Error("max logged problems: must be >= 0");
  if (max_connections < 1 || max_connections > 10000) {
    return Status::Error("max connections: " + std::to_string(max_connections) +
                         " is not in [1, 10000]");
  }
  if (planning_threads < 0 || planning_threads > 256) {
    return Status::Error("planning threads: " + std::to_string(planning_threads) +
                         " is not in [0, 256] (0 = one per core)");
  }
  if (Status s = frame_limits.Validate(); !s.ok()) return Status::Error("frame " + s.message());
  return Status::Ok();
}

namespace {

// Refusals in progress at once, as a multiple of max_connections; beyond, a connection is closed
// at once without an answer.
constexpr int kRefusalsPerConnection = 4;
// Refusals logged per status interval; the rest are counted in the status line.
constexpr int kLoggedRefusals = 5;
// Memory is given back to the system once no connection has closed for this long: under churn
// the freed planners' memory is reused by the next ones.
constexpr auto kTrimDelay = std::chrono::milliseconds(500);

}  // namespace

void Server::Impl::Accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec) {
      if (ec == asio::error::operation_aborted || stopping) return;
      spdlog::warn("accept failed: {}", ec.message());
      Accept();
      return;
    }
    const int id = next_session_id++;
    if (live_sessions >= options.max_connections) {
      Refuse(std::move(socket), id);
    } else {
      std::make_shared<Session>(this, id, std::move(socket))->Start();
    }
    Accept();
  });
}

void Server::Impl::Refuse(tcp::socket socket, int id) {
  const std::string reason = "frenetic serve: " + std::to_string(live_sessions) +
                             " connections open, the limit (--max-connections " +
                             std::to_string(options.max_connections) + "); try again later";
  {
    std::lock_guard lock(mutex);
    ++stats.capacity_refusals;
    if (logged_refusals < kLoggedRefusals) {
      spdlog::warn("session {}: refused: {}", id, reason);
    } else if (logged_refusals == kLoggedRefusals) {
      spdlog::warn("further refusals are counted in the status line, not logged");
    }
    ++logged_refusals;
  }
  if (refusing >= kRefusalsPerConnection * options.max_connections) {
    beast::error_code ignored;
    socket.close(ignored);  // too many at once to answer each
    return;
  }
  StartRefusal(std::move(socket), reason, &refusing);
}

void Server::Impl::ScheduleTrim() {
  if (stopping) return;
  // Each close pushes the trim back: it runs once connections have stopped closing for a while.
  trim_timer.expires_after(kTrimDelay);
  trim_timer.async_wait([this](beast::error_code ec) {
    if (ec || stopping) return;
    // glibc keeps freed memory in its arenas (one per planning thread) unless asked; a planner
    // is several MB, so without this churn would only ever grow the resident set. Walking the
    // arenas takes a while: heavy work on a planning thread, not on the I/O thread.
    pool.SubmitHeavy([] { malloc_trim(0); });
  });
}

void Server::Impl::ScheduleStatus() {
  if (options.status_interval <= 0) return;
  status_timer.expires_after(std::chrono::milliseconds(
      std::max<std::int64_t>(1, static_cast<std::int64_t>(options.status_interval * 1000.0))));
  status_timer.async_wait([this](beast::error_code ec) {
    if (ec || stopping) return;
    LogStatus();
    ScheduleStatus();
  });
}

void Server::Impl::LogStatus() { spdlog::info("{}", StatusLine()); }

std::string Server::Impl::StatusLine() {
  std::lock_guard lock(mutex);
  Interval& iv = interval;
  const double p50 = PercentileInPlace(&iv.plan_ms, 0.50);
  const double p99 = PercentileInPlace(&iv.plan_ms, 0.99);
  std::string ego = "no telemetry yet";
  if (iv.have_ego) {
    const int lane = iv.d >= 0 && iv.d < 12 ? static_cast<int>(iv.d / 4.0) : -1;
    ego = fmt::format("speed {:.1f} m/s ({:.1f} mph), lane {}", iv.speed,
                      iv.speed * units::kSimMpsToMph, lane);
  }
  const ServerStats& s = stats;
  std::string line = fmt::format(
      "status: {} open connections, {} cycles (+{}), plan p50 {:.2f} ms p99 {:.2f} ms, {}; "
      "incidents: short paths {}, bad plans {}, fallback {}, invalid input {}, over budget {}, "
      "planner exceptions {}; frames: manual {}, malformed {}, repaired {}, over limits {}, "
      "binary {}, oversize {}; connections: refused at the limit {}, stalled {}, bad close "
      "codes {}",
      s.open_connections, s.cycles, s.cycles - iv.cycles_at_start, p50, p99, ego, s.short_paths,
      s.bad_plans, s.fallback, s.invalid_input, s.over_budget, s.planner_exceptions,
      s.manual_replies, s.malformed_frames, s.repaired_frames, s.refused_frames, s.binary_frames,
      s.oversize_frames, s.capacity_refusals, s.stalled_connections, s.bad_close_codes);
  iv.plan_ms.clear();
  iv.cycles_at_start = s.cycles;
  logged_refusals = 0;
  return line;
}

void Server::Impl::DoStop() {
  if (stopping) return;
  stopping = true;
  // Queued work is dropped (and the sessions it holds with it); the work in hand finishes.
  pool.Stop();
  beast::error_code ec;
  acceptor.close(ec);
  status_timer.cancel();
  trim_timer.cancel();
  signals.cancel(ec);
  // Copy first: closing makes sessions end, and their destructors unregister.
  std::vector<std::shared_ptr<Session>> live;
  for (auto& [id, weak] : sessions) {
    if (auto s = weak.lock()) live.push_back(std::move(s));
  }
  for (auto& s : live) s->Close();
}

Server::Server(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Server::~Server() = default;

StatusOr<std::unique_ptr<Server>> Server::Create(const ServerOptions& options,
                                                 PlannerFactory factory) {
  if (Status s = options.Validate(); !s.ok()) return s;
  if (!factory) return Status::Error("planner factory: empty");
  auto impl = std::make_unique<Impl>(options, std::move(factory));
  beast::error_code ec;
  const tcp::endpoint endpoint(asio::ip::make_address(options.bind_address, ec),
                               static_cast<unsigned short>(options.port));
  const std::string where = options.bind_address + ":" + std::to_string(options.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (ec) return Status::Error("cannot open a socket for " + where + ": " + ec.message());
  impl->acceptor.bind(endpoint, ec);
  if (ec) return Status::Error("cannot bind " + where + ": " + ec.message());
  impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return Status::Error("cannot listen on " + where + ": " + ec.message());
  impl->bound_port = impl->acceptor.local_endpoint().port();
  return std::unique_ptr<Server>(new Server(std::move(impl)));
}

int Server::port() const { return impl_->bound_port; }

void Server::Run() {
  Impl& s = *impl_;
  int threads = s.options.planning_threads;
  if (threads == 0) {
    threads = std::clamp(UsableCores(), 2, 8);
  }
  spdlog::info("listening on ws://{}:{} (any path), {} planning threads, at most {} connections",
               s.options.bind_address, s.bound_port, threads, s.options.max_connections);
  if (s.options.handle_signals) {
    s.signals.add(SIGINT);
    s.signals.add(SIGTERM);
    s.signals.async_wait([&s](beast::error_code ec, int signal) {
      if (ec) return;
      spdlog::info("signal {}: shutting down", signal);
      s.DoStop();
    });
  }
  s.pool.Start(threads, [&s](std::shared_ptr<void> session) {
    asio::post(s.io, [session = std::move(session)] {});
  });
  s.Accept();
  s.ScheduleStatus();
  s.io.run();
  s.pool.Stop();
  if (s.options.status_interval > 0) s.LogStatus();
  spdlog::info("server stopped");
}

void Server::Stop() {
  asio::post(impl_->io, [impl = impl_.get()] { impl->DoStop(); });
}

std::string Server::StatusLine() { return impl_->StatusLine(); }

ServerStats Server::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace frenetic::net
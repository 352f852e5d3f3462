// One io_context on the thread that calls Run() moves the bytes; every 42 frame is handed to a
// planning pool, which converts it, plans and formats the reply, then posts the write back to
// the I/O thread. A session reads its next frame only after its reply is written, so it has at
// most one frame in the pool: its planner is never used by two threads at once, and a session
// that floods or stops reading delays only itself (the simulator sends only after a reply, §2).
// The pool is a priority queue by recent planning time, so a session that keeps the pool busy
// cannot push a well-paced one behind a queue of its own frames.
#include "frenetic/net/server.h"

#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <deque>
#include <exception>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

namespace frenetic::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

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

class Session;

// Planning times and the last ego state of the current status interval.
struct Interval {
  std::vector<double> plan_ms;
  double speed = 0, d = 0;
  bool have_ego = false;
  std::int64_t cycles_at_start = 0;
};

double Percentile(std::vector<double>* v, double q) {
  if (v->empty()) return 0;
  const std::size_t k = std::min(v->size() - 1, static_cast<std::size_t>(q * v->size()));
  std::nth_element(v->begin(), v->begin() + k, v->end());
  return (*v)[k];
}

// A reply queued behind one the peer does not read is planned for nobody: a small send buffer
// (the kernel doubles it) stops a non-reading client after a few dozen replies, not thousands.
constexpr int kSendBufferBytes = 64 << 10;
// A frame buffer grown past this by a large frame is given back once the frame is handled.
constexpr std::size_t kKeptBufferBytes = 64 << 10;
// How long an over-capacity connection may take to send its upgrade request before the 503.
constexpr auto kRefusalTimeout = std::chrono::seconds(2);
// Refusals in progress at once, as a multiple of max_connections; beyond, a connection is closed
// at once without an answer.
constexpr int kRefusalsPerConnection = 4;
// Refusals logged per status interval; the rest are counted in the status line.
constexpr int kLoggedRefusals = 5;
// The time constant of a session's planning usage (pool priority), s.
constexpr double kUsageTau = 1.0;
// Usage (s of work over ~kUsageTau) beyond which a session's work is heavy: a tenth of a core.
// A simulator at 50 frames/s of ~1 ms each uses ~0.05. At a quarter, 7 flooding connections
// sharing the heavy thread (1/7 of a core each) fell back under it and took turns on the light
// thread, where a simulator's frame waited behind their plans (flood p99 12 ms).
constexpr double kHeavyUsage = 0.1;
// A session's first plans, counted as heavy work whatever its usage.
constexpr int kYoungPlans = 10;
// The niceness of the threads that run heavy work.
constexpr int kHeavyNice = 5;
// Memory is given back to the system once no connection has closed for this long: under churn
// the freed planners' memory is reused by the next ones.
constexpr auto kTrimDelay = std::chrono::milliseconds(500);

// A session's recent planning time, for the pool's choice: seconds of work, decayed with
// kUsageTau. Read and written under the pool's lock only.
struct Usage {
  double seconds = 0;
  Clock::time_point at = Clock::now();

  double Now(Clock::time_point now) const {
    const double age = std::chrono::duration<double>(now - at).count();
    return seconds * std::exp(-std::max(0.0, age) / kUsageTau);
  }
};

// Runs queued work on a few threads. It takes the waiting work of the session with the least
// recent planning time (ties: the first queued). Heavy work (a session that has used more than
// kHeavyUsage lately, building a planner, a session's first plans, giving memory back) never
// runs on the first thread, kept for light work, and runs at a lower priority: a well-paced
// session's frame waits for at most one light frame to finish, however many connections flood
// or churn.
class PlanningPool {
 public:
  using Work = std::function<void()>;
  // Drops a session's reference once its work ran; the server drops it on the I/O thread, so
  // that a session is never destroyed on a planning thread.
  using Release = std::function<void(std::shared_ptr<void>)>;

  void Start(int threads, Release release) {
    release_ = std::move(release);
    has_light_thread_ = threads > 1;
    for (int i = 0; i < threads; ++i) {
      threads_.emplace_back([this, light = has_light_thread_ && i == 0] { Loop(light); });
    }
  }
  // Stops the threads after the work in hand; queued work is dropped. Idempotent.
  void Stop() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      queue_.clear();
    }
    cv_.notify_all();
    for (std::thread& t : threads_) t.join();
    threads_.clear();
  }
  ~PlanningPool() { Stop(); }

  // Queues `work` for the session whose usage is *usage (owned by the session; `keep` holds it
  // alive until the work ran); `heavy` when the work is known to be long (a planner to build).
  void Submit(Usage* usage, bool heavy, std::shared_ptr<void> keep, Work work) {
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
      // Classified once, when queued: a class that changed while the work waits (the usage
      // decays) could leave it to a thread that is not looking.
      heavy = heavy || usage->Now(Clock::now()) > kHeavyUsage;
      queue_.push_back({usage, heavy, std::move(keep), std::move(work)});
    }
    cv_.notify_all();  // not every thread takes every work
  }
  // Heavy work of no session (its usage is the pool's own).
  void SubmitHeavy(Work work) { Submit(&own_usage_, true, nullptr, std::move(work)); }

 private:
  struct Item {
    Usage* usage;
    bool heavy;
    std::shared_ptr<void> keep;
    Work work;
  };

  // The queued item to run next (queue_.end() when none may run now).
  // The queued item a thread runs next (queue_.end() when none is for it now). The light
  // thread takes only light work; the others take any, light work only while the light thread
  // is busy.
  std::deque<Item>::iterator Pick(Clock::time_point now, bool light_thread) {
    auto best = queue_.end();
    double best_usage = 0;
    for (auto it = queue_.begin(); it != queue_.end(); ++it) {
      if (light_thread ? it->heavy : !it->heavy && has_light_thread_ && !light_busy_) continue;
      const double u = it->usage->Now(now);
      if (best == queue_.end() || u < best_usage) {
        best = it;
        best_usage = u;
      }
    }
    return best;
  }

  void Loop(bool light_thread) {
    // Heavy work runs at a lower priority than the light thread and the I/O thread: when the
    // machine is short of cores, floods and churn wait, not the simulators (nice is per thread
    // on Linux; failing to set it is harmless).
    if (has_light_thread_ && !light_thread) {
      // Also when the server runs under a real-time policy (chrt -f, to keep a busy machine's
      // other work from delaying the simulator's replies): heavy work then stays out of it.
      const sched_param normal{};
      (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
      (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kHeavyNice);
    }
    for (;;) {
      Item item;
      {
        std::unique_lock lock(mutex_);
        auto next = queue_.end();
        cv_.wait(lock, [&] {
          if (stopping_) return true;
          next = Pick(Clock::now(), light_thread);
          return next != queue_.end();
        });
        if (stopping_) return;
        item = std::move(*next);
        queue_.erase(next);
        if (light_thread) light_busy_ = true;
      }
      const Clock::time_point start = Clock::now();
      item.work();
      const Clock::time_point end = Clock::now();
      {
        std::lock_guard lock(mutex_);
        item.usage->seconds =
            item.usage->Now(end) + std::chrono::duration<double>(end - start).count();
        item.usage->at = end;
        if (light_thread) light_busy_ = false;
      }
      if (light_thread) cv_.notify_all();  // light work left to the others goes back to it
      if (item.keep) release_(std::move(item.keep));
    }
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Item> queue_;
  bool stopping_ = false;
  bool has_light_thread_ = false;  // set before the threads start
  bool light_busy_ = false;
  Usage own_usage_;
  Release release_;
  std::vector<std::thread> threads_;
};

}  // namespace

struct Server::Impl {
  Impl(const ServerOptions& o, PlannerFactory f) : options(o), factory(std::move(f)) {}

  void Accept();
  void Refuse(tcp::socket socket, int id);
  void ScheduleStatus();
  void ScheduleTrim();
  void LogStatus();
  std::string StatusLine();
  void DoStop();

  ServerOptions options;
  PlannerFactory factory;
  int bound_port = 0;
  int next_session_id = 1;
  bool stopping = false;  // I/O thread only
  int live_sessions = 0;  // upgrading or upgraded; I/O thread only
  int refusing = 0;       // 503 answers in progress; I/O thread only

  mutable std::mutex mutex;  // guards stats, interval and logged_refusals
  ServerStats stats;
  Interval interval;
  int logged_refusals = 0;

  // Live sessions, for closing them on Stop(). Declared before io so that handlers destroyed
  // with io (which own sessions) can still unregister.
  std::map<int, std::weak_ptr<Session>> sessions;

  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer status_timer{io};
  asio::steady_timer trim_timer{io};
  asio::signal_set signals{io};
  // Declared after io: its threads post to io, and the sessions it holds close their sockets.
  PlanningPool pool;
};

namespace {

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(Server::Impl* server, int id, tcp::socket socket)
      : server_(server),
        id_(id),
        ws_(std::move(socket)),
        write_timer_(server->io),
        read_timer_(server->io),
        read_tokens_(static_cast<double>(server->options.max_frame_bytes)) {
    beast::error_code ec;
    const auto remote = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    peer_ = ec ? std::string("?") : remote.address().to_string() + ":" +
                                        std::to_string(remote.port());
    ++server_->live_sessions;
  }

  // Its place is given up in End() (or when the upgrade fails), on the I/O thread: the last
  // reference may go anywhere.

  void Start() {
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
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
      res.set(beast::http::field::server, "frenetic");
    }));
    ws_.control_callback([this](websocket::frame_type kind, beast::string_view) {
      if (kind == websocket::frame_type::close) OnCloseFrame();
    });
    // Any request target is accepted: Beast does not look at the path.
    ws_.async_accept(
        [self = shared_from_this()](beast::error_code ec) { self->OnAccept(ec); });
  }

  void Close() {
    closing_ = true;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  void OnAccept(beast::error_code ec) {
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
  void ReadNext() {
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

  void DoRead() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->OnRead(ec);
    });
  }

  void OnRead(beast::error_code ec) {
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
      ParsedFrame parsed = ParseFrame(frame, server_->options.frame_limits);
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
      auto parsed =
          std::make_shared<ParsedFrame>(ParseFrame(Frame(), server_->options.frame_limits));
      if (parsed->kind == FrameKind::kTelemetry && !planner_ && EnsurePlanner()) {
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

  // Whether this session has yet to build its planner or to plan kYoungPlans frames. Read on
  // the I/O thread between frames (the pool hands the session back through a post).
  bool Young() const { return planner_ == nullptr || plans_ < kYoungPlans; }

  void Waiting(int change) {
    std::lock_guard lock(server_->mutex);
    server_->stats.waiting_frames += change;
  }

  // On a planning thread: the frame was handled; the I/O thread takes over.
  void Done(bool answer) {
    asio::post(server_->io, [self = shared_from_this(), answer] { self->Finish(answer); });
  }

  std::string_view Frame() const {
    const auto data = buffer_.data();
    return {static_cast<const char*>(data.data()), data.size()};
  }

  void FrameDone() {
    buffer_.consume(buffer_.size());
    if (buffer_.capacity() > kKeptBufferBytes) buffer_.shrink_to_fit();
  }

  // I/O thread: the frame was handled (reply_ filled when `answer`).
  void Finish(bool answer) {
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
  void OnCloseFrame() {
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
  bool Handle(const ParsedFrame& parsed) {
    ServerStats& st = server_->stats;
    switch (parsed.kind) {
      case FrameKind::kTelemetry:
        if (!parsed.error.empty()) {
          {
            std::lock_guard lock(server_->mutex);
            ++st.repaired_frames;
          }
          Problem("telemetry repaired: " + parsed.error);
        }
        return Plan(parsed.telemetry);
      case FrameKind::kNullTelemetry: {
        std::lock_guard lock(server_->mutex);
        ++st.null_telemetry;
        ++st.manual_replies;
        reply_ = kManualFrame;
        return true;
      }
      case FrameKind::kOtherEvent:
      case FrameKind::kMalformed:
      case FrameKind::kRefused: {
        {
          std::lock_guard lock(server_->mutex);
          ++(parsed.kind == FrameKind::kMalformed ? st.malformed_frames
             : parsed.kind == FrameKind::kRefused ? st.refused_frames
                                                  : st.other_events);
          ++st.manual_replies;
        }
        Problem(std::string(parsed.kind == FrameKind::kMalformed ? "malformed frame"
                            : parsed.kind == FrameKind::kRefused ? "frame over the limits"
                                                                 : "unexpected event") +
                " answered manual: " + parsed.error);
        reply_ = kManualFrame;
        return true;
      }
      case FrameKind::kPing: {
        std::lock_guard lock(server_->mutex);
        ++st.pings;
        reply_ = kPongFrame;
        return server_->options.answer_ping;
      }
      case FrameKind::kIgnored: {
        std::lock_guard lock(server_->mutex);
        ++st.ignored_frames;
        return false;
      }
    }
    return false;
  }

  // Builds the planner at the first telemetry; false (reply_ manual, the connection to close)
  // when the factory fails.
  bool EnsurePlanner() {
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

  bool Plan(const plan::Telemetry& telemetry) {
    if (!EnsurePlanner()) {
      reply_ = kManualFrame;
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
      reply_ = kManualFrame;
      return true;
    }
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    const std::size_t written = FormatControl(result->x, result->y, &reply_);
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
  void Problem(const std::string& what) {
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
  void Forget() {
    server_->sessions.erase(id_);
    --server_->live_sessions;
  }

  void End(beast::error_code ec) {
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

  Server::Impl* server_;
  int id_;
  websocket::stream<beast::tcp_stream> ws_;
  asio::steady_timer write_timer_;
  asio::steady_timer read_timer_;
  double read_tokens_;  // bytes that may be read now (negative: owed)
  Clock::time_point read_refill_;
  std::unique_ptr<plan::Planner> planner_;
  beast::flat_buffer buffer_;
  std::string reply_;
  std::string peer_;
  Usage usage_;  // pool priority (the pool's lock guards it)
  std::int64_t frames_ = 0;
  std::int64_t plans_ = 0;  // Plan() calls (planning thread; read between frames)
  int problems_ = 0;
  bool upgraded_ = false;
  bool closing_ = false;
  bool ended_ = false;
  bool stalled_ = false;
  bool close_connection_ = false;
};

// Answers one connection over max_connections: reads its upgrade request (so that closing does
// not reset the connection before the client reads the answer), writes a 503 naming the limit,
// and closes.
class Refusal : public std::enable_shared_from_this<Refusal> {
 public:
  Refusal(Server::Impl* server, tcp::socket socket) : server_(server), stream_(std::move(socket)) {
    ++server_->refusing;
    parser_.header_limit(8 << 10);
    parser_.body_limit(0);
  }
  ~Refusal() { --server_->refusing; }

  void Start(std::string reason) {
    reason_ = std::move(reason);
    stream_.expires_after(kRefusalTimeout);
    http::async_read(
        stream_, buffer_, parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->OnRequest(ec); });
  }

 private:
  void OnRequest(beast::error_code ec) {
    if (ec) return;  // no request in time: closed without an answer
    response_ =
        "HTTP/1.1 503 Service Unavailable\r\nServer: frenetic\r\nRetry-After: 1\r\n"
        "Content-Type: text/plain\r\nConnection: close\r\nContent-Length: " +
        std::to_string(reason_.size() + 1) + "\r\n\r\n" + reason_ + "\n";
    asio::async_write(stream_.socket(), asio::buffer(response_),
                      [self = shared_from_this()](beast::error_code, std::size_t) {
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                        self->stream_.close();
                      });
  }

  Server::Impl* server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request_parser<http::empty_body> parser_;
  std::string reason_, response_;
};

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
  std::make_shared<Refusal>(this, std::move(socket))->Start(reason);
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
  const double p50 = Percentile(&iv.plan_ms, 0.50);
  const double p99 = Percentile(&iv.plan_ms, 0.99);
  std::string ego = "no telemetry yet";
  if (iv.have_ego) {
    const int lane = iv.d >= 0 && iv.d < 12 ? static_cast<int>(iv.d / 4.0) : -1;
    ego = fmt::format("speed {:.1f} m/s ({:.1f} mph), lane {}", iv.speed, iv.speed * kMpsToMph,
                      lane);
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
    threads = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 2, 8);
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

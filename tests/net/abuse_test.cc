// `frenetic serve` under load and abuse, on loopback: many clients, clients that pipeline and
// never read, oversized and pathological frames, invalid close codes, connections over the cap,
// churn. Each test asserts behaviour (every well-behaved exchange answered and valid, refusals,
// closes, memory back after churn), never timing; every wait is bounded by a count or a
// generous timeout, so a broken server fails a test instead of hanging it. How fast the replies
// are under the same abuse is measured by scripts/serve-abuse.sh, not asserted here.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/net/client.h"
#include "frenetic/net/server.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/sanitizers.h"
#include "frenetic/wire/protocol.h"
#include "net/net_test_util.h"
#include "net/raw_websocket.h"

namespace frenetic::net {
namespace {

using testing::CloseCode;
using testing::ConnectUpgraded;
using testing::EncodeCloseFrame;
using testing::EncodeRawFrame;
using testing::FakePlanner;
using testing::kOpClose;
using testing::kOpText;
using testing::RawFrame;
using testing::RawSocket;
using testing::ReadRawFrame;
using testing::TelemetryFrameAt;
using testing::TestClient;
using testing::TestServer;

// Checks that `reply` is the fake planner's control for an ego at (x, y) on its `cycle`-th call.
::testing::AssertionResult IsControlFor(const std::optional<std::string>& reply, double x, double y,
                                        int cycle) {
  if (!reply.has_value()) return ::testing::AssertionFailure() << "no reply";
  wire::ParsedReply r;
  wire::ParseReply(*reply, &r);
  if (r.kind != wire::ReplyKind::kControl) {
    return ::testing::AssertionFailure()
           << "not a control: " << reply->substr(0, 80) << " " << r.error;
  }
  if (r.x.size() != static_cast<std::size_t>(plan::kMinPathPoints) || std::abs(r.x[0] - x) > 1e-3 ||
      std::abs(r.y[0] - (y + cycle)) > 1e-3) {
    return ::testing::AssertionFailure()
           << "control for the wrong telemetry or cycle: x0 " << (r.x.empty() ? -1 : r.x[0])
           << " y0 " << (r.y.empty() ? -1 : r.y[0]) << ", expected " << x << ", " << y + cycle;
  }
  return ::testing::AssertionSuccess();
}

// Waits (bounded) until pred() holds; returns whether it did.
template <typename Pred>
bool Eventually(Pred pred, double seconds = 10.0) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(seconds));
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

std::string ClientText(std::string_view payload) {
  return EncodeRawFrame(kOpText, payload, /*mask=*/true);
}

// A well-behaved simulator's run: `exchanges` telemetry frames at (x0 + k, 7), each reply
// checked. Returns the number of replies that were right.
int WellBehavedRun(int port, int exchanges, double x0) {
  TestClient client;
  if (!client.Connect(port)) return 0;
  int good = 0;
  for (int k = 1; k <= exchanges; ++k) {
    const auto reply = client.Exchange(TelemetryFrameAt(x0 + k, 7));
    const auto ok = IsControlFor(reply, x0 + k, 7, k);
    EXPECT_TRUE(ok) << "exchange " << k;
    if (!ok) break;
    ++good;
  }
  client.Close();
  return good;
}

TEST(AbuseTest, ClientsUpToTheCapEachGetEveryReplyRight) {
  ServerOptions options;
  options.max_connections = 8;
  TestServer server(options);
  constexpr int kExchanges = 60;
  std::vector<int> good(options.max_connections, 0);
  std::vector<std::thread> threads;
  for (int i = 0; i < options.max_connections; ++i) {
    threads.emplace_back(
        [&, i] { good[i] = WellBehavedRun(server.port(), kExchanges, 1000.0 * i); });
  }
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < options.max_connections; ++i) EXPECT_EQ(good[i], kExchanges) << i;
  EXPECT_EQ(server.server().stats().cycles, options.max_connections * kExchanges);
  EXPECT_EQ(server.planners_made, options.max_connections);
}

// A planner for the scheduling tests: telemetry at x = kBlockX blocks until Release(), at
// x = kBusyX takes kBusyMs; every call is logged (x, in order) and a planner used by two threads
// at once is noted.
struct PlannerGate {
  static constexpr double kBlockX = 666, kBusyX = 777;
  static constexpr int kBusyMs = 60;
  std::mutex mutex;
  std::condition_variable cv;
  bool released = false, blocked = false;
  std::vector<double> calls;
  std::atomic<int> overlaps{0};
  void Release() {
    {
      std::lock_guard lock(mutex);
      released = true;
    }
    cv.notify_all();
  }
};

class GatedPlanner : public FakePlanner {
 public:
  explicit GatedPlanner(PlannerGate* gate) : gate_(gate) {}
  const plan::PlanResult& Plan(const plan::Telemetry& t) override {
    if (in_plan_.fetch_add(1) > 0) ++gate_->overlaps;
    {
      std::unique_lock lock(gate_->mutex);
      gate_->calls.push_back(t.x);
      if (t.x == PlannerGate::kBlockX) {
        gate_->blocked = true;
        gate_->cv.wait(lock, [this] { return gate_->released; });
      }
    }
    if (t.x == PlannerGate::kBusyX) {
      std::this_thread::sleep_for(std::chrono::milliseconds(PlannerGate::kBusyMs));
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // room for an overlap
    const plan::PlanResult& r = FakePlanner::Plan(t);
    --in_plan_;
    return r;
  }

 private:
  PlannerGate* gate_;
  std::atomic<int> in_plan_{0};
};

// Releases the gate when it goes: declared after the server, it goes first, so a failed test
// does not leave a planning thread blocked while the server waits for it to stop.
struct ReleaseAtEnd {
  PlannerGate* gate;
  ~ReleaseAtEnd() { gate->Release(); }
};

PlannerFactory GatedFactory(PlannerGate* gate) {
  return
      [gate]() -> std::unique_ptr<plan::Planner> { return std::make_unique<GatedPlanner>(gate); };
}

// A planner that never returns (until released) holds one planning thread, not the server.
TEST(AbuseTest, NoConnectionWaitsForAnothersPlanner) {
  PlannerGate gate;
  ServerOptions options;
  options.planning_threads = 2;
  TestServer server(options, GatedFactory(&gate));
  ReleaseAtEnd release{&gate};
  TestClient stuck;
  ASSERT_TRUE(stuck.Connect(server.port()));
  for (int k = 1; k <= 12; ++k) {  // an established connection...
    ASSERT_TRUE(IsControlFor(stuck.Exchange(TelemetryFrameAt(5, 0)), 5, 0, k));
  }
  ASSERT_FALSE(stuck.Send(TelemetryFrameAt(PlannerGate::kBlockX, 0)));  // ...whose planner stalls
  ASSERT_TRUE(Eventually([&] {
    std::lock_guard lock(gate.mutex);
    return gate.blocked;
  }));
  EXPECT_EQ(WellBehavedRun(server.port(), 30, 10), 30) << "answered while the other is stuck";
  gate.Release();
  EXPECT_TRUE(IsControlFor(stuck.Receive(), PlannerGate::kBlockX, 0, 13));
}

// Heavy work (building planners, a connection's first plans, a connection that uses more than
// a quarter of a core) never takes the last planning thread: connections that come, plan and
// go, or flood, cannot hold up an established one, even when their work stalls.
TEST(AbuseTest, HeavyWorkLeavesAThreadForEstablishedConnections) {
  PlannerGate gate;
  ServerOptions options;
  options.planning_threads = 2;
  TestServer server(options, GatedFactory(&gate));
  ReleaseAtEnd release{&gate};
  TestClient established, young, younger;
  ASSERT_TRUE(established.Connect(server.port()) && young.Connect(server.port()) &&
              younger.Connect(server.port()));
  for (int k = 1; k <= 12; ++k) {
    ASSERT_TRUE(IsControlFor(established.Exchange(TelemetryFrameAt(3, 0)), 3, 0, k));
  }
  ASSERT_FALSE(young.Send(TelemetryFrameAt(PlannerGate::kBlockX, 0)));  // its first plan stalls
  ASSERT_TRUE(Eventually([&] {
    std::lock_guard lock(gate.mutex);
    return gate.blocked;
  }));
  ASSERT_FALSE(younger.Send(TelemetryFrameAt(8, 0)));
  ASSERT_TRUE(Eventually([&] { return server.server().stats().waiting_frames == 1; }));
  for (int k = 13; k <= 30; ++k) {  // the kept thread answers the established connection...
    ASSERT_TRUE(IsControlFor(established.Exchange(TelemetryFrameAt(3, 0)), 3, 0, k));
  }
  EXPECT_EQ(server.server().stats().waiting_frames, 1) << "...but not a young one";
  gate.Release();
  EXPECT_TRUE(IsControlFor(young.Receive(), PlannerGate::kBlockX, 0, 1));
  EXPECT_TRUE(IsControlFor(younger.Receive(), 8, 0, 1));
}

// With every planning thread taken, the waiting connection that has planned least lately goes
// first: a connection that keeps the pool busy cannot push a well-paced one behind its work.
TEST(AbuseTest, ThePoolServesTheLeastBusyConnectionFirst) {
  PlannerGate gate;
  ServerOptions options;
  options.planning_threads = 1;
  TestServer server(options, GatedFactory(&gate));
  ReleaseAtEnd release{&gate};
  TestClient busy, stuck, fresh;
  ASSERT_TRUE(busy.Connect(server.port()) && stuck.Connect(server.port()) &&
              fresh.Connect(server.port()));
  EXPECT_TRUE(IsControlFor(busy.Exchange(TelemetryFrameAt(PlannerGate::kBusyX, 0)),
                           PlannerGate::kBusyX, 0, 1));
  ASSERT_FALSE(stuck.Send(TelemetryFrameAt(PlannerGate::kBlockX, 0)));  // takes the only thread
  ASSERT_TRUE(Eventually([&] {
    std::lock_guard lock(gate.mutex);
    return gate.blocked;
  }));
  ASSERT_FALSE(busy.Send(TelemetryFrameAt(1, 0)));  // queued first...
  ASSERT_TRUE(Eventually([&] { return server.server().stats().waiting_frames == 1; }));
  ASSERT_FALSE(fresh.Send(TelemetryFrameAt(2, 0)));  // ...then this one
  ASSERT_TRUE(Eventually([&] { return server.server().stats().waiting_frames == 2; }));
  gate.Release();
  EXPECT_TRUE(IsControlFor(busy.Receive(), 1, 0, 2));
  EXPECT_TRUE(IsControlFor(fresh.Receive(), 2, 0, 1));
  std::lock_guard lock(gate.mutex);
  EXPECT_EQ(gate.calls, (std::vector<double>{PlannerGate::kBusyX, PlannerGate::kBlockX, 2, 1}));
}

// Frames sent back to back without reading are answered one each, in order, and the
// connection's planner is never used by two threads at once, however many the pool has.
TEST(AbuseTest, PipelinedFramesAreAnsweredOneEachInOrder) {
  PlannerGate gate;
  ServerOptions options;
  options.planning_threads = 4;
  TestServer server(options, GatedFactory(&gate));
  ReleaseAtEnd release{&gate};
  RawSocket s = ConnectUpgraded(server.port());
  ASSERT_TRUE(s.ok());
  constexpr int kFrames = 40;
  std::string burst;
  for (int k = 1; k <= kFrames; ++k) burst += ClientText(TelemetryFrameAt(k, 3));
  ASSERT_TRUE(s.WriteAll(burst));
  for (int k = 1; k <= kFrames; ++k) {
    const std::optional<RawFrame> f = ReadRawFrame(s);
    ASSERT_TRUE(f.has_value()) << "no reply " << k;
    EXPECT_TRUE(IsControlFor(f->payload, k, 3, k)) << "reply " << k;
  }
  EXPECT_FALSE(ReadRawFrame(s, 0.3).has_value()) << "one reply per frame, no more";
  EXPECT_EQ(server.server().stats().cycles, kFrames);
  EXPECT_EQ(gate.overlaps, 0);
}

TEST(AbuseTest, AClientOverTheCapIsRefusedWith503NamingTheLimit) {
  ServerOptions options;
  options.max_connections = 3;
  TestServer server(options);
  std::vector<std::unique_ptr<TestClient>> clients;
  for (int i = 0; i < options.max_connections; ++i) {
    clients.push_back(std::make_unique<TestClient>());
    ASSERT_TRUE(clients.back()->Connect(server.port()));
    EXPECT_TRUE(IsControlFor(clients.back()->Exchange(TelemetryFrameAt(i, 0)), i, 0, 1));
  }
  std::string response;
  RawSocket over = RawSocket::Connect(server.port());
  ASSERT_TRUE(over.ok());
  ASSERT_TRUE(testing::UpgradeByHand(over, server.port(), &response));
  EXPECT_EQ(response.rfind("HTTP/1.1 503 Service Unavailable\r\n", 0), 0u) << response;
  std::string body;
  over.ReadUntil("\n", &body);
  EXPECT_NE(body.find("3 connections open, the limit (--max-connections 3)"), std::string::npos)
      << body;
  // The simulator's side says why.
  class OneFrame : public SimulatorEndpoint {
   public:
    std::string OnOpen() override { return std::string(wire::kNullTelemetryFrame); }
    std::string OnControl(std::span<const double>, std::span<const double>) override { return ""; }
    std::string OnManual() override { return ""; }
    bool Done() const override { return true; }
  } endpoint;
  const Status s =
      RunClient("ws://127.0.0.1:" + std::to_string(server.port()) + "/", endpoint, ClientOptions());
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("the server answered 503 Service Unavailable: frenetic serve: 3 "
                             "connections open, the limit (--max-connections 3)"),
            std::string::npos)
      << s.message();
  EXPECT_EQ(server.server().stats().capacity_refusals, 2);
  EXPECT_EQ(server.planners_made, options.max_connections) << "no planner for a refusal";
  // A place freed is a place taken.
  clients.front()->Close();
  clients.erase(clients.begin());
  EXPECT_TRUE(Eventually([&] { return server.server().stats().open_connections == 2; }));
  TestClient next;
  ASSERT_TRUE(next.Connect(server.port()));
  EXPECT_TRUE(IsControlFor(next.Exchange(TelemetryFrameAt(9, 9)), 9, 9, 1));
}

TEST(AbuseTest, ThePlannerIsBuiltAtTheFirstTelemetryAndNotForOtherFrames) {
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  EXPECT_EQ(*client.Exchange(wire::kNullTelemetryFrame), wire::kManualFrame);
  EXPECT_EQ(*client.Exchange("42[\"telemetry\",{\"x\":"), wire::kManualFrame);
  EXPECT_EQ(*client.Exchange(testing::FrameWithRows(100)), wire::kManualFrame);
  EXPECT_EQ(server.planners_made, 0);
  EXPECT_TRUE(IsControlFor(client.Exchange(TelemetryFrameAt(4, 5)), 4, 5, 1));
  EXPECT_TRUE(IsControlFor(client.Exchange(TelemetryFrameAt(4, 5)), 4, 5, 2));
  EXPECT_EQ(server.planners_made, 1);
  const ServerStats stats = server.server().stats();
  EXPECT_EQ(stats.planners_built, 1);
  EXPECT_EQ(stats.refused_frames, 1);
  EXPECT_EQ(stats.malformed_frames, 1);
}

// Clients that send telemetry as fast as the socket takes it and never read a reply: their
// replies stop being written once their buffers are full, so the server stops reading them and
// closes them after write_timeout; a well-behaved client meanwhile gets every reply right.
TEST(AbuseTest, ClientsThatNeverReadDoNotHoldUpOthersAndAreClosed) {
  ServerOptions options;
  options.max_connections = 8;
  options.write_timeout = 0.5;
  TestServer server(options);
  std::vector<RawSocket> flooders;
  const std::string frame = ClientText(TelemetryFrameAt(1, 1));
  for (int i = 0; i + 1 < options.max_connections; ++i) {
    flooders.push_back(ConnectUpgraded(server.port()));
    ASSERT_TRUE(flooders.back().ok());
    ASSERT_TRUE(flooders.back().SetNonBlocking());
  }
  std::atomic<bool> done{false};
  std::thread flood([&] {
    // Until the test has seen them closed (bounded by a count of rounds).
    for (int round = 0; round < 200000 && !done; ++round) {
      for (RawSocket& f : flooders) f.WriteSome(frame);  // a partial frame just stays partial
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
  });
  EXPECT_EQ(WellBehavedRun(server.port(), 200, 500), 200);
  EXPECT_TRUE(Eventually(
      [&] { return server.server().stats().stalled_connections == options.max_connections - 1; },
      30.0))
      << server.server().stats().stalled_connections;
  done = true;
  flood.join();
  EXPECT_TRUE(Eventually([&] { return server.server().stats().open_connections == 0; }));
  EXPECT_EQ(WellBehavedRun(server.port(), 20, 600), 20);
}

TEST(AbuseTest, OversizedAndPathologicalFramesDoNotDisturbAWellBehavedClient) {
  TestServer server;  // 1 MiB frame limit
  constexpr std::size_t kMiB = 1 << 20;
  // Legal 1 MiB frames that must be refused cheaply: answered manual, the connection kept.
  const std::vector<std::string> refused = {
      testing::FrameWithRows(12000),  // ~1 MB of sensor_fusion rows
      testing::FrameWithPath(60000),  // ~1 MB of previous path
      testing::FrameWithJunk(std::string(kMiB - 300, ' ') + "1"),
      testing::FrameWithJunk("\"" + std::string(kMiB - 300, 'a') + "\""),
  };
  std::atomic<bool> done{false};
  std::atomic<int> manuals{0}, wrong{0};
  std::vector<std::thread> hostile;
  for (std::size_t i = 0; i < refused.size(); ++i) {
    ASSERT_LT(refused[i].size(), kMiB);
    hostile.emplace_back([&, i] {
      RawSocket s = ConnectUpgraded(server.port());
      const std::string frame = ClientText(refused[i]);
      for (int n = 0; n < 200 && !done; ++n) {
        if (!s.WriteAll(frame)) return;
        const auto reply = ReadRawFrame(s);
        if (reply.has_value() && reply->payload == wire::kManualFrame) {
          ++manuals;
        } else {
          ++wrong;
          return;
        }
      }
    });
  }
  EXPECT_EQ(WellBehavedRun(server.port(), 200, 700), 200);
  done = true;
  for (std::thread& t : hostile) t.join();
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(manuals, 0);
  EXPECT_EQ(server.server().stats().refused_frames, manuals.load());
  EXPECT_EQ(server.planners_made, 1) << "only the well-behaved client planned";

  // Over the frame limit, by its header alone: failed with 1009 at once, without the payload.
  for (const std::uint64_t announced : {std::uint64_t{kMiB + 1}, std::uint64_t{1} << 30}) {
    RawSocket s = ConnectUpgraded(server.port());
    ASSERT_TRUE(s.ok());
    std::string header = {static_cast<char>(0x81), static_cast<char>(0x80 | 127)};
    for (int i = 7; i >= 0; --i) header.push_back(static_cast<char>((announced >> (8 * i)) & 0xFF));
    header += std::string(4, '\x11');  // the mask key
    ASSERT_TRUE(s.WriteAll(header));
    const std::optional<RawFrame> close = ReadRawFrame(s);
    ASSERT_TRUE(close.has_value()) << announced;
    EXPECT_EQ(close->opcode, kOpClose);
    EXPECT_EQ(CloseCode(*close), 1009) << announced;
  }
  EXPECT_TRUE(Eventually([&] { return server.server().stats().oversize_frames == 2; }));
}

// RFC 6455 §7.4: codes from 5000 up are undefined and 1005, 1006, 1015, 0-999, 1004 and
// 1016-2999 may not be sent: such a close fails the connection with 1002. Defined codes are
// echoed.
TEST(AbuseTest, InvalidCloseCodesFailTheConnectionWith1002) {
  TestServer server;
  for (const int code : {5000, 65535, 1005, 1006, 1015, 999, 1004, 2999, 1000, 1001, 3000, 4999}) {
    RawSocket s = ConnectUpgraded(server.port());
    ASSERT_TRUE(s.ok()) << code;
    ASSERT_TRUE(s.WriteAll(EncodeCloseFrame(code, "bye", /*mask=*/true)));
    const std::optional<RawFrame> close = ReadRawFrame(s);
    ASSERT_TRUE(close.has_value()) << code;
    EXPECT_EQ(close->opcode, kOpClose) << code;
    const bool valid = code == 1000 || code == 1001 || code == 3000 || code == 4999;
    EXPECT_EQ(CloseCode(*close), valid ? code : 1002) << "close code " << code;
    std::string rest;
    EXPECT_FALSE(s.ReadExactly(1, &rest, 2.0)) << code << ": the server closes the connection";
  }
  EXPECT_EQ(server.server().stats().bad_close_codes, 2);
}

// Connections that come and go every way a client can leave; none is left open and none keeps
// a planner, and the server still answers.
TEST(AbuseTest, ChurnLeavesNothingBehind) {
  ServerOptions options;
  options.max_connections = 4;
  options.handshake_timeout = 0.5;
  TestServer server(options);
  int planned = 0;
  for (int i = 0; i < 120; ++i) {
    // A connection the client has dropped stays open until the server has read the drop: the
    // next one waits for a free place, as a reconnecting client would (else it is refused).
    ASSERT_TRUE(Eventually(
        [&] { return server.server().stats().open_connections < options.max_connections; }))
        << i;
    switch (i % 5) {
      case 0: {  // clean close after a few exchanges
        TestClient c;
        ASSERT_TRUE(c.Connect(server.port()));
        EXPECT_TRUE(IsControlFor(c.Exchange(TelemetryFrameAt(i, 0)), i, 0, 1));
        ++planned;
        c.Close();
        break;
      }
      case 1: {  // dropped with a telemetry in flight
        TestClient c;
        ASSERT_TRUE(c.Connect(server.port()));
        ASSERT_FALSE(c.Send(TelemetryFrameAt(i, 0)));
        c.Abort();
        ++planned;
        break;
      }
      case 2: {  // TCP only, no upgrade
        RawSocket s = RawSocket::Connect(server.port());
        ASSERT_TRUE(s.ok());
        break;
      }
      case 3: {  // half an upgrade request
        RawSocket s = RawSocket::Connect(server.port());
        ASSERT_TRUE(s.WriteAll("GET / HTTP/1.1\r\nHost: x\r\n"));
        break;
      }
      case 4: {  // upgraded, then dropped without a word
        RawSocket s = ConnectUpgraded(server.port());
        ASSERT_TRUE(s.ok());
        break;
      }
    }
  }
  EXPECT_TRUE(Eventually([&] { return server.server().stats().open_connections == 0; }));
  EXPECT_TRUE(Eventually([&] { return server.planners_made == planned; }));
  EXPECT_EQ(WellBehavedRun(server.port(), 20, 3), 20);
}

// Connections that come, plan once and go from several threads at once: each ends while its
// last work may still be finishing on a planning thread (a session must then not be destroyed
// there, under the I/O thread's feet). Every exchange is answered, the server stays up.
TEST(AbuseTest, ParallelChurnIsAnsweredAndLeavesNothingBehind) {
  ServerOptions options;
  options.max_connections = 8;
  TestServer server(options);
  constexpr int kThreads = 6, kCycles = 60;
  std::atomic<int> answered{0}, refused{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&, i] {
      const std::string close = EncodeCloseFrame(1000, "", /*mask=*/true);
      for (int k = 0; k < kCycles; ++k) {
        RawSocket s = ConnectUpgraded(server.port());
        if (!s.ok()) {
          ++refused;  // at the cap for a moment: fine
          continue;
        }
        s.WriteAll(ClientText(TelemetryFrameAt(100 * i + k, 1)));
        const auto reply = ReadRawFrame(s);
        if (reply.has_value() && IsControlFor(reply->payload, 100 * i + k, 1, 1)) ++answered;
        if (k % 2 == 0) s.WriteAll(close);  // half close cleanly, half just drop
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(answered + refused, kThreads * kCycles);
  EXPECT_GT(answered, kThreads * kCycles / 2);
  EXPECT_TRUE(Eventually([&] { return server.server().stats().open_connections == 0; }));
  EXPECT_EQ(WellBehavedRun(server.port(), 10, 1), 10);
}

// Resident memory of this process, bytes (/proc/self/statm).
double ResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

// The real search planner (several MB each) on the bundled track: 200 connections come, plan
// once and go, at most max_connections at a time. Their memory is given back: the resident set
// ends near where one connection's left it, not at the high-water mark of a full server.
TEST(AbuseTest, MemoryComesBackAfterChurnWithRealPlanners) {
  if (kUnderSanitizer) {
    GTEST_SKIP() << "the sanitizer's allocator keeps freed memory (its quarantine): RSS is not "
                    "the server's";
  }
  auto track = map::LoadTrack(map::DefaultTrackPath());
  ASSERT_TRUE(track.ok()) << track.message();
  auto line = map::ReferenceLine::Fit(*track);
  ASSERT_TRUE(line.ok()) << line.message();
  auto config = plan::PlannerConfig::LoadDefault();
  ASSERT_TRUE(config.ok()) << config.message();
  auto shared_config = std::make_shared<const plan::PlannerConfig>(*config);
  std::shared_ptr<const map::ReferenceLine> shared_line = *line;
  ServerOptions options;
  options.max_connections = 8;
  TestServer server(options, [shared_config, shared_line]() -> std::unique_ptr<plan::Planner> {
    auto p = plan::MakePlanner("search", *shared_config, shared_line);
    return p.ok() ? std::move(p).value() : nullptr;
  });
  const auto plan_once = [&](TestClient& c) {
    ASSERT_TRUE(c.Connect(server.port()));
    const auto reply = c.Exchange(testing::FirstTelemetryFrame());
    ASSERT_TRUE(reply.has_value());
  };
  {
    TestClient warm;
    plan_once(warm);
    warm.Close();
  }
  ASSERT_TRUE(Eventually([&] { return server.server().stats().open_connections == 0; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the trim after a close
  const double baseline = ResidentBytes();
  double peak = baseline;
  for (int round = 0; round < 25; ++round) {
    std::vector<std::unique_ptr<TestClient>> full;
    for (int i = 0; i < options.max_connections; ++i) {
      full.push_back(std::make_unique<TestClient>());
      plan_once(*full.back());
    }
    peak = std::max(peak, ResidentBytes());
    for (auto& c : full) c->Close();
  }
  EXPECT_EQ(server.server().stats().planners_built, 1 + 25 * options.max_connections);
  ASSERT_TRUE(Eventually([&] { return server.server().stats().open_connections == 0; }));
  const double kMB = 1e6;
  // Planners were alive 8 at a time: the peak shows they are large (else this proves nothing).
  EXPECT_GT(peak - baseline, 20 * kMB) << "peak " << peak / kMB << " MB";
  EXPECT_TRUE(Eventually([&] { return ResidentBytes() < baseline + 10 * kMB; }))
      << "baseline " << baseline / kMB << " MB, peak " << peak / kMB << " MB, now "
      << ResidentBytes() / kMB << " MB";
}

}  // namespace
}  // namespace frenetic::net

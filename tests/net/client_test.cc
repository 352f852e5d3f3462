#include "frenetic/net/client.h"

#include <gtest/gtest.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "frenetic/net/protocol.h"
#include "net/net_test_util.h"

namespace frenetic::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using testing::TestServer;

// A toy simulator: the ego jumps to the second point of each control; every third frame is a
// null telemetry (no tick elapsed), as the real simulator sends when it outruns physics. Done
// after `exchanges` replies.
class ToyEndpoint : public SimulatorEndpoint {
 public:
  explicit ToyEndpoint(int exchanges) : exchanges_(exchanges) {
    t_.x = 100;
    t_.y = 200;
  }

  std::string OnOpen() override { return Next(); }
  std::string OnControl(std::span<const double> x, std::span<const double> y) override {
    EXPECT_EQ(x.size(), y.size());
    ++replies_;
    controls_seen.push_back(x.empty() ? -1 : x[0]);
    if (x.size() >= 2) {
      t_.x = x[1];
      t_.y = y[1];
    }
    return Next();
  }
  std::string OnManual() override {
    ++replies_;
    ++manuals_seen;
    return Next();
  }
  bool Done() const override { return replies_ >= exchanges_; }
  double SimSeconds() const override { return 0.02 * frames_; }

  std::vector<double> controls_seen;
  int manuals_seen = 0;

 private:
  std::string Next() {
    ++frames_;
    if (frames_ % 3 == 0) return std::string(kNullTelemetryFrame);
    return FormatTelemetryFrame(t_);
  }
  plan::Telemetry t_;
  int exchanges_;
  int replies_ = 0;
  int frames_ = 0;
};

std::string UrlFor(int port) {
  return "ws://127.0.0.1:" + std::to_string(port) + "/socket.io/?EIO=4&transport=websocket";
}

TEST(ClientTest, DrivesAServerUntilDone) {
  TestServer server;
  ToyEndpoint endpoint(30);
  ClientStats stats;
  const Status s = RunClient(UrlFor(server.port()), endpoint, ClientOptions(), &stats);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(stats.frames_sent, 30);
  EXPECT_EQ(stats.manuals, 10);  // every third frame was null telemetry
  EXPECT_EQ(stats.controls, 20);
  EXPECT_EQ(stats.protocol_errors, 0);
  EXPECT_EQ(endpoint.manuals_seen, 10);
  ASSERT_EQ(endpoint.controls_seen.size(), 20u);
  // The fake planner's path starts at the ego, which moved 1 m per control.
  for (std::size_t i = 0; i < endpoint.controls_seen.size(); ++i) {
    EXPECT_NEAR(endpoint.controls_seen[i], 100.0 + static_cast<double>(i), 1e-3) << i;
  }
  const ServerStats server_stats = server.server().stats();
  EXPECT_EQ(server_stats.pings, 1);  // the engine.io ping right after connecting
  EXPECT_EQ(server_stats.cycles, 20);
  EXPECT_EQ(server_stats.null_telemetry, 10);
}

TEST(ClientTest, RealtimePacingStillFinishes) {
  TestServer server;
  ToyEndpoint endpoint(5);  // 0.1 s of simulated time
  ClientOptions options;
  options.realtime = true;
  ClientStats stats;
  ASSERT_TRUE(RunClient(UrlFor(server.port()), endpoint, options, &stats).ok());
  EXPECT_EQ(stats.frames_sent, 5);
}

TEST(ClientTest, BadUrlsAreRejected) {
  ToyEndpoint endpoint(1);
  for (const char* url : {"http://127.0.0.1:4567/", "ws://", "ws://127.0.0.1:notaport/",
                          "ws://127.0.0.1:99999/", "127.0.0.1:4567"}) {
    const Status s = RunClient(url, endpoint, ClientOptions());
    ASSERT_FALSE(s.ok()) << url;
    EXPECT_NE(s.message().find("url"), std::string::npos) << s.message();
  }
}

TEST(ClientTest, ConnectionRefusedIsAnError) {
  int port = 0;
  {
    TestServer server;  // take a free port, then release it
    port = server.port();
  }
  ToyEndpoint endpoint(1);
  const Status s = RunClient(UrlFor(port), endpoint, ClientOptions());
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("connect"), std::string::npos) << s.message();
}

// A scripted server: answers each frame but the ping with the next scripted reply ("" = no
// answer; kSep separates several frames sent in a row); serves one connection.
constexpr char kSep = '\x1f';

class ScriptedServer {
 public:
  explicit ScriptedServer(std::vector<std::string> replies)
      : acceptor_(io_, {asio::ip::make_address("127.0.0.1"), 0}), replies_(std::move(replies)) {
    port_ = acceptor_.local_endpoint().port();
    thread_ = std::thread([this] { Serve(); });
  }
  // The serving thread ends when the client disconnects (every client run closes or drops its
  // connection); a client that never connected is stood in for, to release accept().
  ~ScriptedServer() {
    if (!accepted_) {
      asio::io_context io;
      asio::ip::tcp::socket poke(io);
      beast::error_code ec;
      poke.connect({asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port_)}, ec);
    }
    thread_.join();
  }
  int port() const { return port_; }

 private:
  void Serve() {
    beast::error_code ec;
    asio::ip::tcp::socket socket(io_);
    acceptor_.accept(socket, ec);
    accepted_ = true;
    if (ec) return;
    websocket::stream<beast::tcp_stream> ws(std::move(socket));
    ws.accept(ec);
    std::size_t next = 0;
    while (!ec) {
      beast::flat_buffer buffer;
      ws.read(buffer, ec);
      if (ec) break;
      if (beast::buffers_to_string(buffer.data()) == "2") continue;
      if (next >= replies_.size() || replies_[next].empty()) {
        ++next;
        continue;  // silence: the client must time out
      }
      std::string_view rest = replies_[next++];
      while (!ec) {
        const std::size_t cut = rest.find(kSep);
        ws.write(asio::buffer(rest.substr(0, cut)), ec);
        if (cut == std::string_view::npos) break;
        rest.remove_prefix(cut + 1);
      }
    }
  }

  asio::io_context io_;
  asio::ip::tcp::acceptor acceptor_;
  std::vector<std::string> replies_;
  std::atomic<bool> accepted_{false};
  std::thread thread_;
  int port_ = 0;
};

const char* kGoodControl = R"(42["control",{"next_x":[1,2],"next_y":[3,4]}])";
const char* kUnequalControl = R"(42["control",{"next_x":[1,2,3],"next_y":[3,4]}])";
const char* kNullInControl = R"(42["control",{"next_x":[1,null],"next_y":[3,4]}])";

TEST(ClientTest, MalformedControlStopsTheRunLikeTheSimulatorStalls) {
  ScriptedServer server({kGoodControl, kUnequalControl, kGoodControl});
  ToyEndpoint endpoint(100);
  ClientStats stats;
  const Status s = RunClient(UrlFor(server.port()), endpoint, ClientOptions(), &stats);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("next_x has 3 points, next_y 2"), std::string::npos) << s.message();
  EXPECT_EQ(stats.protocol_errors, 1);
  EXPECT_EQ(stats.controls, 1);
  EXPECT_EQ(stats.frames_sent, 2);
}

TEST(ClientTest, MalformedControlIsCountedWhenContinuing) {
  ScriptedServer server({kGoodControl, kUnequalControl, kNullInControl, "42[oops", kGoodControl});
  ToyEndpoint endpoint(5);
  ClientOptions options;
  options.continue_on_protocol_error = true;
  ClientStats stats;
  const Status s = RunClient(UrlFor(server.port()), endpoint, options, &stats);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(stats.protocol_errors, 3);
  EXPECT_EQ(stats.controls, 2);
  EXPECT_NE(stats.first_protocol_error.find("reply to frame 2"), std::string::npos)
      << stats.first_protocol_error;
}

TEST(ClientTest, PongsAndUnknownFramesAreSkipped) {
  // Before the control: a pong, an engine.io open packet and a binary-looking text frame.
  ScriptedServer server({std::string("3") + kSep + R"(0{"sid":"x"})" + kSep + kGoodControl});
  ToyEndpoint endpoint(1);
  ClientStats stats;
  const Status s = RunClient(UrlFor(server.port()), endpoint, ClientOptions(), &stats);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(stats.ignored_frames, 2);
  EXPECT_EQ(stats.controls, 1);
}

TEST(ClientTest, SilentServerTimesOut) {
  ScriptedServer server({""});
  ToyEndpoint endpoint(3);
  ClientOptions options;
  options.timeout = 0.3;
  const Status s = RunClient(UrlFor(server.port()), endpoint, options);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no reply within the timeout"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace frenetic::net

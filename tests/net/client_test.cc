#include "frenetic/net/client.h"

#include <gtest/gtest.h>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <string>
#include <thread>
#include <vector>

#include "frenetic/wire/protocol.h"
#include "net/net_test_util.h"
#include "net/raw_websocket.h"

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
    if (frames_ % 3 == 0) return std::string(wire::kNullTelemetryFrame);
    return wire::FormatTelemetryFrame(t_);
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

// A hostile server written with raw sockets: upgrades, reads the ping and the first telemetry,
// then sends `bytes` and leaves the connection open (no TCP close) until the client is done;
// with `replies`, reads and answers up to that many more frames first, each with `reply`.
// Returns the client's status; *echo gets the next frame the client sent (if any).
Status RunAgainstRawServer(const std::string& bytes, std::optional<testing::RawFrame>* echo,
                           ClientStats* stats, ToyEndpoint* endpoint, ClientOptions options = {},
                           int replies = 0, const std::string& reply = "") {
  testing::RawListener listener;
  EXPECT_GT(listener.port(), 0);
  options.timeout = 5.0;  // far beyond what acting "at once" takes: the messages tell them apart
  Status status;
  std::thread client(
      [&] { status = RunClient(UrlFor(listener.port()), *endpoint, options, stats); });
  testing::RawSocket s = listener.Accept();
  std::string request;
  if (s.ok() && testing::AcceptUpgradeByHand(s, &request)) {
    const auto ping = testing::ReadRawFrame(s);
    const auto telemetry = testing::ReadRawFrame(s);
    EXPECT_TRUE(ping.has_value() && telemetry.has_value());
    s.WriteAll(bytes);
    for (int i = 0; i < replies; ++i) {
      const auto frame = testing::ReadRawFrame(s);
      if (!frame.has_value() || frame->opcode != testing::kOpText) {
        *echo = frame;
        break;
      }
      s.WriteAll(testing::EncodeRawFrame(testing::kOpText, reply, /*mask=*/false));
    }
    if (!echo->has_value()) *echo = testing::ReadRawFrame(s, 5.0);
  }
  client.join();  // the socket stays open until the client has given up
  return status;
}

std::string TextFrame(std::string_view payload) {
  return testing::EncodeRawFrame(testing::kOpText, payload, /*mask=*/false);
}

TEST(ClientTest, ASecondReplyToOneFrameIsAProtocolError) {
  // Two controls for the first telemetry, in one write: both are there when frame 2 is due.
  std::optional<testing::RawFrame> echo;
  ClientStats stats;
  ToyEndpoint endpoint(10);
  const Status s = RunAgainstRawServer(TextFrame(kGoodControl) + TextFrame(kGoodControl), &echo,
                                       &stats, &endpoint);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("a second reply to frame 1 arrived before frame 2 was sent"),
            std::string::npos)
      << s.message();
  EXPECT_EQ(stats.frames_sent, 1);
  EXPECT_EQ(stats.controls, 1);
  EXPECT_EQ(stats.protocol_errors, 1);
  ASSERT_TRUE(echo.has_value());
  EXPECT_EQ(echo->opcode, testing::kOpClose) << "frame 2 must not have been sent";
}

TEST(ClientTest, ASecondReplyIsDroppedAndCountedWhenContinuing) {
  std::optional<testing::RawFrame> echo;
  ClientStats stats;
  ToyEndpoint endpoint(3);
  ClientOptions options;
  options.continue_on_protocol_error = true;
  const Status s =
      RunAgainstRawServer(TextFrame(kGoodControl) + TextFrame(wire::kManualFrame), &echo, &stats,
                          &endpoint, options, /*replies=*/2, kGoodControl);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(stats.protocol_errors, 1);
  EXPECT_EQ(stats.frames_sent, 3);
  // Frames 2 and 3 were answered with controls: the extra manual was not taken for either.
  EXPECT_EQ(stats.controls, 3);
  EXPECT_EQ(stats.manuals, 0);
  EXPECT_EQ(endpoint.manuals_seen, 0);
  EXPECT_NE(stats.first_protocol_error.find("second reply to frame 1"), std::string::npos)
      << stats.first_protocol_error;
}

TEST(ClientTest, ACloseFrameEndsTheRunAtOnceWithItsCodeAndReason) {
  std::optional<testing::RawFrame> echo;
  ClientStats stats;
  ToyEndpoint endpoint(10);
  const Status s =
      RunAgainstRawServer(testing::EncodeCloseFrame(1001, "planner going away", /*mask=*/false),
                          &echo, &stats, &endpoint);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message().find("timeout"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("waiting for the reply to frame 1"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("closed the connection with code 1001 (\"planner going away\")"),
            std::string::npos)
      << s.message();
  ASSERT_TRUE(echo.has_value()) << "the client answers the close frame";
  EXPECT_EQ(echo->opcode, testing::kOpClose);
  ASSERT_GE(echo->payload.size(), 2u);
  EXPECT_EQ(testing::CloseCode(*echo), 1001);
}

TEST(ClientTest, AnOversizedFrameHeaderEndsTheRunAtOnce) {
  // A text frame announcing 1 GiB, and nothing after the header.
  std::string header = {static_cast<char>(0x81), 127};
  for (int i = 7; i >= 0; --i)
    header.push_back(static_cast<char>(((1ull << 30) >> (8 * i)) & 0xFF));
  std::optional<testing::RawFrame> echo;
  ClientStats stats;
  ToyEndpoint endpoint(10);
  const Status s = RunAgainstRawServer(header, &echo, &stats, &endpoint);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message().find("timeout"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("a frame over the client's limit of 16777216 bytes"),
            std::string::npos)
      << s.message();
  ASSERT_TRUE(echo.has_value()) << "the client fails the connection with a close frame";
  EXPECT_EQ(echo->opcode, testing::kOpClose);
  ASSERT_GE(echo->payload.size(), 2u);
  EXPECT_EQ(testing::CloseCode(*echo), 1009);
}

}  // namespace
}  // namespace frenetic::net

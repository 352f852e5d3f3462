// How messages go on the wire, read as raw bytes: the Unity simulator sends every message as one
// unfragmented, masked text frame, and at least one public planner built on the Udacity template
// misbehaves on continuation frames. Both of our ends must do the same (one frame per message,
// FIN set, text opcode, masked from the client only), also for messages far larger than Beast's
// 4096-byte write buffer, and both set TCP_NODELAY on their sockets.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <thread>

#include "frenetic/net/client.h"
#include "frenetic/wire/protocol.h"
#include "net/net_test_util.h"
#include "net/raw_websocket.h"

namespace frenetic::net {
namespace {

using testing::EncodeRawFrame;
using testing::FakePlanner;
using testing::kOpClose;
using testing::kOpText;
using testing::RawFrame;
using testing::RawListener;
using testing::RawSocket;
using testing::ReadRawFrame;
using testing::TestServer;

// A busy scene: a long previous path and many cars, so each telemetry frame is well over 4096
// bytes (the last of the client test's frames over the client's 64 KiB write buffer too). Frame
// i has the ego at x = 1000 + i.
constexpr int kPathPoints = 400, kHugePathPoints = 5000;
plan::Telemetry BigTelemetry(int i, int points = kPathPoints) {
  plan::Telemetry t;
  t.x = 1000 + i;
  t.y = 1128.67;
  t.speed = 21.9;
  t.s = 1234.567;
  t.d = 6.1;
  for (int k = 0; k < points; ++k) {
    t.previous_path_x.push_back(t.x + 0.4371 * k);
    t.previous_path_y.push_back(t.y + 0.0123 * k * k);
  }
  for (int id = 0; id < 40; ++id) {
    t.sensor_fusion.push_back({id, 900.123 + id, 1130.456 - id, 20.4567, 1.2345,
                               1200.98765 + 7 * id, 2.0 + 4 * (id % 3)});
  }
  return t;
}

// Sends BigTelemetry(0), BigTelemetry(1), ... (the last one with kHugePathPoints) and is done
// after `frames` replies.
class BigTelemetryEndpoint : public SimulatorEndpoint {
 public:
  explicit BigTelemetryEndpoint(int frames) : frames_(frames) {}
  std::string OnOpen() override { return Next(); }
  std::string OnControl(std::span<const double>, std::span<const double>) override {
    ++replies_;
    return Next();
  }
  std::string OnManual() override { return OnControl({}, {}); }
  bool Done() const override { return replies_ >= frames_; }

 private:
  std::string Next() {
    const int i = sent_++;
    return wire::FormatTelemetryFrame(
        BigTelemetry(i, i + 1 == frames_ ? kHugePathPoints : kPathPoints));
  }

  int frames_, sent_ = 0, replies_ = 0;
};

void ExpectOneTextFrame(const RawFrame& f, bool masked) {
  EXPECT_TRUE(f.fin) << "FIN not set: the message was fragmented";
  EXPECT_EQ(f.opcode, kOpText) << "opcode " << f.opcode << " (0 = a continuation frame)";
  EXPECT_EQ(f.masked, masked);
}

TEST(FramingTest, ClientSendsEachMessageAsOneMaskedTextFrame) {
  constexpr int kFrames = 5;
  RawListener listener;
  ASSERT_GT(listener.port(), 0);
  BigTelemetryEndpoint endpoint(kFrames);
  ClientOptions options;
  options.timeout = 5.0;
  ClientStats stats;
  Status status;
  std::thread client([&] {
    status = RunClient("ws://127.0.0.1:" + std::to_string(listener.port()) +
                           "/socket.io/?EIO=4&transport=websocket",
                       endpoint, options, &stats);
  });
  {
    RawSocket s = listener.Accept();
    ASSERT_TRUE(s.ok()) << "the client did not connect";
    std::string request;
    ASSERT_TRUE(testing::AcceptUpgradeByHand(s, &request)) << request;
    EXPECT_EQ(request.rfind("GET /socket.io/?EIO=4&transport=websocket HTTP/1.1\r\n", 0), 0u)
        << request;

    // The engine.io ping, then the telemetry frames, each answered with a control.
    std::optional<RawFrame> ping = ReadRawFrame(s);
    ASSERT_TRUE(ping.has_value());
    ExpectOneTextFrame(*ping, /*masked=*/true);
    EXPECT_EQ(ping->payload, wire::kPingFrame);
    std::string control;
    const std::vector<double> xs(50, 1.0), ys(50, 2.0);
    wire::FormatControl(xs, ys, &control);
    for (int i = 0; i < kFrames; ++i) {
      std::optional<RawFrame> f = ReadRawFrame(s);
      ASSERT_TRUE(f.has_value()) << "no frame " << i;
      ExpectOneTextFrame(*f, /*masked=*/true);
      EXPECT_GT(f->payload.size(), i + 1 == kFrames ? 64u << 10 : 4096u * 2);
      // The whole message is in this one frame: it parses, and it is the i-th telemetry (the
      // last one beyond the server's default limits).
      wire::FrameLimits limits;
      limits.max_path_points = kHugePathPoints;
      const wire::ParsedFrame parsed = wire::ParseFrame(f->payload, limits);
      ASSERT_EQ(parsed.kind, wire::FrameKind::kTelemetry) << i << ": " << parsed.error;
      EXPECT_TRUE(parsed.error.empty()) << parsed.error;
      EXPECT_EQ(parsed.telemetry.x, 1000.0 + i);
      EXPECT_EQ(parsed.telemetry.previous_path_x.size(),
                static_cast<std::size_t>(i + 1 == kFrames ? kHugePathPoints : kPathPoints));
      EXPECT_EQ(parsed.telemetry.sensor_fusion.size(), 40u);
      ASSERT_TRUE(s.WriteAll(EncodeRawFrame(kOpText, control, /*mask=*/false)));
    }
    // Done: the client closes the WebSocket cleanly.
    std::optional<RawFrame> close = ReadRawFrame(s);
    ASSERT_TRUE(close.has_value());
    EXPECT_EQ(close->opcode, kOpClose);
    s.WriteAll(EncodeRawFrame(kOpClose, close->payload, /*mask=*/false));
  }  // closing the socket releases the client whatever happened above
  client.join();
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(stats.frames_sent, kFrames);
  EXPECT_EQ(stats.controls, kFrames);
  EXPECT_TRUE(stats.tcp_nodelay) << "TCP_NODELAY is not set on the client's socket";
}

TEST(FramingTest, ServerSendsEachReplyAsOneUnmaskedTextFrame) {
  TestServer server({}, FakePlanner::Mode::kLong);
  RawSocket s = RawSocket::Connect(server.port());
  ASSERT_TRUE(s.ok());
  std::string response;
  ASSERT_TRUE(testing::UpgradeByHand(s, server.port(), &response)) << response;
  EXPECT_EQ(response.rfind("HTTP/1.1 101", 0), 0u) << response;
  EXPECT_NE(response.find(testing::kSampleAccept), std::string::npos) << response;

  for (int i = 0; i < 3; ++i) {
    const std::string frame = wire::FormatTelemetryFrame(BigTelemetry(i));
    ASSERT_TRUE(s.WriteAll(EncodeRawFrame(kOpText, frame, /*mask=*/true)));
    std::optional<RawFrame> f = ReadRawFrame(s);
    ASSERT_TRUE(f.has_value()) << "no reply " << i;
    ExpectOneTextFrame(*f, /*masked=*/false);
    EXPECT_GT(f->payload.size(), 4096u * 2);
    wire::ParsedReply reply;
    wire::ParseReply(f->payload, &reply);
    ASSERT_EQ(reply.kind, wire::ReplyKind::kControl) << reply.error;
    EXPECT_EQ(reply.x.size(), static_cast<std::size_t>(FakePlanner::kLongPoints));
    EXPECT_NEAR(reply.x[0], 1000.0 + i, 1e-6);
  }
  // A small reply too (null telemetry gets manual).
  ASSERT_TRUE(s.WriteAll(EncodeRawFrame(kOpText, wire::kNullTelemetryFrame, /*mask=*/true)));
  std::optional<RawFrame> manual = ReadRawFrame(s);
  ASSERT_TRUE(manual.has_value());
  ExpectOneTextFrame(*manual, /*masked=*/false);
  EXPECT_EQ(manual->payload, wire::kManualFrame);

  const ServerStats stats = server.server().stats();
  EXPECT_EQ(stats.connections, 1);
  EXPECT_EQ(stats.nodelay_connections, 1) << "TCP_NODELAY is not set on the server's socket";
}

}  // namespace
}  // namespace frenetic::net

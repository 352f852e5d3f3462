#include "frenetic/net/server.h"

#include <gtest/gtest.h>

#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "frenetic/wire/protocol.h"
#include "net/net_test_util.h"

namespace frenetic::net {
namespace {

using nlohmann::json;
using testing::FakePlanner;
using testing::FirstTelemetryFrame;
using testing::TelemetryFrameAt;
using testing::TestClient;
using testing::TestServer;

// Checks that `reply` is the fake planner's control for an ego at (x, y) on its `cycle`-th call.
void ExpectControlFor(const std::optional<std::string>& reply, double x, double y, int cycle) {
  ASSERT_TRUE(reply.has_value()) << "no reply";
  wire::ParsedReply r;
  wire::ParseReply(*reply, &r);
  ASSERT_EQ(r.kind, wire::ReplyKind::kControl) << *reply << " " << r.error;
  ASSERT_EQ(r.x.size(), static_cast<std::size_t>(plan::kMinPathPoints));
  EXPECT_NEAR(r.x[0], x, 1e-6);
  EXPECT_NEAR(r.x[49], x + 49, 1e-6);
  EXPECT_NEAR(r.y[0], y + cycle, 1e-6);
}

void ExpectManual(const std::optional<std::string>& reply) {
  ASSERT_TRUE(reply.has_value()) << "no reply";
  EXPECT_EQ(*reply, wire::kManualFrame);
}

TEST(ServerTest, AnswersTheRealFirstMessageWithControl) {
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  ExpectControlFor(client.Exchange(FirstTelemetryFrame()), 909.48, 1128.67, 1);
  ExpectControlFor(client.Exchange(TelemetryFrameAt(100, 200)), 100, 200, 2);
  client.Close();
  EXPECT_EQ(server.planners_made, 1);
  EXPECT_EQ(server.server().stats().cycles, 2);
}

TEST(ServerTest, StatusLineReportsCyclesSpeedLaneAndIncidents) {
  TestServer server({}, FakePlanner::Mode::kShort);
  EXPECT_NE(server.server().StatusLine().find("no telemetry yet"), std::string::npos);
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  // speed 10 mph = 4.47 m/s, d 6 = lane 1 (middle).
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(client.Exchange(TelemetryFrameAt(1, 2)).has_value());
  ASSERT_TRUE(client.Exchange("42[").has_value());
  const std::string line = server.server().StatusLine();
  EXPECT_NE(line.find("1 open connections, 3 cycles (+3)"), std::string::npos) << line;
  EXPECT_NE(line.find("speed 4.5 m/s (10.0 mph), lane 1"), std::string::npos) << line;
  EXPECT_NE(line.find("short paths 3"), std::string::npos) << line;
  EXPECT_NE(line.find("malformed 1"), std::string::npos) << line;
  EXPECT_NE(line.find("p50"), std::string::npos) << line;
  const std::string next = server.server().StatusLine();
  EXPECT_NE(next.find("3 cycles (+0)"), std::string::npos) << next;
}

TEST(ServerTest, AcceptsTheUpgradeOnAnyPath) {
  TestServer server;
  for (const char* target : {"/", "/socket.io/?EIO=4&transport=websocket", "/anything/else"}) {
    TestClient client;
    ASSERT_TRUE(client.Connect(server.port(), target)) << target;
    ExpectControlFor(client.Exchange(TelemetryFrameAt(1, 2)), 1, 2, 1);
  }
}

TEST(ServerTest, NullTelemetryAndOtherEventsGetManual) {
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  ExpectManual(client.Exchange(wire::kNullTelemetryFrame));
  ExpectManual(client.Exchange(R"(42["hello",{}])"));
  ExpectControlFor(client.Exchange(TelemetryFrameAt(5, 6)), 5, 6, 1);
  const ServerStats stats = server.server().stats();
  EXPECT_EQ(stats.null_telemetry, 1);
  EXPECT_EQ(stats.other_events, 1);
  EXPECT_EQ(stats.manual_replies, 2);
}

TEST(ServerTest, PingIsIgnoredByDefault) {
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  ASSERT_FALSE(client.Send(wire::kPingFrame));
  ASSERT_FALSE(client.Send("3"));
  // The first reply must be the one to the telemetry: nothing was sent for the ping.
  ExpectControlFor(client.Exchange(TelemetryFrameAt(5, 6)), 5, 6, 1);
  EXPECT_EQ(server.server().stats().pings, 1);
}

TEST(ServerTest, PingIsAnsweredWhenConfigured) {
  ServerOptions options;
  options.answer_ping = true;
  TestServer server(options);
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  const auto pong = client.Exchange(wire::kPingFrame);
  ASSERT_TRUE(pong.has_value());
  EXPECT_EQ(*pong, wire::kPongFrame);
}

// Each hostile 42 frame is answered with manual (or a repaired control), and the same
// connection then gets a correct control for valid telemetry.
struct HostileServerCase {
  const char* name;
  std::string frame;
  bool expect_control;  // repaired telemetry is still planned
};

class ServerHostileTest : public ::testing::TestWithParam<HostileServerCase> {};

TEST_P(ServerHostileTest, IsAnsweredAndTheNextTelemetryStillWorks) {
  const HostileServerCase& c = GetParam();
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  const auto reply = client.Exchange(c.frame);
  ASSERT_TRUE(reply.has_value());
  int cycles = 0;
  if (c.expect_control) {
    wire::ParsedReply r;
    wire::ParseReply(*reply, &r);
    EXPECT_EQ(r.kind, wire::ReplyKind::kControl) << *reply;
    ++cycles;
  } else {
    EXPECT_EQ(*reply, wire::kManualFrame);
  }
  ExpectControlFor(client.Exchange(TelemetryFrameAt(7, 8)), 7, 8, cycles + 1);
  client.Close();
}

std::string Payload(const std::string& body) { return "42[\"telemetry\",{" + body + "}]"; }
const std::string kGoodRest =
    R"("previous_path_x":[],"previous_path_y":[],"end_path_s":0,"end_path_d":0,"sensor_fusion":[])";

INSTANTIATE_TEST_SUITE_P(
    Cases, ServerHostileTest,
    ::testing::Values(
        HostileServerCase{"MalformedJson", R"(42["telemetry",{"x":)", false},
        HostileServerCase{"NotJsonAtAll", "42 this is not json", false},
        HostileServerCase{"MissingField",
                          Payload(R"("x":1,"y":2,"yaw":0,"speed":0,"s":0,)" + kGoodRest), false},
        HostileServerCase{"WrongType",
                          Payload(R"("x":"1","y":2,"yaw":0,"speed":0,"s":0,"d":0,)" + kGoodRest),
                          false},
        HostileServerCase{"NaNString",
                          Payload(R"("x":1,"y":2,"yaw":"NaN","speed":0,"s":0,"d":0,)" + kGoodRest),
                          false},
        HostileServerCase{"Infinity",
                          Payload(R"("x":1,"y":2,"yaw":0,"speed":1e999,"s":0,"d":0,)" + kGoodRest),
                          false},
        HostileServerCase{"UnequalArrays",
                          Payload(R"("x":1,"y":2,"yaw":0,"speed":0,"s":0,"d":0,)"
                                  R"("previous_path_x":[1,2,3],"previous_path_y":[1],)"
                                  R"("end_path_s":0,"end_path_d":0,"sensor_fusion":[])"),
                          true},
        HostileServerCase{"BadSensorRow",
                          Payload(R"("x":1,"y":2,"yaw":0,"speed":0,"s":0,"d":0,)"
                                  R"("previous_path_x":[],"previous_path_y":[],)"
                                  R"("end_path_s":0,"end_path_d":0,"sensor_fusion":[[1,2],null])"),
                          true},
        HostileServerCase{"DeepNesting", "42" + std::string(50000, '['), false},
        HostileServerCase{"EmptyFortyTwo", "42", false}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(ServerTest, RepairedTelemetryReachesThePlannerCut) {
  // The fake planner echoes the ego position; the repaired frame must still carry it.
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  const std::string frame = Payload(
      R"("x":11,"y":22,"yaw":0,"speed":0,"s":0,"d":0,"previous_path_x":[1,2,3],)"
      R"("previous_path_y":[1],"end_path_s":0,"end_path_d":0,"sensor_fusion":[[1,2],[3,1,2,3,4,5,6]])");
  ExpectControlFor(client.Exchange(frame), 11, 22, 1);
  EXPECT_EQ(server.server().stats().repaired_frames, 1);
}

TEST(ServerTest, OversizeFrameClosesOnlyThatConnection) {
  ServerOptions options;
  options.max_frame_bytes = 4096;
  TestServer server(options);
  TestClient big;
  ASSERT_TRUE(big.Connect(server.port()));
  const std::string huge = "42[\"telemetry\",\"" + std::string(10000, 'a') + "\"]";
  big.Send(huge);
  EXPECT_FALSE(big.Receive().has_value()) << "the connection must be closed";
  TestClient next;
  ASSERT_TRUE(next.Connect(server.port()));
  ExpectControlFor(next.Exchange(TelemetryFrameAt(3, 4)), 3, 4, 1);
  EXPECT_EQ(server.server().stats().oversize_frames, 1);
}

TEST(ServerTest, BinaryFramesAreIgnored) {
  TestServer server;
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  ASSERT_FALSE(client.Send(FirstTelemetryFrame(), /*binary=*/true));
  ExpectControlFor(client.Exchange(TelemetryFrameAt(3, 4)), 3, 4, 1);
  EXPECT_EQ(server.server().stats().binary_frames, 1);
}

TEST(ServerTest, SurvivesAbruptDisconnects) {
  TestServer server;
  {  // TCP connect and drop without an upgrade.
    namespace asio = boost::asio;
    asio::io_context io;
    asio::ip::tcp::socket s(io);
    s.connect({asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(server.port())});
    asio::write(s, asio::buffer(std::string("GET /socket.io/ HTTP/1.1\r\nHost: x\r\n")));
    s.close();
  }
  {  // Drop right after sending telemetry, before the reply is read.
    TestClient client;
    ASSERT_TRUE(client.Connect(server.port()));
    ASSERT_FALSE(client.Send(FirstTelemetryFrame()));
    client.Abort();
  }
  {  // Drop in the middle of an exchange sequence.
    TestClient client;
    ASSERT_TRUE(client.Connect(server.port()));
    ExpectControlFor(client.Exchange(TelemetryFrameAt(1, 1)), 1, 1, 1);
    client.Abort();
  }
  TestClient client;
  ASSERT_TRUE(client.Connect(server.port()));
  ExpectControlFor(client.Exchange(TelemetryFrameAt(9, 9)), 9, 9, 1);
}

TEST(ServerTest, ReconnectGetsAFreshPlanner) {
  TestServer server;
  for (int round = 0; round < 3; ++round) {
    TestClient client;
    ASSERT_TRUE(client.Connect(server.port()));
    ExpectControlFor(client.Exchange(TelemetryFrameAt(round, 0)), round, 0, 1);
    ExpectControlFor(client.Exchange(TelemetryFrameAt(round, 0)), round, 0, 2);
    client.Close();
  }
  EXPECT_EQ(server.planners_made, 3);
  EXPECT_EQ(server.server().stats().connections, 3);
}

TEST(ServerTest, SeveralClientsAtOnceEachHaveTheirOwnPlanner) {
  TestServer server;
  constexpr int kClients = 4;
  std::vector<std::unique_ptr<TestClient>> clients;
  for (int i = 0; i < kClients; ++i) {
    clients.push_back(std::make_unique<TestClient>());
    ASSERT_TRUE(clients.back()->Connect(server.port()));
  }
  // Interleave: all send, then all read, several rounds.
  for (int cycle = 1; cycle <= 5; ++cycle) {
    for (int i = 0; i < kClients; ++i) {
      ASSERT_FALSE(clients[i]->Send(TelemetryFrameAt(100 * i, cycle)));
    }
    for (int i = 0; i < kClients; ++i) {
      ExpectControlFor(clients[i]->Receive(), 100 * i, cycle, cycle);
    }
  }
  EXPECT_EQ(server.planners_made, kClients);
  EXPECT_EQ(server.server().stats().open_connections, kClients);
  EXPECT_EQ(server.server().stats().cycles, 5 * kClients);
}

TEST(ServerTest, BadPlansAreSentEqualAndFiniteAndCounted) {
  for (auto mode : {FakePlanner::Mode::kNaN, FakePlanner::Mode::kUnequal,
                    FakePlanner::Mode::kShort}) {
    TestServer server({}, mode);
    TestClient client;
    ASSERT_TRUE(client.Connect(server.port()));
    const auto reply = client.Exchange(TelemetryFrameAt(1, 2));
    ASSERT_TRUE(reply.has_value());
    wire::ParsedReply r;
    wire::ParseReply(*reply, &r);
    ASSERT_EQ(r.kind, wire::ReplyKind::kControl) << r.error;
    const std::size_t expected = mode == FakePlanner::Mode::kNaN ? 10 : mode == FakePlanner::Mode::kUnequal ? 20 : 3;
    EXPECT_EQ(r.x.size(), expected);
    const ServerStats stats = server.server().stats();
    EXPECT_EQ(stats.short_paths, 1);
    EXPECT_EQ(stats.bad_plans, mode == FakePlanner::Mode::kShort ? 0 : 1);
  }
}

TEST(ServerTest, AFailingFactoryAnswersManualAndClosesOnlyThatConnection) {
  TestServer server({}, FakePlanner::Mode::kGood, /*refuse=*/true);
  TestClient client(2.0);
  ASSERT_TRUE(client.Connect(server.port()));
  EXPECT_EQ(server.planners_made, 0) << "the planner is built at the first telemetry";
  ExpectManual(client.Exchange(TelemetryFrameAt(1, 2)));
  EXPECT_FALSE(client.Receive().has_value()) << "the connection must be closed";
  EXPECT_EQ(server.planners_made, 1);
  EXPECT_EQ(server.server().stats().refused_connections, 1);
  TestClient next(2.0);
  ASSERT_TRUE(next.Connect(server.port())) << "the server must still accept connections";
  ExpectManual(next.Exchange(wire::kNullTelemetryFrame));
}

TEST(ServerTest, StopClosesOpenConnections) {
  auto server = std::make_unique<TestServer>();
  TestClient client;
  ASSERT_TRUE(client.Connect(server->port()));
  ExpectControlFor(client.Exchange(TelemetryFrameAt(1, 2)), 1, 2, 1);
  server.reset();  // Stop() + join: must return although the client is still connected
  EXPECT_FALSE(client.Exchange(TelemetryFrameAt(1, 2)).has_value());
}

TEST(ServerTest, CreateRejectsBadOptions) {
  const auto factory = [] { return std::make_unique<FakePlanner>(); };
  ServerOptions o;
  o.port = 70000;
  auto s = Server::Create(o, factory);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("port"), std::string::npos);
  o = ServerOptions();
  o.bind_address = "not-an-ip";
  s = Server::Create(o, factory);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("bind address"), std::string::npos);
  o = ServerOptions();
  o.max_frame_bytes = 10;
  EXPECT_FALSE(Server::Create(o, factory).ok());
  o = ServerOptions();
  o.status_interval = -1;
  EXPECT_FALSE(Server::Create(o, factory).ok());
  EXPECT_FALSE(Server::Create(ServerOptions(), nullptr).ok());
}

TEST(ServerTest, PortInUseIsAnError) {
  TestServer first;
  ServerOptions o;
  o.port = first.port();
  // reuse_address lets a second listener bind on some systems only when the first is gone;
  // with the first listening, binding must fail.
  auto s = Server::Create(o, [] { return std::make_unique<FakePlanner>(); });
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(std::to_string(first.port())), std::string::npos) << s.message();
}

// A WebSocket client frenetic did not write: Python's `websockets` sends the real first
// message and checks the reply (tests/net/interop_client.py).
TEST(ServerTest, InteroperatesWithPythonWebsockets) {
  std::string python;
  for (const char* candidate : {"python3", "/usr/bin/python3"}) {
    const std::string probe =
        std::string(candidate) + " -c 'import websockets' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      python = candidate;
      break;
    }
  }
  if (python.empty()) GTEST_SKIP() << "python3 with the websockets module is not installed";
  TestServer server;
  const std::string cmd = python + " " + FRENETIC_SOURCE_DIR + "/tests/net/interop_client.py " +
                          std::to_string(server.port()) + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 512> buf;
  while (std::fgets(buf.data(), buf.size(), pipe)) output += buf.data();
  const int rc = pclose(pipe);
  EXPECT_EQ(rc, 0) << output;
  EXPECT_NE(output.find("OK control 50 points from x 909.48"), std::string::npos) << output;
  EXPECT_EQ(server.server().stats().cycles, 1);
  EXPECT_EQ(server.server().stats().null_telemetry, 1);
}

}  // namespace
}  // namespace frenetic::net

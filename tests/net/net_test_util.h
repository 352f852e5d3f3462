// Shared by the net tests: the wire tests' frames (wire/frames.h), a fake planner and a small Beast
// WebSocket client whose every step has a timeout (so a broken server fails a test, not hangs it).
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <boost/system/error_code.hpp>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "frenetic/net/server.h"
#include "frenetic/plan/planner.h"
#include "wire/frames.h"

namespace frenetic::net::testing {

using wire::testing::FirstTelemetryFrame;
using wire::testing::FrameWithJunk;
using wire::testing::FrameWithPath;
using wire::testing::FrameWithRows;
using wire::testing::kFirstTelemetryJson;
using wire::testing::SensorRow;
using wire::testing::TelemetryFrameAt;

// Deterministic planner: point i is (x + i, y + cycles), where cycles counts this instance's
// Plan() calls from 1, so a reply tells both whose telemetry and which planner produced it.
class FakePlanner : public plan::Planner {
 public:
  // kLong: kLongPoints points, a reply far larger than Beast's 4096-byte write buffer.
  enum class Mode { kGood, kNaN, kUnequal, kShort, kLong };
  static constexpr int kLongPoints = 500;
  explicit FakePlanner(Mode mode = Mode::kGood) : mode_(mode) {}

  const plan::PlanResult& Plan(const plan::Telemetry& t) override {
    ++cycles_;
    last_ = t;
    result_.x.clear();
    result_.y.clear();
    const int n = mode_ == Mode::kShort  ? 3
                  : mode_ == Mode::kLong ? kLongPoints
                                         : plan::kMinPathPoints;
    for (int i = 0; i < n; ++i) {
      result_.x.push_back(t.x + i * (mode_ == Mode::kLong ? 0.123456789 : 1.0));
      result_.y.push_back(t.y + cycles_);
    }
    if (mode_ == Mode::kNaN) result_.x[10] = std::nan("");
    if (mode_ == Mode::kUnequal) result_.y.resize(20);
    result_.status = plan::PlanStatus::kOk;
    return result_;
  }
  void Reset() override { cycles_ = 0; }
  std::string_view name() const override { return "fake"; }

  int cycles_ = 0;
  plan::Telemetry last_;

 private:
  Mode mode_;
  plan::PlanResult result_;
};

// A server on 127.0.0.1, ephemeral port, running on its own thread until destruction.
class TestServer {
 public:
  explicit TestServer(ServerOptions options = {}, FakePlanner::Mode mode = FakePlanner::Mode::kGood,
                      bool refuse = false)
      : TestServer(options, [mode, refuse]() -> std::unique_ptr<plan::Planner> {
          if (refuse) return nullptr;
          return std::make_unique<FakePlanner>(mode);
        }) {}
  // With the given planners (planners_made counts the factory's calls).
  TestServer(ServerOptions options, PlannerFactory factory) {
    options.bind_address = "127.0.0.1";
    options.port = 0;
    options.status_interval = 0;
    auto server = Server::Create(options, [this, factory]() -> std::unique_ptr<plan::Planner> {
      ++planners_made;
      return factory();
    });
    if (!server.ok()) {
      ADD_FAILURE() << server.message();
      return;
    }
    server_ = std::move(server).value();
    thread_ = std::thread([this] { server_->Run(); });
  }
  ~TestServer() {
    if (!server_) return;
    server_->Stop();
    thread_.join();
  }
  int port() const { return server_ ? server_->port() : 0; }
  Server& server() { return *server_; }
  std::atomic<int> planners_made{0};

 private:
  std::unique_ptr<Server> server_;
  std::thread thread_;
};

// Synchronous-looking Beast client; each step gives up after `timeout` seconds. Its Beast
// stream lives in net_test_util.cc: the WebSocket templates are compiled once for every net test
// file, not once per file that includes this header.
class TestClient {
 public:
  explicit TestClient(double timeout = 10.0);
  ~TestClient();
  TestClient(const TestClient&) = delete;
  TestClient& operator=(const TestClient&) = delete;

  bool Connect(int port, const std::string& target = "/socket.io/?EIO=4&transport=websocket");
  // The error of the write, none (false) when it was sent.
  boost::system::error_code Send(std::string_view frame, bool binary = false);
  // The next message, or nullopt on error / timeout.
  std::optional<std::string> Receive();
  std::optional<std::string> Exchange(std::string_view frame) {
    if (Send(frame)) return std::nullopt;
    return Receive();
  }
  void Close();
  // Drops the TCP connection without a WebSocket close frame.
  void Abort();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace frenetic::net::testing

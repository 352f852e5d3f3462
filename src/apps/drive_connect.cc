#include "apps/drive_connect.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <vector>

#include "frenetic/net/client.h"
#include "frenetic/net/protocol.h"
#include "frenetic/sim/simulator.h"

namespace frenetic::apps {
namespace {

// Adapts an Episode (the same exchange loop as in-process drives, with the scenario's latency
// rules) to the network client: every reply goes through Episode::Submit, so a drive over the
// network and an in-process drive with the same seed see identical simulator states.
class EpisodeEndpoint final : public net::SimulatorEndpoint {
 public:
  explicit EpisodeEndpoint(sim::Episode* episode) : episode_(episode) {
    round_trip_ms_.reserve(20000);
  }

  std::string OnOpen() override { return Send(); }

  std::string OnControl(std::span<const double> x, std::span<const double> y) override {
    Received();
    if (Status s = episode_->Submit(x, y); !s.ok() && rejected_++ == 0) {
      spdlog::warn("{} (the simulator ignores such a path)", s.message());
    }
    return Send();
  }

  // A manual reply keeps the old path; the simulator still ticks before its next telemetry.
  std::string OnManual() override {
    Received();
    ++manuals_;
    const plan::Telemetry& t = episode_->telemetry();
    const std::vector<double> x = t.previous_path_x, y = t.previous_path_y;
    (void)episode_->Submit(x, y);
    return Send();
  }

  bool Done() const override { return episode_->done(); }
  double SimSeconds() const override { return episode_->sim().time(); }

  const std::vector<double>& round_trip_ms() const { return round_trip_ms_; }
  int manuals() const { return manuals_; }

 private:
  std::string Send() {
    sent_at_ = std::chrono::steady_clock::now();
    return net::FormatTelemetryFrame(episode_->telemetry());
  }
  void Received() {
    round_trip_ms_.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - sent_at_)
            .count());
  }

  sim::Episode* episode_;
  std::chrono::steady_clock::time_point sent_at_;
  std::vector<double> round_trip_ms_;
  int rejected_ = 0, manuals_ = 0;
};

}  // namespace

StatusOr<sim::DriveReport> DriveOverNetwork(std::shared_ptr<const sim::World> world,
                                            const sim::Scenario& scenario, std::uint64_t seed,
                                            const sim::EpisodeLimits& limits,
                                            const ConnectOptions& options) {
  if (Status s = limits.Validate(); !s.ok()) return s;
  auto simulator = sim::Simulator::Create(std::move(world), scenario, seed);
  if (!simulator.ok()) return simulator.status();
  sim::Episode episode(std::move(simulator).value(), limits);
  EpisodeEndpoint endpoint(&episode);
  net::ClientOptions client;
  client.realtime = options.realtime;
  client.timeout = options.timeout;
  net::ClientStats stats;
  if (Status s = net::RunClient(options.url, endpoint, client, &stats); !s.ok()) {
    return Status::Error(options.url + ": " + s.message());
  }
  return sim::MakeReport(episode, "remote", endpoint.round_trip_ms(), endpoint.manuals());
}

}  // namespace frenetic::apps

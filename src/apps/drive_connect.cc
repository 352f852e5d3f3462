#include "apps/drive_connect.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <vector>

#include "frenetic/drive/evaluators.h"
#include "frenetic/net/client.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::apps {
namespace {

constexpr const char* kRemotePlanner = "remote";

// Adapts an Episode (the same exchange loop as in-process drives, with the scenario's latency
// rules) to the network client: every reply goes through Episode::Submit, so a drive over the
// network and an in-process drive with the same seed see identical simulator states. Each reply
// is told to the episode's observers (the record's remote exchange lines).
class EpisodeEndpoint final : public net::SimulatorEndpoint {
 public:
  EpisodeEndpoint(sim::Episode* episode, bool timing) : episode_(episode), timing_(timing) {
    round_trip_ms_.reserve(20000);
  }

  std::string OnOpen() override { return Send(); }

  std::string OnControl(std::span<const double> x, std::span<const double> y) override {
    sim::ExchangeReply reply;
    reply.path_x = x;
    reply.path_y = y;
    reply.kind = "control";
    reply.ms = Received();
    if (Status s = episode_->Submit(x, y, reply); !s.ok() && rejected_++ == 0) {
      spdlog::warn("{} (the simulator ignores such a path)", s.message());
    }
    return Send();
  }

  // A manual reply keeps the old path; the simulator still ticks before its next telemetry.
  std::string OnManual() override {
    sim::ExchangeReply reply;  // no path received
    reply.kind = "manual";
    reply.ms = Received();
    ++manuals_;
    const plan::Telemetry& t = episode_->telemetry();
    const std::vector<double> x = t.previous_path_x, y = t.previous_path_y;
    (void)episode_->Submit(x, y, reply);
    return Send();
  }

  bool Done() const override { return episode_->done(); }
  double SimSeconds() const override { return episode_->sim().time(); }

  const std::vector<double>& round_trip_ms() const { return round_trip_ms_; }
  int manuals() const { return manuals_; }

 private:
  std::string Send() {
    std::string frame = wire::FormatTelemetryFrame(episode_->telemetry());
    sent_at_ = std::chrono::steady_clock::now();
    return frame;
  }
  // Notes the round trip and returns it, ms (0 with timing off).
  double Received() {
    round_trip_ms_.push_back(
        timing_ ? std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                             sent_at_)
                      .count()
                : 0.0);
    return round_trip_ms_.back();
  }

  sim::Episode* episode_;
  bool timing_;
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
  // The judge before the record, whose footer has the judgements.
  std::optional<sim::JudgeObserver> judge;
  if (options.judge) episode.Attach(&judge.emplace(*options.judge, options.timing));
  EpisodeEndpoint endpoint(&episode, options.timing);
  if (options.record != nullptr) {
    options.record->set_timing(options.timing);
    options.record->set_planner(kRemotePlanner, nullptr, options.url);
    episode.Attach(options.record);
  }
  net::ClientOptions client;
  client.realtime = options.realtime;
  client.timeout = options.timeout;
  net::ClientStats stats;
  if (Status s = net::RunClient(options.url, endpoint, client, &stats); !s.ok()) {
    return Status::Error(options.url + ": " + s.message());
  }
  spdlog::debug("{}: first exchange round trip {:.3f} ms, TCP_NODELAY {}", options.url,
                endpoint.round_trip_ms().empty() ? 0.0 : endpoint.round_trip_ms().front(),
                stats.tcp_nodelay);
  sim::DriveReport report =
      sim::MakeReport(episode, kRemotePlanner, endpoint.round_trip_ms(), endpoint.manuals());
  if (Status s = episode.Finish(&report); !s.ok()) return s;
  return report;
}

}  // namespace frenetic::apps

#include "apps/drive_connect.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <vector>

#include "frenetic/net/client.h"
#include "frenetic/sim/simulator.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::apps {
namespace {

constexpr const char* kRemotePlanner = "remote";

// Adapts an Episode (the same exchange loop as in-process drives, with the scenario's latency
// rules) to the network client: every reply goes through Episode::Submit, so a drive over the
// network and an in-process drive with the same seed see identical simulator states.
class EpisodeEndpoint final : public net::SimulatorEndpoint {
 public:
  EpisodeEndpoint(sim::Episode* episode, sim::RecordWriter* record, bool timing)
      : episode_(episode), record_(record), timing_(timing) {
    round_trip_ms_.reserve(20000);
  }

  std::string OnOpen() override { return Send(); }

  std::string OnControl(std::span<const double> x, std::span<const double> y) override {
    const std::size_t first_incident = Received();
    if (Status s = episode_->Submit(x, y); !s.ok() && rejected_++ == 0) {
      spdlog::warn("{} (the simulator ignores such a path)", s.message());
    }
    Record(x, y, "control", first_incident);
    return Send();
  }

  // A manual reply keeps the old path; the simulator still ticks before its next telemetry.
  std::string OnManual() override {
    const std::size_t first_incident = Received();
    ++manuals_;
    const plan::Telemetry& t = episode_->telemetry();
    const std::vector<double> x = t.previous_path_x, y = t.previous_path_y;
    (void)episode_->Submit(x, y);
    Record({}, {}, "manual", first_incident);
    return Send();
  }

  bool Done() const override { return episode_->done(); }
  double SimSeconds() const override { return episode_->sim().time(); }

  const std::vector<double>& round_trip_ms() const { return round_trip_ms_; }
  int manuals() const { return manuals_; }

 private:
  std::string Send() {
    t_sent_ = episode_->sim().time();
    index_ = episode_->exchanges();
    std::string frame;
    if (record_ != nullptr) {
      // The record keeps the telemetry as the text sent, as an in-process record does.
      telemetry_json_ = wire::TelemetryToJson(episode_->telemetry());
      frame = "42[\"telemetry\"," + telemetry_json_ + "]";
    } else {
      frame = wire::FormatTelemetryFrame(episode_->telemetry());
    }
    sent_at_ = std::chrono::steady_clock::now();
    return frame;
  }
  // Notes the round trip; returns where this exchange's incidents will start in the log.
  std::size_t Received() {
    round_trip_ms_.push_back(
        timing_ ? std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                             sent_at_)
                      .count()
                : 0.0);
    return episode_->sim().monitor().log().size();
  }
  void Record(std::span<const double> x, std::span<const double> y, std::string_view reply,
              std::size_t first_incident) {
    if (record_ == nullptr) return;
    record_->WriteRemoteExchange(index_, t_sent_, telemetry_json_, x, y, reply,
                                 round_trip_ms_.back(), episode_->sim(), first_incident,
                                 episode_->last_l_old(), episode_->last_l_new());
  }

  sim::Episode* episode_;
  sim::RecordWriter* record_;
  bool timing_;
  std::chrono::steady_clock::time_point sent_at_;
  double t_sent_ = 0;
  int index_ = 0;
  std::string telemetry_json_;
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
  if (options.judge) episode.EnableJudging(*options.judge, options.timing);
  EpisodeEndpoint endpoint(&episode, options.record, options.timing);
  if (options.record != nullptr) {
    options.record->set_timing(options.timing);
    options.record->WriteHeader(episode.sim(), kRemotePlanner, nullptr, options.url);
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
  if (options.record != nullptr) {
    options.record->WriteFooter(report);
    if (Status s = options.record->status(); !s.ok()) return s;
  }
  return report;
}

}  // namespace frenetic::apps

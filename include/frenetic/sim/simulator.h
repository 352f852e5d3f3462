// The headless simulator: one ego driven by paths, traffic, incident monitor, on a World.
// Step-wise control for both the in-process episode loop and a network client: read the
// telemetry, apply a control path (closest-point trimming), advance N ticks.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "frenetic/plan/telemetry.h"
#include "frenetic/sim/drive_breakdown.h"
#include "frenetic/sim/ego.h"
#include "frenetic/sim/incident_monitor.h"
#include "frenetic/sim/scenario.h"
#include "frenetic/sim/traffic.h"
#include "frenetic/sim/world.h"
#include "frenetic/status.h"

namespace frenetic::sim {

// The car ahead of the ego in its lane (smooth-line lanes), if any within 200 m.
struct LeaderGap {
  int id = -1;          // -1: none
  double gap = 0;       // m, bumper to bumper (centre distance along s minus the car length)
  double headway = 0;   // s, gap / ego speed (infinite below 0.1 m/s)
};

class Simulator {
 public:
  // Fails on an invalid scenario or a start pose that is not a finite point.
  static StatusOr<std::unique_ptr<Simulator>> Create(std::shared_ptr<const World> world,
                                                     const Scenario& scenario,
                                                     std::uint64_t seed);

  // The telemetry the simulator would send now, in SI (float32-rounded values).
  void GetTelemetry(plan::Telemetry* out) const;
  plan::Telemetry Telemetry() const;
  // A control message: replaces the path (float32, trimmed). Non-finite values or unequal
  // lengths are rejected with a message and leave the path unchanged (the real simulator stalls).
  Status ApplyPath(std::span<const double> x, std::span<const double> y);
  // Advances `ticks` physics ticks (each: ego, traffic, incidents, frame scheduler).
  void Advance(int ticks);
  // An independent copy in the same state (traffic and its random draws included): advanced
  // with the same paths it runs as this one would.
  std::unique_ptr<Simulator> Clone() const;

  std::int64_t ticks() const { return ticks_; }
  double time() const { return ticks_ * kTick; }
  const EgoCar& ego() const { return ego_; }
  const Traffic& traffic() const { return *traffic_; }
  Traffic& mutable_traffic() { return *traffic_; }  // for tests and scripted set-ups
  const IncidentMonitor& monitor() const { return monitor_; }
  const Scenario& scenario() const { return scenario_; }
  const World& world() const { return *world_; }
  std::uint64_t seed() const { return seed_; }
  // The ego on the smooth line, and the simulator's (chord) Frenet of it.
  const EgoView& ego_view() const { return view_; }
  double chord_s() const { return chord_s_; }
  double chord_d() const { return chord_d_; }

  LeaderGap leader() const { return leader_; }
  double min_gap() const { return min_gap_; }          // m, +inf if never a leader
  double min_headway() const { return min_headway_; }  // s, +inf if never a leader
  int lane_changes() const { return lane_changes_; }
  int lane() const { return lane_; }  // current ego lane (0..2), -1 off the carriageway
  // Where the time went, per lap (following, at the limit, passes made and missed).
  const DriveBreakdown& breakdown() const { return breakdown_; }

 private:
  Simulator(std::shared_ptr<const World> world, const Scenario& scenario, std::uint64_t seed,
            float x, float y, double yaw);
  Simulator(const Simulator& other) = default;  // Clone: every member copied
  void Tick();
  void UpdateView();
  bool UpdateMetrics();  // true when the ego changed lane
  void UpdateLeader();

  std::shared_ptr<const World> world_;
  Scenario scenario_;
  std::uint64_t seed_;
  EgoCar ego_;
  std::optional<Traffic> traffic_;  // set in the constructor, after the ego's view
  IncidentMonitor monitor_;
  std::int64_t ticks_ = 0;
  double frame_phase_ = 0;  // fraction of a rendered frame elapsed
  EgoView view_;
  double chord_s_ = 0, chord_d_ = 0;
  LeaderGap leader_;
  double min_gap_, min_headway_;
  int lane_changes_ = 0, lane_ = -1;
  DriveBreakdown breakdown_;
};

}  // namespace frenetic::sim

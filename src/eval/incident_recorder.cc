#include "frenetic/eval/incident_recorder.h"

#include <algorithm>
#include <cmath>

namespace frenetic::sim {
namespace {

bool AnyFlag(const IncidentMonitor& m) {
  for (int k = 0; k < kIncidentKinds; ++k) {
    if (m.active(static_cast<IncidentKind>(k))) return true;
  }
  return false;
}

}  // namespace

IncidentRecorder::IncidentRecorder(const Simulator& sim, const JudgeOptions& options, bool timing)
    : sim_(sim), options_(options), timing_(timing) {
  const int window = static_cast<int>(std::lround(options_.window_seconds / kTick));
  ring_ticks_ = std::max(1, window) + kBlockTicks + 1;
  cars_per_tick_ = static_cast<int>(sim_.traffic().cars().size());
  ego_ring_.resize(ring_ticks_);
  car_ring_.resize(static_cast<std::size_t>(ring_ticks_) * cars_per_tick_);
  car_count_.assign(ring_ticks_, 0);
  const int blocks = ring_ticks_ / kBlockTicks + 2;
  monitor_ring_.assign(blocks, sim_.monitor());
  for (IncidentMonitor& m : monitor_ring_) m.ClearLog();
  monitor_tick_.assign(blocks, -1);
  last_spawns_.assign(cars_per_tick_, 0);
  for (const TrafficCar& c : sim_.traffic().cars()) {
    if (c.id >= 0 && c.id < cars_per_tick_) last_spawns_[c.id] = c.spawns;
  }
  tick_cars_.reserve(cars_per_tick_);
  incidents_seen_ = sim_.monitor().log().size();
}

void IncidentRecorder::AfterTick() {
  const std::int64_t k = sim_.ticks();
  if (first_tick_ < 0) first_tick_ = k;
  // The ego as the simulator measured it on this tick.
  RecordedEgo e;
  e.x = sim_.ego().x();
  e.y = sim_.ego().y();
  e.yaw = sim_.ego().yaw();
  e.speed = sim_.ego().speed();
  e.s = sim_.ego_view().s;
  e.d = sim_.ego_view().d;
  e.flagged = AnyFlag(sim_.monitor());
  // The cars as the collision test saw them: a car respawned by this tick's frame was tested
  // where it had been (over 200 m away), so it sits this tick out.
  tick_cars_.clear();
  for (const TrafficCar& c : sim_.traffic().cars()) {
    if (c.id < 0 || c.id >= cars_per_tick_) continue;
    const bool respawned = c.spawns != last_spawns_[c.id];
    last_spawns_[c.id] = c.spawns;
    if (!c.spawned || respawned) continue;
    tick_cars_.push_back({c.id, c.x, c.y, c.heading, c.s, c.d});
  }
  const int slot = static_cast<int>(k % ring_ticks_);
  ego_ring_[slot] = e;
  std::copy(tick_cars_.begin(), tick_cars_.end(),
            car_ring_.begin() + static_cast<std::ptrdiff_t>(slot) * cars_per_tick_);
  car_count_[slot] = static_cast<int>(tick_cars_.size());
  const bool block_tick = k % kBlockTicks == 0;
  if (block_tick) {
    const int m =
        static_cast<int>((k / kBlockTicks) % static_cast<std::int64_t>(monitor_ring_.size()));
    monitor_ring_[m] = sim_.monitor();  // the slot's emptied log keeps its capacity
    monitor_ring_[m].ClearLog();
    monitor_tick_[m] = k;
  }
  for (IncidentCase& c : open_) {
    c.AddTick(e, tick_cars_);
    if (block_tick) c.AddMonitor(k, sim_.monitor());
  }
  // New incidents: a case with the ring's ticks up to this one.
  const std::vector<Incident>& log = sim_.monitor().log();
  for (; incidents_seen_ < log.size(); ++incidents_seen_) {
    IncidentCase c;
    c.incident = log[incidents_seen_];
    c.incident_tick = k;
    c.first_tick = std::max(first_tick_, k - ring_ticks_ + 1);
    c.car_length = sim_.scenario().car_length;
    c.car_width = sim_.scenario().car_width;
    for (std::int64_t t = c.first_tick; t <= k; ++t) {
      const int s = static_cast<int>(t % ring_ticks_);
      const RecordedCar* cars = car_ring_.data() + static_cast<std::ptrdiff_t>(s) * cars_per_tick_;
      c.AddTick(ego_ring_[s], {cars, static_cast<std::size_t>(car_count_[s])});
      if (t % kBlockTicks == 0) {
        const int m =
            static_cast<int>((t / kBlockTicks) % static_cast<std::int64_t>(monitor_ring_.size()));
        if (monitor_tick_[m] == t) c.AddMonitor(t, monitor_ring_[m]);
      }
    }
    open_.push_back(std::move(c));
  }
  // Cases whose margin has been driven, oldest first (they close in log order).
  const std::int64_t margin = std::llround(options_.margin_seconds / kTick);
  std::size_t closed = 0;
  while (closed < open_.size() && open_[closed].incident_tick + margin <= k) {
    Judge(open_[closed]);
    ++closed;
  }
  open_.erase(open_.begin(), open_.begin() + static_cast<std::ptrdiff_t>(closed));
}

void IncidentRecorder::Finish() {
  for (IncidentCase& c : open_) Judge(c);
  open_.clear();
}

void IncidentRecorder::Judge(IncidentCase& c) {
  IncidentJudgement j = JudgeIncident(sim_.world(), c, options_);
  if (!timing_) j.ms = 0;
  judgements_.push_back(std::move(j));
  if (keep_cases_) kept_.push_back(std::move(c));
}

}  // namespace frenetic::sim

#include "plan/predictor.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>

#include "frenetic/units.h"

namespace frenetic::plan {
namespace {

// m: a reading this far from where the previous one predicted it is another car (a respawn
// teleports an id, udacity-sim.md §8.2): its acceleration is not estimated.
constexpr double kRespawnJump = 15.0;
// s: an older reading says little about the current acceleration (a queued car's brake/throttle
// cycle is about a second long).
constexpr double kMaxReadingAge = 0.5;
// s: recorded futures are kept every kFutureStep (interpolated between).
constexpr double kFutureStep = 0.2;
// m/s^2: no car of the simulator speeds up faster (traffic tops out near 5).
constexpr double kMaxCarAccel = 8.0;
// The traffic's lane-change rule (udacity-sim.md §8.5): faster than 15 mph, and no car within
// 20 m in s in the target lane.
constexpr double kGhostMinSpeed = 15.0 / units::kMpsToMph13;  // m/s
constexpr double kGhostClear = 20.0;                   // m
constexpr double kGhostLeaderReach = 40.0;  // m: a leader this close ahead is what it brakes for
constexpr double kGhostOnset = 1.0;         // s: the rule holds this long before the car moves
constexpr double kGhostEgoLateral = 3.0;    // m: the rule minds an ego this close to the lane

// The projections of recorded future samples from the last two Observe calls, per car: a
// recording moves on by a step per cycle, so most samples of a car's future this cycle were
// projected one cycle ago (a stride of one step) or two (a stride of two), and from the same
// hint sample. A projection depends on nothing else (ReferenceLine::HintSample): a kept one is
// the value a fresh projection gives, bit for bit. Sized once; Find and Add do not allocate.
class ProjectionMemo {
 public:
  // One projected sample: its key (x, y, the hint sample), the projection, the line's heading
  // there and, for the sample's heading h, the cosine and sine of the line's heading less h.
  struct Entry {
    double x, y;
    int hint;
    double s, d, line_heading;
    double h, cos_rel, sin_rel;
  };

  ProjectionMemo(int max_cars, int per_car) : max_cars_(max_cars), per_car_(per_car) {
    for (Generation& g : gens_) {
      g.runs.reserve(max_cars);
      // Not written until used (the Udacity simulator's cars have no futures).
      g.entries =
          std::make_unique_for_overwrite<Entry[]>(static_cast<std::size_t>(max_cars) * per_car);
    }
  }

  // A new cycle: the oldest generation's runs are dropped, this cycle's are added from now on.
  void NextCycle() {
    cur_ = (cur_ + 1) % kGenerations;
    gens_[cur_].runs.clear();
    run_ = nullptr;
  }
  void Clear() {
    for (Generation& g : gens_) g.runs.clear();
    run_ = nullptr;
  }

  // Starts car `id`'s run of this cycle (with no room left, Find finds nothing and Add keeps
  // nothing): the car's runs of the earlier cycles are where Find looks.
  void BeginCar(int id) {
    run_ = nullptr;
    Generation& g = gens_[cur_];
    if (static_cast<int>(g.runs.size()) >= max_cars_) return;
    g.runs.push_back({id, static_cast<int>(g.runs.size()) * per_car_, 0});
    run_ = &g.runs.back();
    for (int b = 1; b < kGenerations; ++b) {
      Look& look = looks_[b - 1];
      look = {};
      const Generation& old = gens_[(cur_ + kGenerations - b) % kGenerations];
      for (const Run& r : old.runs) {
        if (r.id == id) look.run = &r;
      }
      look.gen = &old;
    }
  }

  // The kept projection of (x, y) from hint sample `hint`, or null. The samples of a car are
  // looked up in order, so each earlier run is searched once (for the first sample it holds)
  // and then followed entry by entry; a run that stops matching is not searched again.
  const Entry* Find(double x, double y, int hint) {
    if (run_ == nullptr) return nullptr;
    for (Look& look : looks_) {
      if (look.run == nullptr) continue;
      const Entry* e = look.gen->entries.get() + look.run->offset;
      const int n = look.run->count;
      if (look.next < 0) {  // not found in this run yet: search it (once)
        for (int k = 0; k < n && look.next < 0; ++k) {
          if (Same(e[k], x, y)) look.next = k;
        }
        if (look.next < 0) {
          look.run = nullptr;
          continue;
        }
      } else if (look.next >= n || !Same(e[look.next], x, y)) {
        look.run = nullptr;
        continue;
      }
      const Entry& hit = e[look.next++];
      if (hit.hint == hint) return &hit;
    }
    return nullptr;
  }

  // Keeps a projection in the current car's run.
  void Add(const Entry& e) {
    if (run_ == nullptr || run_->count >= per_car_) return;
    gens_[cur_].entries[run_->offset + run_->count++] = e;
  }

 private:
  static constexpr int kGenerations = 3;  // this cycle's and the two before
  struct Run {
    int id, offset, count;
  };
  struct Generation {
    std::vector<Run> runs;
    std::unique_ptr<Entry[]> entries;  // per_car_ per run, the run's first `count` used
  };
  // A car's run of an earlier generation as Find follows it: the entry expected next (-1: not
  // searched yet).
  struct Look {
    const Generation* gen = nullptr;
    const Run* run = nullptr;
    int next = -1;
  };
  static bool Same(const Entry& e, double x, double y) {
    return std::bit_cast<std::uint64_t>(e.x) == std::bit_cast<std::uint64_t>(x) &&
           std::bit_cast<std::uint64_t>(e.y) == std::bit_cast<std::uint64_t>(y);
  }

  int max_cars_, per_car_;
  Generation gens_[kGenerations];
  int cur_ = 0;
  Run* run_ = nullptr;
  Look looks_[kGenerations - 1];
};

class TrafficPredictor : public Predictor {
 public:
  TrafficPredictor(std::shared_ptr<const map::Road> road, const PredictorOptions& options,
                   bool manoeuvres)
      : road_(std::move(road)),
        line_(road_->line_ptr()),
        options_(options),
        manoeuvres_(manoeuvres),
        memo_(options_.max_cars, kMaxFutureSamples) {
    cars_.reserve(2 * options_.max_cars);  // room for a ghost per car
    slot_.reserve(2 * options_.max_cars);
    ghost_seen_.reserve(options_.max_cars);
    ghost_seen_next_.reserve(options_.max_cars);
    memory_.reserve(options_.max_cars);
    if (!road_->uniform() && options_.merge_time > 0) FindMerges();
    const std::size_t n = static_cast<std::size_t>(options_.max_cars) * kMaxFutureSamples;
    for (auto* v : {&fut_s_, &fut_d_, &fut_v_, &fut_vd_}) v->assign(n, 0.0);
    fut_n_.assign(options_.max_cars, 0);
    fut_dt_.assign(options_.max_cars, 0.0);
    fut_t0_.assign(options_.max_cars, 0.0);
  }

  void Observe(std::span<const SensorCar> rows, double ego_s, double now,
               std::span<const CarFuture> futures, double ego_d) override {
    cars_.clear();
    slot_.clear();
    memo_.NextCycle();
    if (!std::isfinite(ego_s)) return;
    for (const SensorCar& row : rows) {
      if (static_cast<int>(cars_.size()) >= options_.max_cars) break;
      if (!std::isfinite(row.x) || !std::isfinite(row.y) || !std::isfinite(row.vx) ||
          !std::isfinite(row.vy) || std::abs(row.x) > 1e6 || std::abs(row.y) > 1e6) {
        continue;
      }
      // Recompute Frenet from x, y: the reported s, d may be the seam's 0/0 glitch. The reported
      // s is only a hint (the line falls back to a global search when it is wrong).
      const double hint = std::isfinite(row.s) ? row.s : ego_s;
      const map::FrenetPoint f = line_->ToFrenet(row.x, row.y, hint);
      if (!std::isfinite(f.s) || !std::isfinite(f.d)) continue;
      if (!OnRoad(f.s, f.d)) continue;  // parked / off the road
      const double rel = line_->DiffS(f.s, line_->WrapS(ego_s));
      if (std::abs(rel) > options_.range) continue;
      const double heading = line_->At(f.s).heading;
      const double ch = std::cos(heading), sh = std::sin(heading);
      TrackedCar car;
      car.id = row.id;
      car.s = rel;
      car.d = f.d;
      // Along the lane and across it (the right normal is (sin h, -cos h)).
      double v = row.vx * ch + row.vy * sh;
      double v_d = row.vx * sh - row.vy * ch;
      Memory* m = Find(row.id);
      if (IsSpawnGlitch(m, f.s, v, now)) {
        // The spawn glitch reports the speed in mph as if it were m/s for one message: undo
        // the unit slip.
        v = std::min(v / units::kMpsToMph13, options_.max_speed);
        v_d /= units::kMpsToMph13;
      } else {
        car.a_s = Acceleration(m, f.s, v, now);
        Remember(m, row.id, f.s, v, now);
      }
      car.v_s = v;
      car.v_d = v_d;
      car.d_target = manoeuvres_ ? LateralTarget(f.s, car.d, v_d) : car.d;
      if (!manoeuvres_) car.a_s = 0;
      car.length = row.length > 0 && std::isfinite(row.length) ? row.length : options_.car_length;
      car.width = row.width > 0 && std::isfinite(row.width) ? row.width : options_.car_width;
      const int slot = static_cast<int>(cars_.size());
      car.recorded = LoadFuture(row.id, futures, slot, f.s, ego_s);
      if (!car.recorded && car.d_target == car.d) PredictMerge(f.s, car);
      cars_.push_back(car);
      slot_.push_back(car.recorded ? slot : -1);
    }
    AddCarsToCome(rows, futures, ego_s);
    for (TrackedCar& c : cars_) c.brake_time = options_.brake_horizon;
    if (manoeuvres_ && options_.follow_gap > 0 && road_->uniform()) FollowGaps();
    if (manoeuvres_ && options_.lane_change_ghosts && road_->uniform()) {
      AddLaneChangeGhosts(now, ego_d);
    }
  }

  std::span<const TrackedCar> cars() const override { return cars_; }

  Prediction Predict(int i, double t) const override {
    const TrackedCar& c = cars_[i];
    if (slot_[i] >= 0) return FromFuture(slot_[i], t);
    Prediction p;
    p.s = c.s;
    p.v = c.v_s;
    if (c.a_s < -options_.brake_threshold) {
      // Braking at a_s for tb, then at the reached speed (never backwards).
      const double tb = std::clamp(std::min(c.brake_time, c.v_s / -c.a_s), 0.0, t);
      p.s += c.v_s * tb + 0.5 * c.a_s * tb * tb;
      p.v = std::max(0.0, c.v_s + c.a_s * tb);
      p.s += p.v * (t - tb);
    } else {
      p.s += c.v_s * t;
    }
    p.d = c.d;
    if (c.d_target != c.d && c.v_d != 0 && t > c.lat_delay) {
      const double reach = (c.d_target - c.d) / c.v_d;  // s until the target lane's centre
      const double moving = t - c.lat_delay;
      if (moving < reach) {
        p.d = c.d + c.v_d * moving;
        p.v_d = c.v_d;
      } else {
        p.d = c.d_target;
      }
    }
    return p;
  }

  void Reset() override {
    cars_.clear();
    slot_.clear();
    memory_.clear();
    ghost_seen_.clear();
    memo_.Clear();
  }

 private:
  struct Memory {
    int id;
    double s;  // line s of the reading (wrapped)
    double v;
    double time;  // s, `now` of the reading (NaN: unknown)
  };

  Memory* Find(int id) {
    for (Memory& e : memory_) {
      if (e.id == id) return &e;
    }
    return nullptr;
  }

  // The spawn glitch: a speed above any car's, or a jump from a recent reading of the same car
  // that no car could accelerate through. An old reading, or one from before a respawn (the id
  // teleported), says nothing about the current speed, so it never makes a reading a glitch.
  bool IsSpawnGlitch(const Memory* m, double s, double v, double now) const {
    if (v > options_.max_speed) return true;
    if (m == nullptr || !(m->v > 1.0)) return false;
    const double dt = now - m->time;
    if (!(dt > 0 && dt <= kMaxReadingAge)) return false;
    if (std::abs(line_->DiffS(s, m->s + m->v * dt)) > kRespawnJump) return false;
    return v > options_.spike_ratio * m->v && v - m->v > kMaxCarAccel * dt + 2.0;
  }

  // Longitudinal acceleration from the id's previous reading, when that is recent, or 0.
  double Acceleration(const Memory* m, double s, double v, double now) const {
    if (m == nullptr) return 0.0;
    const double dt = now - m->time;  // NaN when either time is unknown
    if (!(dt > 0 && dt <= kMaxReadingAge)) return 0.0;
    const double expected = m->s + 0.5 * (m->v + v) * dt;
    if (std::abs(line_->DiffS(s, expected)) > kRespawnJump) return 0.0;
    return (v - m->v) / dt;
  }

  void Remember(Memory* m, int id, double s, double v, double now) {
    if (m == nullptr) {
      if (static_cast<int>(memory_.size()) >= options_.max_cars) return;
      memory_.push_back({id, s, v, now});
      return;
    }
    *m = {id, s, v, now};
  }

  // Each braking car's brake_time behind a leader in its lane (the nearest ahead within 2 m
  // across) whose bumper gap is under follow_gap: the time until the gap, at the leader's
  // present speed and the car's present deceleration, has opened to follow_gap (at most
  // brake_horizon). A car braking with no such leader keeps brake_horizon.
  void FollowGaps() {
    const int n = static_cast<int>(cars_.size());
    for (int i = 0; i < n; ++i) {
      TrackedCar& c = cars_[i];
      if (!(c.a_s < -options_.brake_threshold) || c.recorded || !(c.s > kAbsentS)) continue;
      int lead = -1;
      for (int j = 0; j < n; ++j) {
        const TrackedCar& o = cars_[j];
        if (j == i || o.recorded || !(std::abs(o.d - c.d) < 2.0) || !(o.s > c.s)) continue;
        if (lead < 0 || o.s < cars_[lead].s) lead = j;
      }
      if (lead < 0) continue;
      const TrackedCar& l = cars_[lead];
      const double gap = l.s - c.s - 0.5 * (l.length + c.length);
      if (!(gap < options_.follow_gap)) continue;
      // gap + (v_l - v) t - a t^2 / 2 = follow_gap, a < 0: the positive root.
      const double a = -c.a_s, b = l.v_s - c.v_s, need = options_.follow_gap - gap;
      const double t = (-b + std::sqrt(b * b + 2 * a * need)) / a;
      if (std::isfinite(t)) c.brake_time = std::clamp(t, 0.0, options_.brake_horizon);
    }
  }

  // The second hypothesis of every car ahead that may change lanes by the traffic's own rule
  // (see PredictorOptions::lane_change_ghosts): braking behind a leader in its lane, faster than
  // 15 mph, the target lane clear within 20 m. The rule must hold for more than 50 evaluations
  // (about a second) before the car moves, so the ghost starts its move kGhostOnset after the
  // car was first seen so, or at once when that was long enough ago.
  void AddLaneChangeGhosts(double now, double ego_d) {
    const double w = options_.lane_width;
    const int n = static_cast<int>(cars_.size());
    ghost_seen_next_.clear();
    for (int i = 0; i < n; ++i) {
      const TrackedCar c = cars_[i];
      if (!(c.a_s < -options_.brake_threshold) || !(c.v_s > kGhostMinSpeed)) continue;
      if (c.d_target != c.d) continue;  // already moving
      const int lane = static_cast<int>(std::floor(c.d / w));
      const int target = lane == 1 ? 0 : 1;  // the middle lane's cars only ever go left
      if (lane < 0 || lane > 2 || target >= options_.num_lanes) continue;
      const double centre = (target + 0.5) * w;
      // The rule keeps a car 20 m clear of the ego only when the ego is in (or near) the target
      // lane; either way a car behind the ego is its follower's business.
      const bool ego_minded = !(std::abs(ego_d - centre) > kGhostEgoLateral);  // NaN: minded
      if (!(c.s > (ego_minded ? kGhostClear : -kGhostClear))) continue;
      bool clear = true, blocked = false;
      for (int j = 0; j < n && clear; ++j) {
        if (j == i) continue;
        const double ds = cars_[j].s - c.s;
        clear = !(std::abs(cars_[j].d - centre) <= 2.0) || std::abs(ds) > kGhostClear;
        blocked = blocked || (ds > 0 && ds < kGhostLeaderReach && std::abs(cars_[j].d - c.d) < 2.0);
      }
      if (!clear || !blocked) continue;
      double since = now;
      for (const auto& [id, t] : ghost_seen_) {
        if (id == c.id && std::isfinite(t)) since = t;
      }
      ghost_seen_next_.push_back({c.id, since});
      TrackedCar g = c;
      g.ghost = true;
      g.d_target = centre;
      g.v_d = std::copysign(options_.ghost_lateral_speed, centre - c.d);
      g.lat_delay = std::isfinite(now - since) ? std::clamp(kGhostOnset - (now - since), 0.0, kGhostOnset)
                                               : kGhostOnset;
      cars_.push_back(g);
      slot_.push_back(-1);
    }
    ghost_seen_.swap(ghost_seen_next_);
  }

  // Whether a reading at line coordinates (s, d) is on the carriageway.
  bool OnRoad(double s, double d) const {
    if (road_->uniform()) return !(d < options_.d_min || d > options_.d_max);
    const map::Road::Span e = road_->EdgesAt(s);
    return e.exists && d >= e.left - options_.edge_slack && d <= e.right + options_.edge_slack;
  }

  // The cars to come (CarFuture::start > 0, no row with their id): tracked from their first
  // sample, absent until it.
  void AddCarsToCome(std::span<const SensorCar> rows, std::span<const CarFuture> futures,
                     double ego_s) {
    for (const CarFuture& f : futures) {
      if (static_cast<int>(cars_.size()) >= options_.max_cars) return;
      if (!(f.start > 0) || !std::isfinite(f.start) || f.x.empty() || f.y.empty() ||
          !std::isfinite(f.x[0]) || !std::isfinite(f.y[0])) {
        continue;
      }
      bool has_row = false;
      for (const SensorCar& row : rows) has_row = has_row || row.id == f.id;
      if (has_row) continue;
      const map::FrenetPoint p = line_->ToFrenet(f.x[0], f.y[0], ego_s);
      if (!std::isfinite(p.s) || !std::isfinite(p.d) || !OnRoad(p.s, p.d)) continue;
      if (std::abs(line_->DiffS(p.s, line_->WrapS(ego_s))) > options_.range) continue;
      const int slot = static_cast<int>(cars_.size());
      if (!LoadFuture(f.id, {&f, 1}, slot, p.s, ego_s, /*to_come=*/true)) continue;
      TrackedCar car;
      car.id = f.id;
      car.s = kAbsentS;
      car.d = p.d;
      car.d_target = p.d;
      car.length = f.length > 0 && std::isfinite(f.length) ? f.length : options_.car_length;
      car.width = f.width > 0 && std::isfinite(f.width) ? f.width : options_.car_width;
      car.recorded = true;
      car.appears = f.start;
      cars_.push_back(car);
      slot_.push_back(slot);
    }
  }

  // Loads the future of car `id` (if `futures` has a usable one) into `slot`, s relative to
  // ego_s as TrackedCar::s; line_s is the car's line coordinate now (the projections' hint).
  // A car there now (to_come false) takes a future that starts now only; a car to come one
  // that starts later.
  bool LoadFuture(int id, std::span<const CarFuture> futures, int slot, double line_s,
                  double ego_s, bool to_come = false) {
    const CarFuture* fut = nullptr;
    for (const CarFuture& f : futures) {
      if (f.id == id && (f.start > 0) == to_come) fut = &f;
    }
    if (fut == nullptr || slot >= static_cast<int>(fut_n_.size()) || !(fut->dt > 0) ||
        !std::isfinite(fut->dt) || !(fut->start >= 0) || !std::isfinite(fut->start)) {
      return false;
    }
    // Every stride-th sample up to the horizon (and the last one before it): the predictions
    // between are interpolated, ~1 cm off over 0.2 s of a recorded car.
    const int given = static_cast<int>(
        std::min({fut->x.size(), fut->y.size(), fut->v.size(), fut->heading.size()}));
    const int stride = std::max(1, static_cast<int>(std::lround(kFutureStep / fut->dt)));
    const int wanted = static_cast<int>(std::ceil(options_.future_horizon / (stride * fut->dt))) + 1;
    const int n = std::min({(given + stride - 1) / stride, wanted, kMaxFutureSamples});
    if (n < 1) return false;
    // Every sample of the stretch used must be finite, the skipped ones too.
    for (int q = 0; q < std::min(given, (n - 1) * stride + 1); ++q) {
      if (!std::isfinite(fut->x[q]) || !std::isfinite(fut->y[q]) || !std::isfinite(fut->v[q]) ||
          !std::isfinite(fut->heading[q])) {
        return false;
      }
    }
    const double ego_w = line_->WrapS(ego_s);
    double hint = line_s;
    const int base = slot * kMaxFutureSamples;
    memo_.BeginCar(id);
    for (int k = 0; k < n; ++k) {
      const int q = std::min(k * stride, given - 1);
      const double x = fut->x[q], y = fut->y[q], v = fut->v[q], h = fut->heading[q];  // finite
      // The projection from the hint, or the same one kept from an earlier cycle.
      const int hint_sample = line_->HintSample(hint);
      ProjectionMemo::Entry e;
      if (const ProjectionMemo::Entry* kept = memo_.Find(x, y, hint_sample); kept != nullptr) {
        e = *kept;
      } else {
        const map::FrenetPoint f = line_->ToFrenet(x, y, hint);
        e = {x, y, hint_sample, f.s, f.d, line_->At(f.s).heading, NAN, 0, 0};
      }
      if (std::bit_cast<std::uint64_t>(e.h) != std::bit_cast<std::uint64_t>(h)) {
        const double rel = e.line_heading - h;  // the car's heading against the line's
        e.h = h;
        e.cos_rel = std::cos(rel);
        e.sin_rel = std::sin(rel);
      }
      memo_.Add(e);
      hint = e.s;
      fut_s_[base + k] = line_->DiffS(e.s, ego_w);
      fut_d_[base + k] = e.d;
      fut_v_[base + k] = v * e.cos_rel;
      fut_vd_[base + k] = v * e.sin_rel;  // d is to the right: a heading right of the line
    }
    // The last sample kept may be one the stride overshot (the recording's end): its time.
    fut_n_[slot] = n;
    fut_dt_[slot] = fut->dt * stride;
    fut_t0_[slot] = fut->start;
    if (n >= 2 && (n - 1) * stride > given - 1) {
      // Rare (a recording that ends off the stride): keep only the samples on it.
      fut_n_[slot] = n - 1;
    }
    return true;
  }

  // A recorded car t s after the observation: its samples interpolated, then straight on at
  // the last one's speed.
  Prediction FromFuture(int slot, double t) const {
    const int base = slot * kMaxFutureSamples, n = fut_n_[slot];
    Prediction p;
    if (t < fut_t0_[slot]) {  // a car to come, not there yet
      p.s = kAbsentS;
      p.d = fut_d_[base];
      return p;
    }
    const double x = std::max(t - fut_t0_[slot], 0.0) / fut_dt_[slot];
    if (x >= n - 1) {
      const double extra = (x - (n - 1)) * fut_dt_[slot];
      p.v = fut_v_[base + n - 1];
      p.v_d = fut_vd_[base + n - 1];
      p.s = fut_s_[base + n - 1] + p.v * extra;
      p.d = fut_d_[base + n - 1] + p.v_d * extra;
      return p;
    }
    const int k = static_cast<int>(x);
    const double f = x - k;
    auto lerp = [&](const std::vector<double>& a) {
      return a[base + k] + f * (a[base + k + 1] - a[base + k]);
    };
    p.s = lerp(fut_s_);
    p.d = lerp(fut_d_);
    p.v = lerp(fut_v_);
    p.v_d = lerp(fut_vd_);
    return p;
  }

  // Per lane, once: where a lane drop (map::Road::Drops) ends, and the centres there of its
  // neighbours that go on past the end (NaN: none). The road does not change.
  struct Merge {
    double end = NAN;
    double to[2] = {NAN, NAN};  // the left and the right neighbour's centre
  };
  void FindMerges() {
    merges_.assign(road_->num_lanes(), Merge{});
    for (int l = 0; l < road_->num_lanes(); ++l) {
      if (!road_->Drops(l)) continue;
      Merge& m = merges_[l];
      m.end = road_->LaneEnd(l);
      for (int side = 0; side < 2; ++side) {
        const int n = side == 0 ? l - 1 : l + 1;
        const map::Road::Span span = road_->LaneAt(n, m.end - kMergeSlack);
        if (span.exists && road_->LaneEnd(n) > m.end + kMergeSlack) m.to[side] = span.centre();
      }
    }
  }

  // PredictorOptions::merge_time: a car at line coordinate s whose lane drops ahead moves into
  // the neighbouring lane that goes on (the nearer one when both do): car.d_target, v_d and
  // lat_delay set for Predict's lateral move.
  void PredictMerge(double s, TrackedCar& car) const {
    if (merges_.empty() || !(car.v_s > 0.5)) return;
    const int lane = road_->LaneOf(s, car.d);
    if (lane < 0) return;
    const Merge& m = merges_[lane];
    if (std::isnan(m.end)) return;
    const double t_end = std::max(m.end - s - 0.5 * car.length, 0.0) / car.v_s;
    if (!(t_end <= options_.future_horizon)) return;
    double target = m.to[0];
    if (std::isnan(target) || std::abs(m.to[1] - car.d) < std::abs(target - car.d)) {
      target = m.to[1];
    }
    if (std::isnan(target)) return;
    // A car at the end already (or nearly) still takes kMinMergeTime to move over, not a jump.
    const double move = std::max(std::min(options_.merge_time, t_end), kMinMergeTime);
    car.d_target = target;
    car.v_d = (target - car.d) / move;
    car.lat_delay = std::max(t_end - options_.merge_time, 0.0);
  }

  // The centre of the next lane in the direction of a lateral move faster than the threshold,
  // or d itself (no move predicted, or a move away from that centre: wander). s: the car's line
  // coordinate.
  double LateralTarget(double s, double d, double v_d) const {
    if (!(std::abs(v_d) > options_.lateral_threshold)) return d;
    if (!road_->uniform()) {
      const double centre = road_->CentreToward(s, d, v_d);
      return std::isnan(centre) ? d : centre;
    }
    const double w = options_.lane_width;
    const int last = std::max(options_.num_lanes, 1) - 1;
    const double ahead = d + std::copysign(0.5 * w + 0.01, v_d);
    const int lane = std::clamp(static_cast<int>(std::floor(ahead / w)), 0, last);
    const double centre = (lane + 0.5) * w;
    return (centre - d) * v_d > 0 ? centre : d;
  }

  std::shared_ptr<const map::Road> road_;
  std::shared_ptr<const map::ReferenceLine> line_;
  // m: a merge's neighbour must go on this far past the drop's end (and is read this far
  // before it).
  static constexpr double kMergeSlack = 5.0;
  std::vector<Merge> merges_;  // per lane (empty: no merges predicted)
  static constexpr double kMinMergeTime = 1.0;  // s: the quickest move over predicted
  PredictorOptions options_;
  bool manoeuvres_;
  std::vector<TrackedCar> cars_;
  std::vector<int> slot_;  // per car: its future's slot, -1 when predicted
  // Recorded futures, kMaxFutureSamples per slot: s (relative, as TrackedCar::s), d, speeds.
  std::vector<double> fut_s_, fut_d_, fut_v_, fut_vd_, fut_dt_;
  std::vector<double> fut_t0_;  // s: the future's first sample (> 0: a car to come)
  std::vector<int> fut_n_;
  std::vector<Memory> memory_;
  // Cars that gave a ghost last time, with the time they were first seen so (NaN: unknown).
  std::vector<std::pair<int, double>> ghost_seen_, ghost_seen_next_;
  ProjectionMemo memo_;  // LoadFuture's projections, kept for the next two cycles
};

}  // namespace

std::unique_ptr<Predictor> MakeConstantVelocityPredictor(std::shared_ptr<const map::Road> road,
                                                         const PredictorOptions& options) {
  return std::make_unique<TrafficPredictor>(std::move(road), options, false);
}

std::unique_ptr<Predictor> MakeManoeuvrePredictor(std::shared_ptr<const map::Road> road,
                                                  const PredictorOptions& options) {
  return std::make_unique<TrafficPredictor>(std::move(road), options, true);
}

std::unique_ptr<Predictor> MakeConstantVelocityPredictor(
    std::shared_ptr<const map::ReferenceLine> line, const PredictorOptions& options) {
  return MakeConstantVelocityPredictor(
      map::Road::Uniform(std::move(line), options.num_lanes, options.lane_width), options);
}

std::unique_ptr<Predictor> MakeManoeuvrePredictor(std::shared_ptr<const map::ReferenceLine> line,
                                                  const PredictorOptions& options) {
  return MakeManoeuvrePredictor(
      map::Road::Uniform(std::move(line), options.num_lanes, options.lane_width), options);
}

}  // namespace frenetic::plan

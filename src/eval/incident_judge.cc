// The incident judge's search (design and coverage in incident_judge.h). Every candidate block is
// measured by the simulator's own code: IncidentMonitor, BoxesOverlap, ChordFrenet, and the
// EgoCar's float32 speed and heading arithmetic, so "incident-free" means what the simulator
// means; the rest of this file only proposes trajectories and orders them.
#include "frenetic/eval/incident_judge.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "eval/incident_judge_internal.h"
#include "frenetic/key_table.h"

namespace frenetic::sim {
namespace judge {
namespace {

constexpr double kDt = kTick;  // s
constexpr double kBlockSeconds = kBlockTicks * kDt;
// Along-lane speed cap, m/s: 49.88 mph, under the simulator's 50 mph with room for the float32
// jitter of positions (a speed still measured over 50 mph is caught by the monitor anyway).
constexpr double kSpeedCap = 22.30;
// Block accelerations, m/s^2, in the order tried when the look-ahead ties. -9.6 is as hard as
// the 10 m/s^2 total-acceleration flag allows on a straight with the float32 jitter.
constexpr std::array<double, 8> kAccels = {0, -2, -4, -6, -8, -9.6, 2, 4};
// Lateral moves: peak lateral acceleration of a rest-to-rest quintic, m/s^2 (duration
// sqrt(kQuinticPeak * |move| / peak)).
constexpr std::array<double, 4> kLateralPeaks = {9.0, 6.0, 3.5, 1.5};
constexpr double kQuinticPeak = 5.7735;  // 10 / sqrt(3): peak |d''| * T^2 / |move|
constexpr double kLaneOffset = 1.2;      // m, in-lane targets either side of the nearest centre
// Look-ahead used to order children: how long either continuation stays clear of every car.
constexpr int kLookTicks = 80;  // 1.6 s
constexpr int kLookStep = 5;

double NanToZero(double v) { return std::isnan(v) ? 0.0 : v; }

// The simulator's lane and road-edge thresholds of d (IncidentMonitor::Update).
constexpr std::array<double, 6> kLaneThresholds = {0.8, 3.2, 4.8, 7.2, 8.8, 11.2};
// m added to the reference line's bounds of the chord offset before they are trusted.
constexpr double kChordMargin = 0.3;

bool OnLaneLine(double d) { return (d > 3.2 && d < 4.8) || (d > 7.2 && d < 8.8); }

}  // namespace

bool AnyFlag(const IncidentMonitor& m) {
  for (int k = 0; k < kIncidentKinds; ++k) {
    if (m.active(static_cast<IncidentKind>(k))) return true;
  }
  return false;
}

double ChordDFromBounds(const map::ReferenceLine& line, double s, double d) {
  const map::ReferenceLine::OffsetRange r = line.ChordOffset(s, s, d);
  const double lo = d + r.lo - kChordMargin, hi = d + r.hi + kChordMargin;
  if (!std::isfinite(lo) || !std::isfinite(hi)) return std::nan("");
  for (double threshold : kLaneThresholds) {
    if (lo <= threshold && hi >= threshold) return std::nan("");
  }
  return 0.5 * (lo + hi);
}

bool MeasureTick(const World& world, const IncidentCase& c, std::int64_t tick, float x, float y,
                 float next_x, float next_y, double s, double d, EgoTick* ego,
                 IncidentMonitor* monitor) {
  // EgoCar::Tick: teleport to the point, the speed from the displacement over the tick, the
  // nose toward the next point from the pre-tick position (kept when they coincide).
  const float vx = (x - ego->x) / 0.02f, vy = (y - ego->y) / 0.02f;
  const float speed = std::sqrt(vx * vx + vy * vy);
  const float hx = next_x - ego->x, hy = next_y - ego->y;
  if (hx != 0.0f || hy != 0.0f) ego->yaw = std::atan2(static_cast<double>(hy), hx);
  ego->x = x;
  ego->y = y;
  // Simulator::Tick: the box against every car of the tick, the chord Frenet, the monitor.
  const Box box{x, y, ego->yaw, c.car_length, c.car_width};
  const double reach = std::hypot(c.car_length, c.car_width);
  TickSample sample;
  sample.x = x;
  sample.y = y;
  sample.speed = speed;
  for (const RecordedCar& car : c.CarsAt(tick)) {
    if (std::abs(car.x - x) > reach || std::abs(car.y - y) > reach) continue;
    if (BoxesOverlap(box, Box{car.x, car.y, car.heading, c.car_length, c.car_width})) {
      sample.collision_with = car.id;
      break;
    }
  }
  // The chord conversion is the costliest step: skipped when the bounds decide the flags (the
  // monitor only logs s).
  sample.d = ChordDFromBounds(*world.line, s, d);
  if (std::isnan(sample.d)) {
    const map::FrenetPoint f = world.chord->Convert(x, y);
    sample.s = NanToZero(static_cast<float>(f.s));
    sample.d = NanToZero(static_cast<float>(f.d));
  }
  monitor->Update(sample, tick * kDt);
  ego->band = OnLaneLine(sample.d) ? ego->band + 1 : 0;
  return !AnyFlag(*monitor);
}

namespace {

// d(t) from (d0, v0, a0) to (target, 0, 0) over T, then held.
struct Lateral {
  std::array<double, 6> c{};
  double duration = 0, target = 0;
  double elapsed = 0;  // s since the move began

  static Lateral Make(double d0, double v0, double a0, double target, double duration) {
    Lateral l;
    const double t = duration, t2 = t * t, t3 = t2 * t;
    const double h = target - d0;
    l.c = {d0,
           v0,
           0.5 * a0,
           (20 * h - 12 * v0 * t - 3 * a0 * t2) / (2 * t3),
           (-30 * h + 16 * v0 * t + 3 * a0 * t2) / (2 * t3 * t),
           (12 * h - 6 * v0 * t - a0 * t2) / (2 * t3 * t2)};
    l.duration = duration;
    l.target = target;
    return l;
  }
  void At(double t, double* d, double* dd, double* ddd) const {
    if (t >= duration) {
      *d = target;
      *dd = *ddd = 0;
      return;
    }
    *d = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))));
    *dd = c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5])));
    *ddd = 2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5]));
  }
};

// The ego between two blocks.
struct Node {
  explicit Node(const IncidentMonitor& m) : monitor(m) {}
  double s = 0;  // smooth-line s, unwrapped
  double u = 0;  // speed along the lane at its offset, m/s
  double d = 0, dd = 0, ddd = 0;
  Lateral lat;
  float x = 0, y = 0;  // the last tick's position, as the EgoCar holds it
  double yaw = 0;
  int band = 0;    // ticks on a lane line (chord d), as the monitor counts them
  int accel = -1;  // the last block's acceleration (index into kAccels), -1 at the start
  int moves = 0, changes = 0;  // lateral moves begun, acceleration changes made
  IncidentMonitor monitor;
};

// The passes of a search: first the trajectories with one lateral move and three acceleration
// pieces at most (most escapes are among them: found sooner, and they read well), then every
// one. -1: unlimited. The first pass's cells ignore the manoeuvres used (it need not be
// exhaustive: the second is).
struct Pass {
  int moves, changes;
};
constexpr std::array<Pass, 2> kPasses = {{{1, 2}, {-1, -1}}};

struct Action {
  int accel = 0;     // index into kAccels
  int lateral = -1;  // -1: keep the current move, else an index into the node's new moves
};

struct Child {
  Action action;
  std::uint64_t key = 0;
  int score = 0;     // look-ahead blocks clear
  int switches = 0;  // a new lateral move, an acceleration change
  int order = 0;
};

struct Step {
  double accel = 0;
  bool new_move = false;
  double target = 0, duration = 0;
};

int Bucket(double v, double step, int lo, int hi) {
  return std::clamp(static_cast<int>(std::floor(v / step)), lo, hi) - lo;
}

class Search {
 public:
  Search(const World& world, const IncidentCase& c, std::int64_t start, std::int64_t end,
         int budget)
      : world_(world), case_(c), start_(start), end_(end), budget_(budget) {
    visited_.Clear();
  }

  StartResult Run(const Node& root) {
    s0_ = root.s;
    for (const Pass& pass : kPasses) {
      pass_ = pass;
      visited_.Clear();
      path_.clear();
      if (Dfs(root, start_, 0)) return StartResult::kAvoidable;
      if (out_of_budget_) return StartResult::kUndecided;
    }
    return StartResult::kUnavoidable;
  }
  std::int64_t blocks() const { return blocks_; }
  const std::vector<Step>& path() const { return path_; }

 private:
  // The node's new lateral moves: every lane centre and 1.2 m either side of the nearest one,
  // each at every duration, from the node's lateral state.
  void NewMoves(const Node& n, std::vector<Lateral>* moves) const {
    moves->clear();
    const int lane = std::clamp(static_cast<int>(std::floor(n.d / 4.0)), 0, 2);
    const double centre = 2.0 + 4.0 * lane;
    const std::array<double, 5> targets = {2.0, 6.0, 10.0, centre - kLaneOffset,
                                           centre + kLaneOffset};
    for (double target : targets) {
      // Already there and still: that move is the node's own (held) one.
      if (std::abs(target - n.d) < 0.05 && std::abs(n.dd) < 0.05) continue;
      const double h = std::max(std::abs(target - n.d), 0.3);
      for (double peak : kLateralPeaks) {
        const double duration = std::max(0.6, std::sqrt(kQuinticPeak * h / peak));
        moves->push_back(Lateral::Make(n.d, n.dd, n.ddd, target, duration));
      }
    }
  }

  // The end state of a block, estimated without simulating it: the transposition key.
  std::uint64_t Key(const Node& n, int layer, int accel, const Lateral& lat, int ticks) const {
    const double t = ticks * kDt;
    double d, dd, ddd;
    lat.At(lat.elapsed + t, &d, &dd, &ddd);
    const double a = kAccels[accel];
    const double u = std::clamp(n.u + a * t, 0.0, kSpeedCap);
    const double s = n.s + 0.5 * (n.u + u) * t - s0_;
    const int band = OnLaneLine(d) ? n.band + ticks : 0;
    std::uint64_t k = static_cast<std::uint64_t>(layer & 31);
    auto put = [&](int value, int bits) { k = (k << bits) | static_cast<std::uint64_t>(value); };
    put(Bucket(s, 1.0, 0, 1023), 10);
    put(Bucket(u, 0.5, 0, 63), 6);
    put(Bucket(d, 0.4, -16, 47), 6);
    put(Bucket(dd, 0.8, -16, 15), 5);
    put(accel, 3);
    put(std::min(band / 25, 7), 3);
    return k;
  }

  // Ticks until the ego, continuing this block's action or braking at 8 m/s^2 (its lateral
  // move continued), would first come near a car's box; kLookTicks when it never does.
  int LookAhead(const Node& n, std::int64_t tick, int accel, const Lateral& lat, int ticks) const {
    const map::ReferenceLine& line = *world_.line;
    const double near_s = case_.car_length + 0.4, near_d = case_.car_width + 0.2;
    int best = 0;
    for (double a_after : {kAccels[accel], -8.0}) {
      double s = n.s, u = n.u;
      int clear = kLookTicks;
      for (int i = kLookStep; i <= ticks + kLookTicks; i += kLookStep) {
        const double a = i <= ticks ? kAccels[accel] : a_after;
        const double u_next = std::clamp(u + a * kLookStep * kDt, 0.0, kSpeedCap);
        s += 0.5 * (u + u_next) * kLookStep * kDt;
        u = u_next;
        const std::int64_t k = tick + i;
        if (k > end_) break;
        if (i <= ticks) continue;  // the block itself is simulated exactly
        double d, dd, ddd;
        lat.At(lat.elapsed + i * kDt, &d, &dd, &ddd);
        bool hit = false;
        for (const RecordedCar& car : case_.CarsAt(k)) {
          if (std::abs(car.d - d) < near_d && std::abs(line.DiffS(car.s, s)) < near_s) {
            hit = true;
            break;
          }
        }
        if (hit) {
          clear = i - ticks - kLookStep;
          break;
        }
      }
      best = std::max(best, clear);
    }
    return best;
  }

  // Drives `ticks` ticks from `from` with the acceleration and lateral move through the
  // simulator's measures. False at the first tick with a flag up.
  bool Simulate(const Node& from, std::int64_t tick, int ticks, double accel, const Lateral& lat,
                Node* out) {
    ++blocks_;
    const map::ReferenceLine& line = *world_.line;
    std::array<float, kBlockTicks + 2> px, py;
    std::array<double, kBlockTicks + 2> ds, dd_s;  // smooth-line s and d of every tick
    px[0] = from.x;
    py[0] = from.y;
    double s = from.s, u = from.u, d = 0, dd = 0, ddd = 0;
    // One tick beyond the block (same action) gives the last tick's heading.
    for (int i = 1; i <= ticks + 1; ++i) {
      lat.At(lat.elapsed + i * kDt, &d, &dd, &ddd);
      const double ceiling = std::sqrt(std::max(0.0, kSpeedCap * kSpeedCap - dd * dd));
      u = std::clamp(u + accel * kDt, 0.0, ceiling);
      const double scale = std::max(0.2, 1.0 + line.At(s).kappa * d);
      s += u / scale * kDt;
      const map::CartesianPose p = line.ToCartesian(s, d);
      px[i] = static_cast<float>(p.x);
      py[i] = static_cast<float>(p.y);
      ds[i] = s;
      dd_s[i] = d;
      if (i == ticks) {
        out->s = s;
        out->u = u;
        out->d = d;
        out->dd = dd;
        out->ddd = ddd;
      }
    }
    out->lat = lat;
    out->lat.elapsed += ticks * kDt;
    out->monitor = from.monitor;
    EgoTick ego{from.x, from.y, from.yaw, from.band};
    for (int i = 1; i <= ticks; ++i) {
      if (!MeasureTick(world_, case_, tick + i, px[i], py[i], px[i + 1], py[i + 1], ds[i], dd_s[i],
                       &ego, &out->monitor)) {
        return false;
      }
    }
    out->x = ego.x;
    out->y = ego.y;
    out->yaw = ego.yaw;
    out->band = ego.band;
    return true;
  }

  bool Dfs(const Node& node, std::int64_t tick, int layer) {
    if (tick >= end_) return true;
    const int ticks = static_cast<int>(std::min<std::int64_t>(kBlockTicks, end_ - tick));
    std::vector<Lateral> moves;
    NewMoves(node, &moves);
    std::vector<Child> children;
    children.reserve(kAccels.size() * (moves.size() + 1));
    for (int lat = -1; lat < static_cast<int>(moves.size()); ++lat) {
      const Lateral& move = lat < 0 ? node.lat : moves[lat];
      const int used_moves = node.moves + (lat >= 0);
      if (pass_.moves >= 0 && used_moves > pass_.moves) break;
      for (int a = 0; a < static_cast<int>(kAccels.size()); ++a) {
        if (node.u <= 0 && kAccels[a] < 0) continue;  // standing: 0 is the one way to stand
        const bool change = node.accel >= 0 && a != node.accel;
        const int used_changes = node.changes + change;
        if (pass_.changes >= 0 && used_changes > pass_.changes) continue;
        Child c;
        c.action = {a, lat};
        c.key = Key(node, layer, a, move, ticks);
        if (visited_.Contains(c.key)) continue;
        c.switches = (lat >= 0) + change;
        c.order = static_cast<int>(children.size());
        children.push_back(c);
      }
    }
    for (Child& c : children) {
      const Lateral& move = c.action.lateral < 0 ? node.lat : moves[c.action.lateral];
      // In whole blocks, so that among children about as clear the simpler goes first.
      c.score = LookAhead(node, tick, c.action.accel, move, ticks) / kBlockTicks;
    }
    std::sort(children.begin(), children.end(), [](const Child& a, const Child& b) {
      if (a.score != b.score) return a.score > b.score;
      return a.switches != b.switches ? a.switches < b.switches : a.order < b.order;
    });
    Node child(node.monitor);
    for (const Child& c : children) {
      if (!visited_.Insert(c.key)) continue;  // reached meanwhile by a deeper branch
      if (blocks_ >= budget_) {
        out_of_budget_ = true;
        return false;
      }
      const bool new_move = c.action.lateral >= 0;
      const Lateral& move = new_move ? moves[c.action.lateral] : node.lat;
      if (!Simulate(node, tick, ticks, kAccels[c.action.accel], move, &child)) continue;
      child.accel = c.action.accel;
      child.moves = node.moves + new_move;
      child.changes = node.changes + (node.accel >= 0 && c.action.accel != node.accel);
      path_.push_back({kAccels[c.action.accel], new_move, move.target, move.duration});
      if (Dfs(child, tick + ticks, layer + 1)) return true;
      path_.pop_back();
      if (out_of_budget_) return false;
    }
    return false;
  }

  const World& world_;
  const IncidentCase& case_;
  std::int64_t start_, end_;
  std::int64_t budget_;
  std::int64_t blocks_ = 0;
  bool out_of_budget_ = false;
  Pass pass_ = kPasses.back();
  double s0_ = 0;
  KeyTable visited_;
  std::vector<Step> path_;
};

// Least-squares slope and curvature of y over ticks -n..0: first and second derivative per
// second at tick 0 of the quadratic fit.
void FitRates(const double* y, int n, double* rate, double* accel) {
  // Normal equations of y = c0 + c1 t + c2 t^2 over t = -n..0.
  double s[5] = {0, 0, 0, 0, 0}, r[3] = {0, 0, 0};
  for (int j = 0; j <= n; ++j) {
    const double t = -j;
    double p = 1;
    for (int e = 0; e < 5; ++e) {
      s[e] += p;
      if (e < 3) r[e] += p * y[j];
      p *= t;
    }
  }
  const double a[3][3] = {{s[0], s[1], s[2]}, {s[1], s[2], s[3]}, {s[2], s[3], s[4]}};
  auto det3 = [](const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double det = det3(a);
  double c[3];
  for (int col = 0; col < 3; ++col) {
    double m[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m[i][j] = j == col ? r[i] : a[i][j];
    }
    c[col] = det3(m) / det;
  }
  *rate = c[1] / kDt;
  *accel = 2 * c[2] / (kDt * kDt);
}

// The ego at tick `start` of the case as the search's root; false without 0.2 s of history.
bool MakeRoot(const World& world, const IncidentCase& c, std::int64_t start, Node* root) {
  const std::int64_t i0 = start - c.first_tick;
  if (i0 < kBlockTicks || i0 >= static_cast<std::int64_t>(c.ego.size())) return false;
  const map::ReferenceLine& line = *world.line;
  const RecordedEgo& e = c.ego[i0];
  std::array<double, kBlockTicks + 1> s, d;
  for (int j = 0; j <= kBlockTicks; ++j) {
    const RecordedEgo& past = c.ego[i0 - j];
    s[j] = e.s + line.DiffS(past.s, e.s);
    d[j] = past.d;
  }
  double s_rate, s_acc, d_rate, d_acc;
  FitRates(s.data(), kBlockTicks, &s_rate, &s_acc);
  FitRates(d.data(), kBlockTicks, &d_rate, &d_acc);
  root->s = e.s;
  root->d = e.d;
  root->dd = d_rate;
  root->ddd = d_acc;
  root->u = std::max(0.0, s_rate * std::max(0.2, 1.0 + line.At(e.s).kappa * e.d));
  // The current lateral motion as a move: held where it is when it is still, else finished at
  // the lane centre it is heading for.
  if (std::abs(d_rate) < 0.2 && std::abs(d_acc) < 0.5) {
    root->lat = Lateral::Make(e.d, d_rate, d_acc, e.d, 1.0);
  } else {
    const double ahead = std::clamp(e.d + 0.8 * d_rate, 2.0, 10.0);
    const double target = 2.0 + 4.0 * std::round((ahead - 2.0) / 4.0);
    const double duration = std::max(1.0, std::sqrt(kQuinticPeak * std::abs(target - e.d) / 3.5));
    root->lat = Lateral::Make(e.d, d_rate, d_acc, target, duration);
  }
  root->x = e.x;
  root->y = e.y;
  root->yaw = e.yaw;
  // The lane-line timer, counted back over the recorded ticks (it only shapes the cells).
  root->band = 0;
  for (std::int64_t i = i0; i >= 0 && root->band <= 150; --i) {
    const map::FrenetPoint f = world.chord->Convert(c.ego[i].x, c.ego[i].y);
    if (!OnLaneLine(NanToZero(static_cast<float>(f.d)))) break;
    ++root->band;
  }
  return true;
}

std::string Escape(const std::vector<Step>& path) {
  std::string lon, lat;
  double t = 0;
  for (std::size_t i = 0; i < path.size();) {
    std::size_t j = i;
    while (j < path.size() && path[j].accel == path[i].accel) ++j;
    lon += fmt::format("{}{:g} m/s^2 {:.1f} s", lon.empty() ? "" : ", ", path[i].accel,
                       (j - i) * kBlockSeconds);
    i = j;
  }
  for (const Step& step : path) {
    if (step.new_move) {
      lat += fmt::format("{}to d {:.1f} m at +{:.1f} s over {:.2f} s", lat.empty() ? "" : ", ",
                         step.target, t, step.duration);
    }
    t += kBlockSeconds;
  }
  return "accel " + lon + (lat.empty() ? "; lane kept" : "; lateral " + lat);
}

}  // namespace

StartJudgement SearchFrom(const World& world, const IncidentCase& c, std::int64_t start,
                          std::int64_t until, int budget_blocks, std::string* escape) {
  StartJudgement sj;
  sj.t = start * kDt;
  sj.result = StartResult::kInIncident;
  const auto at = std::find(c.monitor_ticks.begin(), c.monitor_ticks.end(), start);
  if (at == c.monitor_ticks.end()) return sj;
  const IncidentMonitor& monitor = c.monitors[at - c.monitor_ticks.begin()];
  Node root(monitor);
  if (AnyFlag(monitor) || !MakeRoot(world, c, start, &root)) return sj;
  Search search(world, c, start, until, budget_blocks);
  sj.result = search.Run(root);
  sj.blocks = search.blocks();
  if (sj.result == StartResult::kAvoidable && escape != nullptr) *escape = Escape(search.path());
  return sj;
}

}  // namespace judge

using judge::kBlockSeconds;
using judge::kDt;

Status JudgeOptions::Validate() const {
  if (!(window_seconds >= kBlockSeconds && window_seconds <= 30)) {
    return Status::Error("judge window_seconds must be in [0.2, 30]");
  }
  if (!(margin_seconds >= 0 && margin_seconds <= 30)) {
    return Status::Error("judge margin_seconds must be in [0, 30]");
  }
  if (budget_blocks < 1) return Status::Error("judge budget_blocks must be >= 1");
  return Status::Ok();
}

IncidentJudgement JudgeIncident(const World& world, const IncidentCase& c,
                                const JudgeOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  IncidentJudgement j;
  j.incident_t = c.incident.t;
  if (c.ego.empty() || !options.Validate().ok()) return j;
  const std::int64_t margin = std::llround(options.margin_seconds / kDt);
  const std::int64_t window = std::llround(options.window_seconds / kDt);
  const std::int64_t end = std::min(c.incident_tick + margin, c.last_tick());
  j.until = end * kDt;
  // Starts, latest first.
  std::vector<std::size_t> starts;
  for (std::size_t i = c.monitor_ticks.size(); i-- > 0;) {
    const std::int64_t k = c.monitor_ticks[i];
    if (k >= c.incident_tick || k < c.incident_tick - window || k - c.first_tick < kBlockTicks) {
      continue;
    }
    starts.push_back(i);
  }
  std::int64_t escape_tick = -1;  // latest start found avoidable by a search
  bool any_budget = false, any_judged = false;
  for (std::size_t i : starts) {
    const std::int64_t k = c.monitor_ticks[i];
    StartJudgement sj;
    sj.t = k * kDt;
    if (judge::AnyFlag(c.monitors[i])) {
      sj.result = StartResult::kInIncident;
      j.starts.push_back(sj);
      continue;
    }
    any_judged = true;
    if (escape_tick >= 0) {
      // Driving as the ego did up to the later start, then its escape, avoids it too, if the
      // drive had no flag up in between.
      bool clean = true;
      for (std::int64_t t = k + 1; t <= escape_tick && clean; ++t) {
        clean = !c.ego[t - c.first_tick].flagged;
      }
      if (clean) {
        sj.result = StartResult::kAvoidable;
        sj.as_driven_first = true;
        j.starts.push_back(sj);
        continue;
      }
    }
    std::string escape;
    sj = judge::SearchFrom(world, c, k, end, options.budget_blocks, &escape);
    j.blocks += sj.blocks;
    if (sj.result == StartResult::kAvoidable && escape_tick < 0) {
      escape_tick = k;
      j.escape = std::move(escape);
    }
    any_budget = any_budget || sj.result == StartResult::kUndecided;
    j.starts.push_back(sj);
  }
  std::reverse(j.starts.begin(), j.starts.end());
  bool found = false;
  for (const StartJudgement& s : j.starts) {
    if (s.result != StartResult::kAvoidable) continue;
    if (!found) j.avoidable_from = s.t;
    j.last_chance = s.t;
    found = true;
  }
  if (found) {
    j.verdict = Verdict::kAvoidable;
  } else if (any_budget) {
    j.verdict = Verdict::kUndecided;
  } else if (any_judged) {
    j.verdict = Verdict::kUnavoidable;
  }
  j.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return j;
}

}  // namespace frenetic::sim

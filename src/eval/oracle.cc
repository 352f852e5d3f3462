#include "frenetic/eval/oracle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace frenetic::sim {
namespace {

constexpr double kNegInf = -std::numeric_limits<double>::infinity();
constexpr int kMaxId = 4096;  // sensor_fusion ids beyond this are not traffic the search follows
constexpr double kMaxStages = 2e5;  // a longer trace (28 h of 0.5 s stages) is not searched
constexpr double kJump = 30.0;  // m along (or 4.5 m across) between two rows: a respawn

// A car at one stage: along-road position and the lanes it is in (bit per lane).
struct StageCar {
  int id = 0;
  double s = 0;
  unsigned mask = 0;
};

struct Stage {
  double t = 0, ego_s = 0;
  int row = 0;  // the trace's row
  std::vector<StageCar> cars;
  std::vector<int> index;  // by id: into cars, or -1
};

// The traffic at every stage: the last row at or before the stage's time.
std::vector<Stage> MakeStages(const OracleTrace& trace, const OracleOptions& o, int stages) {
  const auto& rows = trace.rows();
  int max_id = -1;
  for (const OracleTrace::Car& c : trace.cars()) max_id = std::max(max_id, c.id);
  std::vector<Stage> out(stages + 1);
  std::size_t r = 0;
  for (int k = 0; k <= stages; ++k) {
    Stage& st = out[k];
    st.t = rows.front().t + k * o.step;
    while (r + 1 < rows.size() && rows[r + 1].t <= st.t + 1e-9) ++r;
    st.ego_s = rows[r].ego_s;
    st.row = static_cast<int>(r);
    st.index.assign(max_id + 1, -1);
    for (std::size_t i = rows[r].first; i < rows[r].first + rows[r].count; ++i) {
      const OracleTrace::Car& c = trace.cars()[i];
      if (c.since < o.spawn_grace) continue;
      unsigned mask = 0;
      for (int l = 0; l < o.lanes; ++l) {
        if (std::abs(c.d - (l + 0.5) * o.lane_width) < o.lane_reach) mask |= 1u << l;
      }
      if (mask == 0) continue;
      st.index[c.id] = static_cast<int>(st.cars.size());
      st.cars.push_back({c.id, c.s, mask});
    }
  }
  return out;
}

// No car in the way of the ego moving from (lanes `ma`, s0) at stage a to (lanes `mb`, s1) at
// stage b. Of the cars in b's lanes:
// - one behind the ego at a in a lane they shared is a follower, which brakes for it (skipped),
//   and so is one ahead there moving away at least as fast;
// - any other blocks it from `gap` behind s1 to `gap` + headway x v1 ahead;
// - one in a lane the ego moves into, behind it, needs `room_behind` more, plus closing_time of
//   the speed it closes in with;
// - one it has passed in a lane they shared, it drove through.
bool Free(const Stage& a, const Stage& b, unsigned ma, unsigned mb, double s0, double s1,
          double v1, double step, const OracleOptions& o) {
  const double gap = o.gap, ahead = o.gap + o.headway * v1;
  for (const StageCar& cb : b.cars) {
    const unsigned m = cb.mask & mb;
    if (m == 0) continue;
    const double ds1 = cb.s - s1;
    const int ia = cb.id < static_cast<int>(a.index.size()) ? a.index[cb.id] : -1;
    const StageCar* ca = ia >= 0 ? &a.cars[ia] : nullptr;
    const bool shared = ca != nullptr && (ca->mask & ma & m) != 0;
    const double ds0 = ca != nullptr ? ca->s - s0 : 0;
    if (shared && ds0 < 0) continue;  // a follower
    // Ahead in a lane they shared and at least as fast: pulling away (never closing into its
    // body), or a follower that the record shows overtaking, where it would have stayed behind.
    if (shared && ds1 > 0 && (ds1 >= gap || ds0 < gap) && (cb.s - ca->s) >= v1 * step - 1e-6) {
      continue;
    }
    if (ds1 > -gap && ds1 < ahead) return false;
    // Moving into its lane in front of it: room behind, plus a second of its closing speed.
    if (!shared && ds1 < 0) {
      const double closing = ca != nullptr ? std::max(0.0, (cb.s - ca->s) / step - v1) : 0.0;
      if (ds1 > -(gap + o.room_behind + closing * o.closing_time)) return false;
    }
    if (shared && ds1 <= -gap) return false;  // driven through
  }
  return true;
}

}  // namespace

Status OracleOptions::Validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!(step >= 0.05 && step <= 5)) {
    return Status::Error("oracle step must be 0.05..5 s, got " + std::to_string(step));
  }
  if (!(top_speed > 0 && top_speed <= 100)) return Status::Error("oracle top_speed must be in (0, 100] m/s");
  if (!(speed_bin >= 0.1) || speed_bin > top_speed) {
    return Status::Error("oracle speed_bin must be in [0.1, top_speed] m/s");
  }
  if (!positive(max_accel) || !positive(max_decel)) {
    return Status::Error("oracle max_accel and max_decel must be > 0 m/s^2");
  }
  if (!(s_bin >= 0.05 && s_bin <= 10)) return Status::Error("oracle s_bin must be 0.05..10 m");
  if (!positive(gap)) return Status::Error("oracle gap must be > 0 m");
  if (!positive(lane_width)) return Status::Error("oracle lane_width must be > 0 m");
  if (lanes < 1 || lanes > 16) return Status::Error("oracle lanes must be 1..16");
  if (!positive(lane_reach)) return Status::Error("oracle lane_reach must be > 0 m");
  if (!(spawn_grace >= 0)) return Status::Error("oracle spawn_grace must be >= 0 s");
  if (!(behind > 0 && behind <= 1000)) return Status::Error("oracle behind must be in (0, 1000] m");
  if (!(horizon > 0 && horizon <= 120)) return Status::Error("oracle horizon must be in (0, 120] s");
  if (!(foresight == 0 || (foresight >= step && foresight <= 120))) {
    return Status::Error("oracle foresight must be 0 or from one step to 120 s");
  }
  if (!(headway >= 0)) return Status::Error("oracle headway must be >= 0 s");
  if (!(room_behind >= 0) || !(closing_time >= 0)) {
    return Status::Error("oracle room_behind and closing_time must be >= 0");
  }
  if (!(change >= 3 * step && change <= 30)) {
    return Status::Error("oracle change must be 3 steps..30 s");
  }
  return Status::Ok();
}

void OracleTrace::Add(double t, double ego_s, double ego_d, double ego_speed,
                      std::span<const plan::SensorCar> cars) {
  auto wrap = [this](double ds) {
    if (!(max_s_ > 0)) return ds;
    ds = std::fmod(ds, max_s_);
    if (ds >= 0.5 * max_s_) ds -= max_s_;
    if (ds < -0.5 * max_s_) ds += max_s_;
    return ds;
  };
  if (!std::isfinite(t) || !std::isfinite(ego_s) || !std::isfinite(ego_d) ||
      !std::isfinite(ego_speed) || std::abs(ego_d) > 1e4 || (!rows_.empty() && t <= rows_.back().t)) {
    return;
  }
  Row row;
  row.t = t;
  row.ego_s = rows_.empty() ? 0.0 : rows_.back().ego_s + wrap(ego_s - raw_ego_s_);
  raw_ego_s_ = ego_s;
  row.ego_d = ego_d;
  row.ego_speed = ego_speed;
  row.first = cars_.size();
  for (const plan::SensorCar& c : cars) {
    if (c.id < 0 || c.id >= kMaxId || !std::isfinite(c.s) || !std::isfinite(c.d)) continue;
    if (static_cast<int>(last_.size()) <= c.id) last_.resize(c.id + 1);
    Last& last = last_[c.id];
    const double s = row.ego_s + wrap(c.s - ego_s);
    if (!last.seen || std::abs(s - last.s) > kJump + 30.0 * (t - last.t) ||
        std::abs(c.d - last.d) > 4.5) {
      last.appeared = t;
    }
    last.seen = true;
    last.t = t;
    last.s = s;
    last.d = c.d;
    cars_.push_back({c.id, s, c.d, t - last.appeared});
  }
  row.count = cars_.size() - row.first;
  rows_.push_back(row);
}

namespace {

// The search over stages k0..k1 from the ego's state as it drove at k0: the farthest s reached
// at k1 (-inf when every move from there is blocked).
class Search {
 public:
  Search(const std::vector<Stage>& st, const OracleTrace& trace, const OracleOptions& o)
      : st_(st), trace_(trace), o_(o) {
    for (int i = 0; i * o.speed_bin < o.top_speed - 1e-9; ++i) speeds_.push_back(i * o.speed_bin);
    speeds_.push_back(o.top_speed);
    nv_ = static_cast<int>(speeds_.size());
    next_.resize(nv_);
    for (int i = 0; i < nv_; ++i) {
      for (int j = 0; j < nv_; ++j) {
        const double dv = speeds_[j] - speeds_[i];
        if (dv <= o.max_accel * o.step + 1e-9 && -dv <= o.max_decel * o.step + 1e-9) {
          next_[i].push_back(j);
        }
      }
    }
    // States: in lane l (0..lanes-1), or changing from lane i to i+1 (right) or back (left),
    // at phase 1..np of the change: lanes + (2i + left) np + phase - 1. The change's first third
    // is in its first lane, the middle astride both, the last in the other.
    nl_ = o.lanes;
    np_ = std::max(1, static_cast<int>(std::lround(o.change / o.step)));
    ng_ = nl_ + 2 * (nl_ - 1) * np_;
    occupies_.resize(ng_);
    lands_.resize(ng_);
    astride_.assign(ng_, false);
    for (int g = 0; g < ng_; ++g) {
      if (g < nl_) {
        occupies_[g] = 1u << g;
        lands_[g] = g;
      } else {
        const int move = (g - nl_) / np_, i = move / 2, phase = (g - nl_) % np_ + 1;
        const int from = move % 2 == 0 ? i : i + 1, to = move % 2 == 0 ? i + 1 : i;
        lands_[g] = to;
        if (3 * phase <= np_) {
          occupies_[g] = 1u << from;
        } else if (3 * phase <= 2 * np_) {
          occupies_[g] = 3u << i;
          astride_[g] = true;
        } else {
          occupies_[g] = 1u << to;
        }
      }
    }
  }

  // A state of the search: its lane (or lane change and phase), speed index and s.
  struct State {
    int g = 0, v = 0;
    double s = 0;
  };
  // The ego's state as it drove at stage k.
  State Driven(int k) const {
    const OracleTrace::Row& r0 = trace_.rows()[st_[k].row];
    State x;
    x.g = std::clamp(static_cast<int>(std::floor(r0.ego_d / o_.lane_width)), 0, nl_ - 1);
    for (int i = 0; i < nv_; ++i) {
      if (std::abs(speeds_[i] - r0.ego_speed) < std::abs(speeds_[x.v] - r0.ego_speed)) x.v = i;
    }
    x.s = st_[k].ego_s;
    return x;
  }

  // The farthest s reached at k1 from the ego's state as it drove at k0, and in *lanes the
  // path's lane at each stage after k0 (a digit, or '/' astride).
  double Run(int k0, int k1, std::string* lanes, std::vector<double>* speeds) {
    return RunFrom(k0, k1, Driven(k0), lanes, speeds, nullptr);
  }

  // The same from state x at stage k0 (-inf when every way is blocked before k1); with `first`,
  // the best path's state at k0 + 1.
  double RunFrom(int k0, int k1, const State& x, std::string* lanes, std::vector<double>* speeds,
                 State* first) {
    parents_.clear();
    double lo = 0, lo1 = 0;
    int bins = 0, bins1 = 0;
    start_s_ = x.s;
    Window(k0, k0, &lo, &bins);
    cur_.assign(static_cast<std::size_t>(ng_) * nv_ * bins, kNegInf);
    const double s_start = x.s;
    cur_[(static_cast<std::size_t>(x.g) * nv_ + x.v) * bins +
         std::clamp(static_cast<int>((s_start - lo) / o_.s_bin), 0, bins - 1)] = s_start;
    std::vector<int> cell_count;
    cell_count.push_back(bins);
    int succ[3];
    for (int k = k0; k < k1; ++k) {
      Window(k0, k + 1, &lo1, &bins1);
      nxt_.assign(static_cast<std::size_t>(ng_) * nv_ * bins1, kNegInf);
      parents_.emplace_back(nxt_.size(), -1);
      std::vector<int>& parent = parents_.back();
      cell_count.push_back(bins1);
      const Stage& a = st_[k];
      const Stage& b = st_[k + 1];
      for (int g = 0; g < ng_; ++g) {
        const int ns = Successors(g, succ);
        for (int i = 0; i < nv_; ++i) {
          const double* row = &cur_[(static_cast<std::size_t>(g) * nv_ + i) * bins];
          for (int bi = 0; bi < bins; ++bi) {
            const double s0 = row[bi];
            if (s0 == kNegInf) continue;
            for (int j : next_[i]) {
              const double s1 = s0 + 0.5 * (speeds_[i] + speeds_[j]) * o_.step;
              if (s1 < lo1) continue;
              const int bj = std::min(static_cast<int>((s1 - lo1) / o_.s_bin), bins1 - 1);
              for (int n = 0; n < ns; ++n) {
                const int h = succ[n];
                const std::size_t at = (static_cast<std::size_t>(h) * nv_ + j) * bins1 + bj;
                if (s1 <= nxt_[at]) continue;
                if (!Free(a, b, occupies_[g], occupies_[h], s0, s1, speeds_[j], o_.step, o_)) continue;
                nxt_[at] = s1;
                parent[at] = static_cast<int>((static_cast<std::size_t>(g) * nv_ + i) * bins + bi);
              }
            }
          }
        }
      }
      if (k == k0 && first != nullptr) first_ = nxt_;
      cur_.swap(nxt_);
      lo = lo1;
      bins = bins1;
    }
    double best = kNegInf;
    std::size_t best_at = 0;
    for (std::size_t c = 0; c < cur_.size(); ++c) {
      if (cur_[c] > best) {
        best = cur_[c];
        best_at = c;
      }
    }
    if (first != nullptr && best != kNegInf) {
      long at = static_cast<long>(best_at);
      for (std::size_t k = parents_.size(); k-- > 1 && at >= 0;) at = parents_[k][at];
      const int cells = cell_count[1];
      first->g = static_cast<int>(at / (static_cast<long>(nv_) * cells));
      first->v = static_cast<int>((at / cells) % nv_);
      first->s = first_[at];
    }
    if (lanes != nullptr) {
      lanes->assign(parents_.size(), '?');
      speeds->assign(parents_.size(), std::numeric_limits<double>::quiet_NaN());
      if (best != kNegInf) {
        long at = static_cast<long>(best_at);
        for (std::size_t k = parents_.size(); k-- > 0 && at >= 0;) {
          const int g = static_cast<int>(at / (static_cast<long>(nv_) * cell_count[k + 1]));
          (*lanes)[k] = astride_[g] ? '/' : static_cast<char>('0' + __builtin_ctz(occupies_[g]));
          (*speeds)[k] = speeds_[(at / cell_count[k + 1]) % nv_];
          at = parents_[k][at];
        }
      }
    }
    return best;
  }

 private:
  int Successors(int g, int* out) const {
    int n = 0;
    if (g >= nl_) {
      const int phase = (g - nl_) % np_ + 1;
      out[n++] = phase < np_ ? g + 1 : lands_[g];
      return n;
    }
    out[n++] = g;
    if (g + 1 < nl_) out[n++] = nl_ + 2 * g * np_;            // right, to g + 1
    if (g > 0) out[n++] = nl_ + (2 * (g - 1) + 1) * np_;     // left, to g - 1
    return n;
  }

 public:
  char LaneChar(int g) const {
    return astride_[g] ? '/' : static_cast<char>('0' + __builtin_ctz(occupies_[g]));
  }
  double Speed(int v) const { return speeds_[v]; }

 private:
  // Stage k's positions: from `behind` m behind the ego as driven to the farthest reachable.
  // Both ends within what is reachable from the search's start, whatever the ego's s did.
  void Window(int k0, int k, double* lo, int* bins) const {
    const double start = start_s_;
    const double hi = start + o_.top_speed * (k - k0) * o_.step + o_.s_bin;
    *lo = std::clamp(st_[k].ego_s - o_.behind, start - o_.s_bin, hi - o_.s_bin);
    *bins = static_cast<int>(std::ceil((hi - *lo) / o_.s_bin)) + 1;
  }

  const std::vector<Stage>& st_;
  const OracleTrace& trace_;
  const OracleOptions& o_;
  std::vector<double> speeds_;
  int nv_ = 0, nl_ = 0, np_ = 1, ng_ = 0;
  std::vector<std::vector<int>> next_;
  std::vector<unsigned> occupies_;
  std::vector<int> lands_;
  std::vector<bool> astride_;
  std::vector<double> cur_, nxt_, first_;
  double start_s_ = 0;  // the s the search starts from
  std::vector<std::vector<int>> parents_;  // per stage searched: each cell's cell before
};

}  // namespace

OracleResult SearchOracle(const OracleTrace& trace, const OracleOptions& o) {
  OracleResult result;
  const auto& rows = trace.rows();
  if (rows.size() < 2 || !o.Validate().ok()) return result;
  const double span = (rows.back().t - rows.front().t) / o.step;
  if (!(span >= 1) || span > kMaxStages) return result;
  const int stages = static_cast<int>(std::floor(span + 1e-9));
  const std::vector<Stage> st = MakeStages(trace, o, stages);
  Search search(st, trace, o);
  const int per_window = std::max(1, static_cast<int>(std::lround(o.horizon / o.step)));
  const int ahead = std::max(1, static_cast<int>(std::lround(o.foresight / o.step)));
  for (int k0 = 0; k0 < stages; k0 += per_window) {
    const int k1 = std::min(stages, k0 + per_window);
    OracleWindow w;
    w.t = st[k0].t;
    w.driven_m = st[k1].ego_s - st[k0].ego_s;
    double best = kNegInf;
    if (o.foresight > 0) {
      // Receding: plan `ahead` stages (fewer near the window's end), take the first. No way
      // that far from x: every way from x ends within it (up to the bins), the window is stuck.
      Search::State x = search.Driven(k0);
      for (int k = k0; k < k1; ++k) {
        Search::State next;
        if (search.RunFrom(k, std::min(k + ahead, k1), x, nullptr, nullptr, &next) == kNegInf) {
          w.stuck_stage = k - k0;
          ++result.stuck_windows;
          break;
        }
        x = next;
        w.lanes.push_back(search.LaneChar(x.g));
        w.speeds.push_back(search.Speed(x.v));
      }
      w.search_m = x.s - st[k0].ego_s;
      best = w.stuck_stage < 0 ? x.s : kNegInf;
    } else {
      best = search.Run(k0, k1, &w.lanes, &w.speeds);
      w.search_m = best == kNegInf ? -1.0 : best - st[k0].ego_s;
    }
    w.best_m = std::max(w.driven_m, best - st[k0].ego_s);
    for (int k = k0 + 1; k <= k1; ++k) {
      const double d = trace.rows()[st[k].row].ego_d;
      w.driven_lanes.push_back(
          static_cast<char>('0' + std::clamp(static_cast<int>(std::floor(d / o.lane_width)), 0, 9)));
    }
    result.distance_m += w.best_m;
    result.driven_m += w.driven_m;
    if (w.stuck_stage < 0 && w.search_m >= 0) {
      result.through_seconds += (k1 - k0) * o.step;
      result.through_search_m += w.search_m;
      result.through_driven_m += w.driven_m;
    }
    result.windows.push_back(std::move(w));
  }
  result.seconds = stages * o.step;
  result.foresight = o.foresight > 0 ? ahead * o.step : 0.0;
  return result;
}

}  // namespace frenetic::sim

// The stages of a planning cycle alone, on the public building blocks the search planner is
// made of (its stages, src/plan/search/*.h, are private to the plan module; their in-planner
// times are the gen_us / score_us / check_us / refine_us counters of BM_Plan*): polynomial
// solves, bundle generation (solve + sample, the planner's Lattice::Generate work), cost
// scoring, the collision check, XY feasibility, Frenet <-> XY, NLopt refinement, telemetry
// parsing and control serialisation. Inputs are deterministic: a fixed start state, the default
// configuration and its cost set, traffic at fixed spacing (or a recorded message where one is
// parsed).
#include <benchmark/benchmark.h>
#include <nlopt.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "frenetic/cost/cost_set.h"
#include "frenetic/map/reference_line.h"
#include "frenetic/map/track.h"
#include "frenetic/plan/feasibility.h"
#include "frenetic/plan/planner_config.h"
#include "frenetic/traj/box.h"
#include "frenetic/traj/frenet.h"
#include "frenetic/traj/polynomial.h"
#include "frenetic/wire/protocol.h"

namespace frenetic::bench {
namespace {

constexpr double kTick = 0.02;
constexpr double kScoreDt = 0.25;
constexpr int kSamples = 25;  // score.horizon 6 s / score.dt 0.25 s + 1
constexpr int kCheckTicks = 250;  // check.horizon 5 s of 0.02 s ticks

// The candidate bundles of one cycle as the planner samples them (struct of arrays).
struct Bundles {
  std::vector<traj::Trajectory1d> lon, lat;
  std::vector<double> lon_s, lon_sd, lon_sdd, lat_d, lat_dd, lat_ddd, lon_j2, lat_j2;
};

// Everything the stage benchmarks share, built once.
struct Fixture {
  std::shared_ptr<const map::ReferenceLine> line;
  std::shared_ptr<const cost::CostSet> costs;
  traj::FrenetState start{500.0, 18.0, 0.0, 6.0, 0.0, 0.0};
  std::string error;

  static const Fixture& Get() {
    static const Fixture f = [] {
      Fixture x;
      auto line = LineFor(map::DefaultTrackPath());
      if (!line.ok()) {
        x.error = line.message();
        return x;
      }
      x.line = *line;
      auto config = plan::PlannerConfig::LoadDefault();
      if (!config.ok()) {
        x.error = config.message();
        return x;
      }
      auto costs = cost::CostSet::Build(config->cost_terms());
      if (!costs.ok()) {
        x.error = costs.message();
        return x;
      }
      x.costs = *costs;
      return x;
    }();
    return f;
  }
};

// Lattice::Generate's work for a grid shape: velocity-keeping quartics (+ stopping quintic) per
// duration and lateral quintics per lane, duration and offset, each sampled at the score times.
void Generate(const traj::FrenetState& s0, const GridShape& g, Bundles* b) {
  b->lon.clear();
  b->lat.clear();
  auto add = [](const traj::Trajectory1d& t, std::vector<traj::Trajectory1d>* out,
                std::vector<double>* p, std::vector<double>* v, std::vector<double>* a,
                std::vector<double>* j2) {
    const std::size_t i = out->size();
    out->push_back(t);
    (*j2)[i] = t.poly.JerkSquaredIntegral(t.duration);
    for (int k = 0; k < kSamples; ++k) {
      const traj::State1d st = t.At(k * kScoreDt);
      (*p)[i * kSamples + k] = st.p;
      (*v)[i * kSamples + k] = st.v;
      (*a)[i * kSamples + k] = st.a;
    }
  };
  for (int di = 0; di < g.durations; ++di) {
    const double T = 1.5 + 4.5 * di / std::max(1, g.durations - 1);
    for (int vi = 0; vi < g.speeds; ++vi) {
      const double v1 = 22.0 * vi / std::max(1, g.speeds - 1);
      add({traj::SolveQuartic(s0.s, s0.s_d, s0.s_dd, v1, 0, T), T}, &b->lon, &b->lon_s,
          &b->lon_sd, &b->lon_sdd, &b->lon_j2);
    }
    if (g.stop) {
      add({traj::SolveQuintic(s0.s, s0.s_d, s0.s_dd, s0.s + 0.5 * s0.s_d * T, 0, 0, T), T},
          &b->lon, &b->lon_s, &b->lon_sd, &b->lon_sdd, &b->lon_j2);
    }
  }
  for (int lane = 0; lane < 3; ++lane) {
    for (int ti = 0; ti < g.lat_durations; ++ti) {
      const double T = 2.0 + 2.0 * ti / std::max(1, g.lat_durations - 1);
      for (int oi = 0; oi < g.lat_offsets; ++oi) {
        const double d1 = 2.0 + 4.0 * lane + (oi - g.lat_offsets / 2) * 0.3;
        add({traj::SolveQuintic(s0.d, s0.d_d, s0.d_dd, d1, 0, 0, T), T}, &b->lat, &b->lat_d,
            &b->lat_dd, &b->lat_ddd, &b->lat_j2);
      }
    }
  }
}

void Size(const GridShape& g, Bundles* b) {
  const int n_lon = g.durations * (g.speeds + g.stop), n_lat = 3 * g.lat_durations * g.lat_offsets;
  b->lon.reserve(n_lon);
  b->lat.reserve(n_lat);
  for (auto* v : {&b->lon_s, &b->lon_sd, &b->lon_sdd}) v->assign(n_lon * kSamples, 0.0);
  for (auto* v : {&b->lat_d, &b->lat_dd, &b->lat_ddd}) v->assign(n_lat * kSamples, 0.0);
  b->lon_j2.assign(n_lon, 0.0);
  b->lat_j2.assign(n_lat, 0.0);
}

// Traffic for the cost context: `vehicles` cars over three lanes, -60 m ... +200 m around s0.
struct Traffic {
  std::vector<double> s, d, v;        // s per sample; d and v per car
  std::vector<double> d_at, v_at;     // d and v per sample (the cost context's layout)
  void Make(int vehicles, double s0) {
    s.assign(vehicles * kSamples, 0.0);
    d.assign(vehicles, 0.0);
    v.assign(vehicles, 0.0);
    d_at.assign(vehicles * kSamples, 0.0);
    v_at.assign(vehicles * kSamples, 0.0);
    for (int c = 0; c < vehicles; ++c) {
      const double u = std::fmod(0.5 + c * 0.6180339887498949, 1.0);
      d[c] = 2.0 + 4.0 * (c % 3);
      v[c] = 15.0 + (c % 7);
      const double sc = s0 - 60.0 + 260.0 * u;
      for (int k = 0; k < kSamples; ++k) {
        s[c * kSamples + k] = sc + v[c] * k * kScoreDt;
        d_at[c * kSamples + k] = d[c];
        v_at[c * kSamples + k] = v[c];
      }
    }
  }
};

cost::CostContext Context(const traj::FrenetState& s0, const Traffic& tr) {
  cost::CostContext c;
  c.num_samples = kSamples;
  c.dt = kScoreDt;
  for (int l = 0; l < 3; ++l) {
    c.lane_center[l] = 2.0 + 4.0 * l;
    c.lane_speed_limit[l] = 22.0;
  }
  c.lane_center[2] -= 0.2;
  c.start_s = s0.s;
  c.start_d = s0.d;
  c.start_speed = s0.s_d;
  c.current_lane = 1;
  c.previous_target_lane = 1;
  c.num_cars = static_cast<int>(tr.d.size());
  c.car_s = tr.s.data();
  c.car_d = tr.d_at.data();
  c.car_v = tr.v_at.data();
  return c;
}

cost::CostInput Input(const Bundles& b, int i, int j) {
  cost::CostInput in;
  in.s = b.lon_s.data() + i * kSamples;
  in.s_d = b.lon_sd.data() + i * kSamples;
  in.s_dd = b.lon_sdd.data() + i * kSamples;
  in.d = b.lat_d.data() + j * kSamples;
  in.d_d = b.lat_dd.data() + j * kSamples;
  in.d_dd = b.lat_ddd.data() + j * kSamples;
  in.lon_duration = b.lon[i].duration;
  in.lat_duration = b.lat[j].duration;
  in.lon_jerk_squared = b.lon_j2[i];
  in.lat_jerk_squared = b.lat_j2[j];
  in.end_speed = b.lon[i].poly.V(b.lon[i].duration);
  in.end_d = b.lat_d[j * kSamples + kSamples - 1];
  in.target_lane = j / (static_cast<int>(b.lat.size()) / 3);
  return in;
}

#define FRENETIC_REQUIRE_FIXTURE(state, f)                    \
  const Fixture& f = Fixture::Get();                          \
  if (!f.error.empty()) return state.SkipWithError(f.error.c_str())

void BM_SolveQuintic(benchmark::State& state) {
  double k = 0;
  for (auto _ : state) {
    k = k > 10 ? 0 : k + 0.01;  // varies the input so nothing is hoisted
    benchmark::DoNotOptimize(traj::SolveQuintic(1.0, 18.0 + k, 0.1, 90.0, 20.0, 0.0, 4.0 + k));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SolveQuintic);

void BM_SolveQuartic(benchmark::State& state) {
  double k = 0;
  for (auto _ : state) {
    k = k > 10 ? 0 : k + 0.01;
    benchmark::DoNotOptimize(traj::SolveQuartic(1.0, 18.0 + k, 0.1, 20.0, 0.0, 4.0 + k));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SolveQuartic);

// Candidate generation: the bundles (solve + sample) for a nominal grid size; the lon x lat
// pairing is index bookkeeping on top.
void BM_GenerateBundles(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  const GridShape g = ShapeFor(static_cast<int>(state.range(0)));
  Bundles b;
  Size(g, &b);
  for (auto _ : state) {
    Generate(f.start, g, &b);
    benchmark::DoNotOptimize(b.lon_s.data());
  }
  const double cands = static_cast<double>(b.lon.size() * b.lat.size());
  state.counters["cands"] = cands;
  state.counters["ns_per_cand"] = benchmark::Counter(
      cands, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_GenerateBundles)->ArgName("cands")->RangeMultiplier(4)->Range(64, 4096);

// Cost scoring: every lon x lat pair through the weighted cost set (8 terms of the default
// configuration) against `vehicles` cars, with the planner's broad-phase masks (their building
// included). ns_per_cand is the target metric (<= 1000 ns).
void BM_ScoreSweep(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  const GridShape g = ShapeFor(1024);
  Bundles b;
  Size(g, &b);
  Generate(f.start, g, &b);
  Traffic tr;
  tr.Make(static_cast<int>(state.range(0)), f.start.s);
  cost::CostContext ctx = Context(f.start, tr);
  const int n_lon = static_cast<int>(b.lon.size()), n_lat = static_cast<int>(b.lat.size());
  // The planner's broad phase: masks per lateral and per longitudinal trajectory, built once
  // per cycle (included in the timing, as in the planner's generation stage).
  const int vehicles = ctx.num_cars;
  std::vector<std::uint64_t> near_lat(2 * n_lat * kSamples), near_lon(2 * n_lon * kSamples);
  for (int m = 0; m < 2; ++m) {
    ctx.near_lateral[m] = cost::kNearLateral[m];
    ctx.near_longitudinal[m] = cost::kNearLongitudinal[m];
  }
  ctx.max_car_speed = *std::max_element(tr.v.begin(), tr.v.end());
  std::vector<double> out(n_lon * n_lat);
  for (auto _ : state) {
    for (int j = 0; j < n_lat; ++j) {
      cost::FillNearMasks(b.lat_d.data() + j * kSamples, kSamples, vehicles, cost::kNearLateral,
                          tr.d_at.data(), kSamples, near_lat.data() + 2 * j * kSamples);
    }
    for (int i = 0; i < n_lon; ++i) {
      cost::FillNearMasks(b.lon_s.data() + i * kSamples, kSamples, vehicles,
                          cost::kNearLongitudinal, tr.s.data(), kSamples,
                          near_lon.data() + 2 * i * kSamples);
    }
    for (int i = 0; i < n_lon; ++i) {
      for (int j = 0; j < n_lat; ++j) {
        cost::CostInput in = Input(b, i, j);
        for (int m = 0; m < 2; ++m) {
          in.near_lat[m] = near_lat.data() + (2 * j + m) * kSamples;
          in.near_lon[m] = near_lon.data() + (2 * i + m) * kSamples;
        }
        out[i * n_lat + j] = f.costs->Evaluate(ctx, in);
      }
    }
    benchmark::DoNotOptimize(out.data());
  }
  const double cands = n_lon * n_lat;
  state.SetItemsProcessed(state.iterations() * n_lon * n_lat);
  state.counters["cands"] = cands;
  state.counters["ns_per_cand"] = benchmark::Counter(
      cands, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ScoreSweep)->ArgName("vehicles")->Arg(12)->Arg(24)->Arg(48);

// Collision check of one candidate: oriented-box overlap at every 0.1 s of the 5 s horizon
// against every car near the ego (the planner's Collides(), with its 12 m / 5 m prefilter).
void BM_CollisionCheck(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  const int vehicles = static_cast<int>(state.range(0));
  Traffic tr;
  tr.Make(vehicles, f.start.s);
  const traj::FrenetTrajectory cand{
      {traj::SolveQuartic(f.start.s, f.start.s_d, 0, 21.0, 0, 4.0), 4.0},
      {traj::SolveQuintic(f.start.d, 0, 0, 10.0, 0, 0, 3.0), 3.0}};
  std::vector<double> ts(kCheckTicks + 1), td(kCheckTicks + 1), tsd(kCheckTicks + 1),
      tdd(kCheckTicks + 1);
  for (int i = 1; i <= kCheckTicks; ++i) {
    const traj::FrenetState st = cand.At(i * kTick);
    ts[i] = st.s;
    td[i] = st.d;
    tsd[i] = st.s_d;
    tdd[i] = st.d_d;
  }
  int hits = 0;
  for (auto _ : state) {
    bool hit = false;
    for (int i = 5; i <= kCheckTicks && !hit; i += 5) {
      const double t = i * kTick;
      const traj::OrientedBox ego{ts[i], td[i], std::atan2(tdd[i], std::max(tsd[i], 0.5)), 2.4,
                                  1.2};
      for (int c = 0; c < vehicles; ++c) {
        const double cs = tr.s[c * kSamples] + tr.v[c] * t;
        if (std::abs(cs - ego.cx) > 12 || std::abs(tr.d[c] - ego.cy) > 5) continue;
        if (traj::Overlap(ego, {cs, tr.d[c], 0.0, 2.4 + 2.0, 1.2 + 0.3})) {
          hit = true;
          break;
        }
      }
    }
    hits += hit;
    benchmark::DoNotOptimize(hit);
  }
  state.counters["collides"] = hits > 0 ? 1 : 0;
}
BENCHMARK(BM_CollisionCheck)->ArgName("vehicles")->Arg(12)->Arg(24)->Arg(48);

void BM_BoxOverlap(benchmark::State& state) {
  traj::OrientedBox a{0, 0, 0.05, 2.4, 1.2}, b{3.0, 1.0, 0.0, 4.4, 1.5};
  for (auto _ : state) {
    a.cx = a.cx > 10 ? 0 : a.cx + 0.01;
    benchmark::DoNotOptimize(traj::Overlap(a, b));
  }
}
BENCHMARK(BM_BoxOverlap);

// A candidate's path in XY (history 110 + kept 6 + 250 new ticks), as the lazy check builds it.
struct XyPath {
  std::vector<double> x, y;
  int first = 0;
  void Make(const map::ReferenceLine& line, const traj::FrenetState& s0) {
    const traj::FrenetTrajectory cand{{traj::SolveQuartic(s0.s, s0.s_d, 0, 21.0, 0, 4.0), 4.0},
                                      {traj::SolveQuintic(s0.d, 0, 0, 2.0, 0, 0, 3.0), 3.0}};
    for (int i = -116; i <= kCheckTicks; ++i) {
      const double s = i <= 0 ? s0.s + s0.s_d * i * kTick : cand.At(i * kTick).s;
      const double d = i <= 0 ? s0.d : cand.At(i * kTick).d;
      const map::CartesianPose p = line.ToCartesian(s, d);
      x.push_back(p.x);
      y.push_back(p.y);
    }
    first = 116;
  }
};

void BM_XyFeasibility(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  XyPath path;
  path.Make(*f.line, f.start);
  plan::XyChecker checker(static_cast<int>(path.x.size()) + 8);
  const int n = static_cast<int>(path.x.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(checker.Measure(path.x.data(), path.y.data(), n, path.first));
  }
  state.counters["points"] = n;
}
BENCHMARK(BM_XyFeasibility);

// Frenet -> XY of one candidate's 250 check ticks (ns per point via items_per_second).
void BM_FrenetToXy(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  double sum = 0;
  for (auto _ : state) {
    for (int i = 1; i <= kCheckTicks; ++i) {
      const map::CartesianPose p = f.line->ToCartesian(f.start.s + 0.4 * i, 6.0 + 0.01 * i);
      sum += p.x;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kCheckTicks);
}
BENCHMARK(BM_FrenetToXy);

// XY -> Frenet (the cold-start projection of the ego, and the predictor's per-car projection).
void BM_XyToFrenet(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  const bool hint = state.range(0) != 0;
  std::vector<map::CartesianPose> pts;
  for (int i = 0; i < 64; ++i) pts.push_back(f.line->ToCartesian(f.start.s + 3.0 * i, 2.0 + i % 9));
  std::size_t k = 0;
  for (auto _ : state) {
    const map::CartesianPose& p = pts[k];
    k = (k + 1) % pts.size();
    benchmark::DoNotOptimize(hint ? f.line->ToFrenet(p.x, p.y, f.start.s + 3.0 * k)
                                  : f.line->ToFrenet(p.x, p.y));
  }
}
BENCHMARK(BM_XyToFrenet)->ArgName("hint")->Arg(0)->Arg(1);

// NLopt refinement of a winner, as the planner sets it up: LN_COBYLA over (end speed, T, T_lat,
// lateral offset) with bounds, at most 24 evaluations, the weighted cost as objective and the
// XY feasibility of the resampled candidate as inequality constraint. allocs counts the mallocs
// of one nlopt_optimize (the planner's no-allocation rule meets NLopt here).
struct RefineData {
  const Fixture* f = nullptr;
  cost::CostContext ctx;
  plan::XyChecker checker{512};
  std::vector<double> s, sd, sdd, d, dd, ddd, x, y;
  int evals = 0;

  traj::FrenetTrajectory Make(const double* p) const {
    const traj::FrenetState& s0 = f->start;
    return {{traj::SolveQuartic(s0.s, s0.s_d, s0.s_dd, p[0], 0, p[1]), p[1]},
            {traj::SolveQuintic(s0.d, s0.d_d, s0.d_dd, 6.0 + p[3], 0, 0, p[2]), p[2]}};
  }
  static double Objective(unsigned, const double* p, double*, void* data) {
    auto* r = static_cast<RefineData*>(data);
    ++r->evals;
    const traj::FrenetTrajectory tr = r->Make(p);
    for (int k = 0; k < kSamples; ++k) {
      const traj::FrenetState st = tr.At(k * kScoreDt);
      r->s[k] = st.s, r->sd[k] = st.s_d, r->sdd[k] = st.s_dd;
      r->d[k] = st.d, r->dd[k] = st.d_d, r->ddd[k] = st.d_dd;
    }
    cost::CostInput in;
    in.s = r->s.data(), in.s_d = r->sd.data(), in.s_dd = r->sdd.data();
    in.d = r->d.data(), in.d_d = r->dd.data(), in.d_dd = r->ddd.data();
    in.lon_duration = tr.lon.duration;
    in.lat_duration = tr.lat.duration;
    in.lon_jerk_squared = tr.lon.poly.JerkSquaredIntegral(tr.lon.duration);
    in.lat_jerk_squared = tr.lat.poly.JerkSquaredIntegral(tr.lat.duration);
    in.end_speed = p[0];
    in.end_d = r->d[kSamples - 1];
    in.target_lane = 1;
    return r->f->costs->Evaluate(r->ctx, in);
  }
  static double Constraint(unsigned, const double* p, double*, void* data) {
    auto* r = static_cast<RefineData*>(data);
    const traj::FrenetTrajectory tr = r->Make(p);
    for (int i = 0; i < kCheckTicks; ++i) {
      const traj::FrenetState st = tr.At((i + 1) * kTick);
      const map::CartesianPose q = r->f->line->ToCartesian(st.s, st.d);
      r->x[i] = q.x;
      r->y[i] = q.y;
    }
    const plan::XyMeasure m = r->checker.Measure(r->x.data(), r->y.data(), kCheckTicks, 1);
    return std::max({m.max_speed / 22.128, m.max_accel / 9.0, m.max_jerk / 9.0}) - 1.0;
  }
};

void BM_NloptRefine(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  Traffic tr;
  tr.Make(12, f.start.s);
  RefineData data;
  data.f = &f;
  data.ctx = Context(f.start, tr);
  for (auto* v : {&data.s, &data.sd, &data.sdd, &data.d, &data.dd, &data.ddd}) {
    v->assign(kSamples, 0.0);
  }
  data.x.assign(kCheckTicks, 0.0);
  data.y.assign(kCheckTicks, 0.0);
  nlopt_opt opt = nlopt_create(NLOPT_LN_COBYLA, 4);
  if (opt == nullptr) return state.SkipWithError("nlopt_create(LN_COBYLA) failed");
  nlopt_set_min_objective(opt, &RefineData::Objective, &data);
  nlopt_add_inequality_constraint(opt, &RefineData::Constraint, &data, 1e-6);
  nlopt_set_maxeval(opt, 24);
  const double lo[4] = {0, 1.5, 2.0, -0.5}, hi[4] = {22, 6, 4, 0.5};
  nlopt_set_lower_bounds(opt, lo);
  nlopt_set_upper_bounds(opt, hi);
  std::int64_t allocs = 0;
  int evals = 0;
  for (auto _ : state) {
    double p[4] = {20.0, 4.0, 3.0, 0.0}, best = 0;
    data.evals = 0;
    g_allocations.store(0, std::memory_order_relaxed);
    g_count_allocations.store(true, std::memory_order_relaxed);
    nlopt_optimize(opt, p, &best);
    g_count_allocations.store(false, std::memory_order_relaxed);
    allocs += g_allocations.load(std::memory_order_relaxed);
    evals += data.evals;
    benchmark::DoNotOptimize(best);
  }
  nlopt_destroy(opt);
  const double n = static_cast<double>(state.iterations());
  state.counters["evals"] = evals / n;
  state.counters["allocs"] = static_cast<double>(allocs) / n;
}
BENCHMARK(BM_NloptRefine)->Unit(benchmark::kMicrosecond);

// Telemetry parse of a recorded message (wire text -> plan::Telemetry in SI) and the control
// reply serialisation of a 100-point path.
void BM_ParseTelemetry(benchmark::State& state, const Scene* scene) {
  const std::string& frame = scene->wire.back();
  for (auto _ : state) {
    wire::ParsedFrame p = wire::ParseFrame(frame);
    benchmark::DoNotOptimize(p.telemetry.x);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(frame.size()));
  state.counters["cars"] = static_cast<double>(scene->messages.back().sensor_fusion.size());
  state.counters["prev_points"] =
      static_cast<double>(scene->messages.back().previous_path_x.size());
}

void BM_FormatControl(benchmark::State& state) {
  FRENETIC_REQUIRE_FIXTURE(state, f);
  std::vector<double> x, y;
  for (int i = 0; i < 100; ++i) {
    const map::CartesianPose p = f.line->ToCartesian(f.start.s + 0.4 * i, 6.0);
    x.push_back(p.x);
    y.push_back(p.y);
  }
  std::string out;
  out.reserve(8192);
  for (auto _ : state) {
    benchmark::DoNotOptimize(wire::FormatControl(x, y, &out));
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(out.size()));
}
BENCHMARK(BM_FormatControl);

}  // namespace

void RegisterStageBenchmarks(const std::vector<Scene>& scenes) {
  // The densest recorded message makes the parse benchmark's input.
  const Scene* densest = nullptr;
  for (const Scene& s : scenes) {
    if (densest == nullptr || s.wire.back().size() > densest->wire.back().size()) densest = &s;
  }
  if (densest != nullptr) {
    benchmark::RegisterBenchmark(("BM_ParseTelemetry/" + densest->name).c_str(),
                                 [densest](benchmark::State& st) { BM_ParseTelemetry(st, densest); });
  }
}

}  // namespace frenetic::bench

// The incident judge's power on scenes built with exactly one narrow escape, or none, and its
// agreement with the simulator it judges for.
#include "frenetic/eval/incident_judge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "eval/incident_judge_internal.h"
#include "frenetic/eval/incident_recorder.h"
#include "frenetic/sim/ego.h"
#include "frenetic/sim/simulator.h"
#include "sim/sim_test_util.h"

namespace frenetic::sim {
namespace {

constexpr double kDt = 0.02;
constexpr int kBudget = 400000;  // blocks per start: every "unavoidable" below is exhaustive

// A car of a built scene, along its lane at d: standing at s0 until t_start, then from speed v
// with acceleration a until its speed reaches v_end (a negative speed reverses).
struct SceneCar {
  double s0 = 0, d = 6, v = 0, a = 0, v_end = 0, t_start = 0;

  double S(double t) const {
    if (t <= t_start) return s0;
    const double tau = t - t_start;
    if (a == 0) return s0 + v * tau;
    const double t_end = std::max(0.0, (v_end - v) / a);
    const double run = std::min(tau, t_end);
    return s0 + v * run + 0.5 * a * run * run + (tau > t_end ? v_end * (tau - t_end) : 0.0);
  }
};

// The ego drives its lane at a constant speed (an EgoCar on a path, measured by a monitor as
// Simulator::Tick measures it) among scripted cars, on the Udacity map's long straight
// (s 550-1000, radius > 1,000 m): the drive the judge reads, for `ticks` ticks.
struct Scene {
  double ego_s0 = 480, ego_d = 6, ego_v = 20;
  std::vector<SceneCar> cars;
  int ticks = 500;

  double EgoS(std::int64_t tick) const { return ego_s0 + ego_v * tick * kDt; }
  // A column of standing cars in the lane at d, 5.4 m apart (0.8 m between bumpers).
  void Wall(double d, double from, double to) {
    for (double s = from; s <= to; s += 5.4) cars.push_back({s, d});
  }
};

IncidentCase Build(const World& world, const Scene& sc) {
  const map::ReferenceLine& line = *world.line;
  IncidentCase c;
  c.first_tick = 1;
  const map::CartesianPose start = line.ToCartesian(sc.ego_s0, sc.ego_d);
  EgoCar ego(static_cast<float>(start.x), static_cast<float>(start.y), start.heading);
  std::vector<double> px, py;
  for (int k = 1; k <= sc.ticks + 2; ++k) {
    const map::CartesianPose p = line.ToCartesian(sc.EgoS(k), sc.ego_d);
    px.push_back(p.x);
    py.push_back(p.y);
  }
  ego.ApplyPath(px, py);
  IncidentMonitor monitor{IncidentOptions()};
  std::vector<RecordedCar> cars;
  for (int k = 1; k <= sc.ticks; ++k) {
    ego.Tick();
    cars.clear();
    for (std::size_t i = 0; i < sc.cars.size(); ++i) {
      const double s = sc.cars[i].S(k * kDt), d = sc.cars[i].d;
      const map::CartesianPose p = line.ToCartesian(s, d);
      cars.push_back({static_cast<int>(i), p.x, p.y, p.heading, s, d});
    }
    TickSample sample;
    sample.x = ego.x();
    sample.y = ego.y();
    sample.speed = ego.speed();
    const map::FrenetPoint chord = world.chord->Convert(ego.x(), ego.y());
    sample.s = std::isnan(chord.s) ? 0.0 : static_cast<float>(chord.s);
    sample.d = std::isnan(chord.d) ? 0.0 : static_cast<float>(chord.d);
    const Box box{ego.x(), ego.y(), ego.yaw(), c.car_length, c.car_width};
    for (const RecordedCar& car : cars) {
      if (BoxesOverlap(box, Box{car.x, car.y, car.heading, c.car_length, c.car_width})) {
        sample.collision_with = car.id;
      }
    }
    monitor.Update(sample, k * kDt);
    const map::FrenetPoint f = line.ToFrenet(ego.x(), ego.y());
    c.AddTick({ego.x(), ego.y(), ego.yaw(), ego.speed(), f.s, f.d, judge::AnyFlag(monitor)}, cars);
    if (k % 10 == 0) c.AddMonitor(k, monitor);
  }
  c.incident_tick = sc.ticks;
  return c;
}

StartJudgement Search(const World& world, const IncidentCase& c, std::int64_t start, double seconds,
                      std::string* escape = nullptr) {
  return judge::SearchFrom(world, c, start, start + std::llround(seconds / kDt), kBudget, escape);
}

constexpr std::int64_t kStart = 250;  // t = 5 s: the monitor's start-up flags are long over

// Brake hard at once: a standing car 22.3 m ahead (bumper to bumper) of the ego at 20 m/s, both
// neighbour lanes full of standing cars. Braking at 9.6 m/s^2 stops 21 m on; at the lattice's
// hardest, 8 m/s^2, it takes 25 m, and 0.4 s later nothing stops in time.
TEST(IncidentJudge, FindsTheHardBrakeThatIsTheOnlyEscape) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scene sc;
  const double s = sc.EgoS(kStart);
  sc.Wall(2, s - 120, s + 120);
  sc.Wall(10, s - 120, s + 120);
  sc.cars.push_back({s + 4.6 + 22.3, 6});
  const IncidentCase c = Build(*world, sc);
  std::string escape;
  const StartJudgement now = Search(*world, c, kStart, 4.0, &escape);
  EXPECT_EQ(now.result, StartResult::kAvoidable) << now.blocks;
  EXPECT_EQ(escape.rfind("accel -9.6 m/s^2", 0), 0u) << escape;
  EXPECT_NE(escape.find("lane kept"), std::string::npos) << escape;
  const StartJudgement later = Search(*world, c, kStart + 20, 4.0);
  EXPECT_EQ(later.result, StartResult::kUnavoidable) << later.blocks;
}

// Change lanes in a window: a standing car 18 m ahead in the ego's lane (0.9 s away at 20 m/s),
// a car 5 m behind at the ego's speed (braking hard gets the ego rear-ended), the left lane full
// of standing cars, and in the right lane a car at 27 m/s just passing the ego: moving right at
// once hits it, 0.2 s late hits the standing car, and only the fastest moves (1.6 s for the
// lane, a peak lateral acceleration of 9 m/s^2, with some braking) get through.
Scene WindowScene(double ahead) {
  Scene sc;
  const double s = sc.EgoS(kStart), t = kStart * kDt;
  sc.Wall(2, s - 120, s + 120);
  sc.cars.push_back({s + 4.6 + ahead, 6});
  sc.cars.push_back({s - 4.6 - 5 - 20 * t, 6, 20, 0, 0, 0});
  sc.cars.push_back({s - 3 - 27 * t, 10, 27, 0, 0, 0});
  return sc;
}

TEST(IncidentJudge, FindsTheLaneChangeWindow) {
  FRENETIC_REQUIRE_UDACITY(world);
  const IncidentCase c = Build(*world, WindowScene(18));
  std::string escape;
  const StartJudgement now = Search(*world, c, kStart, 4.0, &escape);
  EXPECT_EQ(now.result, StartResult::kAvoidable) << now.blocks;
  EXPECT_NE(escape.find("to d 10.0 m"), std::string::npos) << escape;
  // The window has closed 0.2 s later.
  const StartJudgement later = Search(*world, c, kStart + 10, 4.0);
  EXPECT_EQ(later.result, StartResult::kUnavoidable) << later.blocks;
}

// Boxed in: standing cars in both neighbour lanes, a standing car 10 m ahead, a car 4 m behind
// at the ego's 20 m/s.
TEST(IncidentJudge, BoxedInIsUnavoidable) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scene sc;
  const double s = sc.EgoS(kStart), t = kStart * kDt;
  sc.Wall(2, s - 120, s + 120);
  sc.Wall(10, s - 120, s + 120);
  sc.cars.push_back({s + 4.6 + 10, 6});
  sc.cars.push_back({s - 4.6 - 4 - 20 * t, 6, 20, 0, 0, 0});
  const IncidentCase c = Build(*world, sc);
  const StartJudgement r = Search(*world, c, kStart, 3.0);
  EXPECT_EQ(r.result, StartResult::kUnavoidable) << r.blocks;
  EXPECT_GT(r.blocks, 0);
}

// A car reversing into a standing ego: standing cars on both sides and 1 m behind.
TEST(IncidentJudge, CarReversingIntoAStandingEgoIsUnavoidable) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scene sc;
  sc.ego_s0 = 600;
  sc.ego_v = 0;
  const double s = sc.EgoS(kStart), t = kStart * kDt;
  sc.Wall(2, s - 60, s + 60);
  sc.Wall(10, s - 60, s + 60);
  sc.cars.push_back({s - 4.6 - 1, 6});
  sc.cars.push_back({s + 4.6 + 3, 6, -2, 0, 0, t});
  const IncidentCase c = Build(*world, sc);
  const StartJudgement r = Search(*world, c, kStart, 3.0);
  EXPECT_EQ(r.result, StartResult::kUnavoidable) << r.blocks;
  // Without the reversing car the same ego just stands there.
  sc.cars.pop_back();
  EXPECT_EQ(Search(*world, Build(*world, sc), kStart, 3.0).result, StartResult::kAvoidable);
}

// On an empty road the first trajectory tried, the lane and speed kept, is the answer: one block
// per 0.2 s, no search.
TEST(IncidentJudge, EmptyRoadNeedsOneBlockPerStep) {
  FRENETIC_REQUIRE_UDACITY(world);
  const IncidentCase c = Build(*world, Scene());
  std::string escape;
  const StartJudgement r = Search(*world, c, kStart, 4.0, &escape);
  EXPECT_EQ(r.result, StartResult::kAvoidable);
  EXPECT_EQ(r.blocks, 20);
  EXPECT_EQ(escape, "accel 0 m/s^2 4.0 s; lane kept");
}

// JudgeIncident over the starts of the 3 s before: the last chance is the latest start the
// search finds avoidable, and every earlier one is avoidable by driving as the ego did first.
TEST(IncidentJudge, VerdictOverTheStartsBeforeTheIncident) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scene sc;
  const double s = sc.EgoS(kStart);
  sc.Wall(2, s - 120, s + 120);
  sc.Wall(10, s - 120, s + 120);
  sc.cars.push_back({s + 4.6 + 22.3, 6});
  sc.ticks = 480;
  IncidentCase c = Build(*world, sc);
  // The ego keeps driving into the standing car: the collision's tick.
  std::int64_t hit = -1;
  for (std::int64_t k = c.first_tick; k <= c.last_tick() && hit < 0; ++k) {
    const auto& e = c.ego[k - c.first_tick];
    for (const RecordedCar& car : c.CarsAt(k)) {
      if (BoxesOverlap({e.x, e.y, e.yaw, 4.6, 2.4}, {car.x, car.y, car.heading, 4.6, 2.4})) {
        hit = k;
      }
    }
  }
  ASSERT_GT(hit, kStart);
  c.incident_tick = hit;
  c.incident.t = hit * kDt;
  c.incident.kind = IncidentKind::kCollision;
  JudgeOptions options;
  options.budget_blocks = kBudget;
  const IncidentJudgement j = JudgeIncident(*world, c, options);
  EXPECT_EQ(j.verdict, Verdict::kAvoidable) << Describe(j);
  EXPECT_NEAR(j.last_chance, kStart * kDt, 0.21) << Describe(j);
  EXPECT_NEAR(j.avoidable_from, std::ceil((hit - 150) / 10.0) * 10 * kDt, 1e-9) << Describe(j);
  EXPECT_NEAR(j.until, std::min<std::int64_t>(hit + 100, c.last_tick()) * kDt, 1e-9);
  ASSERT_EQ(j.starts.size(), 15u);
  for (std::size_t i = 1; i < j.starts.size(); ++i) EXPECT_GT(j.starts[i].t, j.starts[i - 1].t);
  for (const StartJudgement& st : j.starts) {
    if (st.t < j.last_chance - 1e-9) {
      EXPECT_EQ(st.result, StartResult::kAvoidable);
      EXPECT_TRUE(st.as_driven_first);
    } else if (st.t > j.last_chance + 1e-9) {
      EXPECT_EQ(st.result, StartResult::kUnavoidable);
    }
  }
  EXPECT_EQ(Describe(j).rfind("avoidable from t = ", 0), 0u);
  // Deterministic.
  const IncidentJudgement again = JudgeIncident(*world, c, options);
  EXPECT_EQ(again.blocks, j.blocks);
  EXPECT_EQ(again.escape, j.escape);
}

TEST(IncidentJudge, NoHistoryIsNotJudged) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scene sc;
  sc.ticks = 8;
  IncidentCase c = Build(*world, sc);
  c.incident_tick = 8;
  const IncidentJudgement j = JudgeIncident(*world, c, JudgeOptions());
  EXPECT_EQ(j.verdict, Verdict::kNotJudged);
  EXPECT_EQ(Describe(j), "not judged");
  EXPECT_EQ(JudgeIncident(*world, IncidentCase(), JudgeOptions()).verdict, Verdict::kNotJudged);
}

TEST(IncidentJudge, OptionsAreValidated) {
  EXPECT_TRUE(JudgeOptions().Validate().ok());
  JudgeOptions o;
  o.window_seconds = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = JudgeOptions();
  o.margin_seconds = -1;
  EXPECT_FALSE(o.Validate().ok());
  o = JudgeOptions();
  o.budget_blocks = 0;
  EXPECT_NE(o.Validate().message().find("budget_blocks"), std::string::npos);
}

// The chord conversion is skipped only where the reference line's bounds decide the lane and
// road-edge flags: over the whole track and every d across the road, the flags they give are
// ChordFrenet's.
TEST(IncidentJudge, ChordBoundsNeverDecideADifferentFlag) {
  FRENETIC_REQUIRE_UDACITY(world);
  const map::ReferenceLine& line = *world->line;
  auto flags = [](double d) {
    return std::pair<bool, bool>{d < 0.8 || d > 11.2, (d > 3.2 && d < 4.8) || (d > 7.2 && d < 8.8)};
  };
  int decided = 0, total = 0;
  for (double s = 0; s < line.length(); s += 0.53) {
    for (double d = -1.0; d <= 13.0; d += 0.17) {
      ++total;
      const double bound = judge::ChordDFromBounds(line, s, d);
      if (std::isnan(bound)) continue;
      ++decided;
      const map::CartesianPose p = line.ToCartesian(s, d);
      const map::FrenetPoint f =
          world->chord->Convert(static_cast<float>(p.x), static_cast<float>(p.y));
      const double exact = std::isnan(f.d) ? 0.0 : static_cast<float>(f.d);
      ASSERT_EQ(flags(bound), flags(exact)) << "s " << s << " d " << d << ": " << exact;
    }
  }
  EXPECT_GT(decided, total / 2);  // the shortcut does its job
}

// The recorder keeps what the simulator saw: replaying the recorded drive through the judge's
// measure of a tick, from the monitor at a start before a collision, flags that collision on
// the very tick the simulator did; and the judge finds the keep-lane ego could have braked.
TEST(IncidentRecorder, ReplayOfTheDriveFlagsTheSimulatorsIncidentOnItsTick) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scenario sc;
  sc.traffic.cars = 1;
  sc.traffic.lane_changes = false;
  auto sim = Simulator::Create(world, sc, 1);
  ASSERT_TRUE(sim.ok());
  Simulator& s = **sim;
  TrafficCar& car = s.mutable_traffic().mutable_cars()[0];
  car.spawned = true;
  car.s = s.ego_view().s + 150;
  car.d = 6;
  car.v = car.top_speed = 0;
  car.lane = 1;
  car.wander_amp = 0;
  s.mutable_traffic().Place(car);
  IncidentRecorder recorder(s, JudgeOptions(), false);
  recorder.set_keep_cases(true);
  testing::KeepLanePlanner planner(world->line, 20);
  plan::Telemetry t;
  while (s.time() < 30 && recorder.cases().empty()) {
    s.GetTelemetry(&t);
    const plan::PlanResult& r = planner.Plan(t);
    ASSERT_TRUE(s.ApplyPath(r.x, r.y).ok());
    s.Advance(1);
    recorder.AfterTick();
  }
  ASSERT_FALSE(recorder.cases().empty()) << "no incident within 30 s";
  const IncidentCase& c = recorder.cases().front();
  ASSERT_EQ(c.incident.kind, IncidentKind::kCollision);
  ASSERT_EQ(recorder.judgements().size(), 1u);
  EXPECT_EQ(recorder.judgements()[0].verdict, Verdict::kAvoidable)
      << Describe(recorder.judgements()[0]);
  // Replay from the first start of the window.
  const std::size_t m = 1;
  ASSERT_LT(m, c.monitor_ticks.size());
  const std::int64_t k0 = c.monitor_ticks[m];
  IncidentMonitor monitor = c.monitors[m];
  const RecordedEgo& e0 = c.ego[k0 - c.first_tick];
  judge::EgoTick ego{e0.x, e0.y, e0.yaw, 0};
  std::int64_t flagged = -1;
  for (std::int64_t k = k0 + 1; k < c.last_tick() && flagged < 0; ++k) {
    const RecordedEgo& e = c.ego[k - c.first_tick];
    const RecordedEgo& next = c.ego[k + 1 - c.first_tick];
    if (!judge::MeasureTick(*world, c, k, e.x, e.y, next.x, next.y, e.s, e.d, &ego, &monitor)) {
      flagged = k;
      EXPECT_TRUE(monitor.active(IncidentKind::kCollision));
    }
    EXPECT_NEAR(ego.yaw, e.yaw, 1e-6) << k;
  }
  EXPECT_EQ(flagged, c.incident_tick);
}

}  // namespace
}  // namespace frenetic::sim

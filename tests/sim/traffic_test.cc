#include "frenetic/sim/traffic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "frenetic/units.h"
#include "sim_test_util.h"

namespace frenetic::sim {
namespace {


// A ghost ego that drives the middle lane at constant speed (traffic sees it, nothing hits it).
struct Ghost {
  const World* world;
  double s, d, speed;
  EgoView View() const {
    const map::CartesianPose p = world->line->ToCartesian(s, d);
    return EgoView{p.x, p.y, p.heading, speed, world->line->WrapS(s), d};
  }
  void Step() { s = world->line->WrapS(s + speed * 0.02); }
};

double Quantile(std::vector<float> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * (v.size() - 1))];
}

TEST(Traffic, SpawnRulesPlaceCarsAheadAndBehindWithTheirSpeedRanges) {
  FRENETIC_REQUIRE_UDACITY(world);
  int ahead = 0, behind = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Ghost ego{world.get(), 1000, 6, 0};
    Traffic traffic(world, TrafficOptions(), 4.6, 2.4, seed, ego.View());
    for (int frame = 0; frame < 600; ++frame) {  // 12 s: every car has spawned once
      traffic.Tick(ego.View(), frame);
      traffic.Frame(ego.View());
    }
    for (const TrafficCar& c : traffic.cars()) {
      ASSERT_TRUE(c.spawned) << "seed " << seed << " car " << c.id;
      EXPECT_GE(c.top_speed * units::kSimMpsToMph, 40 - 1e-9);
      EXPECT_LE(c.top_speed * units::kSimMpsToMph, 60 + 1e-9);
      EXPECT_TRUE(c.lane >= 0 && c.lane <= 2);
    }
    const auto& offsets = traffic.stats().spawn_offsets;
    EXPECT_GE(offsets.size(), 12u);  // cars that drove away were respawned too
    for (float off : offsets) {
      // Behind: waypoint -3/-2 (about 50-130 m); ahead: +4/+5 (about 120-220 m).
      if (off < 0) {
        ++behind;
        EXPECT_GT(off, -140);
        EXPECT_LT(off, -40);
      } else {
        ++ahead;
        EXPECT_GT(off, 100);
        EXPECT_LT(off, 230);
      }
    }
  }
  EXPECT_GT(ahead, 80);  // p = 1/2 each over 240 spawns
  EXPECT_GT(behind, 80);
}

TEST(Traffic, FirstSchedulerRunSpawnsOneToThreeAndRowsAreInIdOrder) {
  FRENETIC_REQUIRE_UDACITY(world);
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Ghost ego{world.get(), 124.8, 6, 0};
    Traffic traffic(world, TrafficOptions(), 4.6, 2.4, seed, ego.View());
    const auto n = std::count_if(traffic.cars().begin(), traffic.cars().end(),
                                 [](const TrafficCar& c) { return c.spawned; });
    EXPECT_GE(n, 1);
    EXPECT_LE(n, 3);
    std::vector<plan::SensorCar> rows;
    traffic.FillSensorFusion(&rows);
    ASSERT_EQ(rows.size(), 12u);
    for (int i = 0; i < 12; ++i) {
      EXPECT_EQ(rows[i].id, i);
      if (traffic.cars()[i].spawned) {
        // The spawn-speed quirk: top speed in mph reported as m/s until the next tick.
        EXPECT_NEAR(std::hypot(rows[i].vx, rows[i].vy),
                    traffic.cars()[i].top_speed * units::kSimMpsToMph, 1e-3);
      }
    }
    traffic.Tick(ego.View(), 0);
    traffic.FillSensorFusion(&rows);
    for (int i = 0; i < 12; ++i) {
      if (traffic.cars()[i].spawned) {
        EXPECT_LE(std::hypot(rows[i].vx, rows[i].vy), traffic.cars()[i].top_speed + 0.5);
      }
    }
  }
}

TEST(Traffic, SpeedsBrakingAndDistanceBandLikeTheRealRecordings) {
  FRENETIC_REQUIRE_UDACITY(world);
  Ghost ego{world.get(), 500, 6, 20};
  Traffic traffic(world, TrafficOptions(), 4.6, 2.4, 7, ego.View());
  for (int tick = 0; tick < 15000; ++tick) {  // 5 minutes
    ego.Step();
    traffic.Tick(ego.View(), tick);
    traffic.Frame(ego.View());
  }
  const TrafficStats& st = traffic.stats();
  ASSERT_GT(st.speeds.size(), 10000u);
  const double median = Quantile(st.speeds, 0.5);
  const double p5 = Quantile(st.speeds, 0.05), p95 = Quantile(st.speeds, 0.95);
  // STATS.md: median 16.4 m/s, p5 9.1, p95 21.3 (about two minutes of real traffic).
  std::printf("traffic: speed p5 %.2f median %.2f p95 %.2f m/s, hard-brake share %.4f, lane crossings %.3f per car-minute, rel_s p1 %.0f p99 %.0f m\n",
              p5, median, p95, static_cast<double>(st.hard_brake_ticks) / st.car_ticks,
              st.lane_crossings / st.car_minutes(), Quantile(st.rel_s, 0.01), Quantile(st.rel_s, 0.99));
  EXPECT_GT(median, 13.0);
  EXPECT_LT(median, 21.0);
  EXPECT_GT(p5, 3.0);
  EXPECT_LT(p95, 26.0);
  // Cars brake hard behind slower leaders now and then, but not most of the time.
  const double hard_share = static_cast<double>(st.hard_brake_ticks) / st.car_ticks;
  EXPECT_GT(hard_share, 0.001);
  EXPECT_LT(hard_share, 0.25);
  // Respawns keep traffic around the ego: the rule is 200 m of Euclidean distance, which
  // across a bend of the loop can be more along s, and queued cars keep driving.
  EXPECT_GT(Quantile(st.rel_s, 0.01), -215);
  EXPECT_LT(Quantile(st.rel_s, 0.99), 215);
  for (float r : st.rel_s) EXPECT_LT(std::abs(r), 450);
  // STATS.md: 0.16 lane-line crossings per car-minute (order of magnitude).
  const double crossings = st.lane_crossings / st.car_minutes();
  EXPECT_GT(crossings, 0.02);
  EXPECT_LT(crossings, 1.5);
  EXPECT_GT(st.spawn_offsets.size(), 12u);  // some cars were respawned
}

// One 59 mph car queued behind a ghost ego at 14.6 m/s in its lane (the recorded situation of
// car 2 in the advanced run). Returns the share of the last 30 s spent braking hard and the
// lowest speed there.
// One car in the left lane behind a ghost ego held at `ego_speed` in the same lane (s 500), lane
// changes and respawns off, braking from 35 m; the caller steps both.
struct CarBehindGhost {
  Ghost ego;
  Traffic traffic;
  CarBehindGhost(std::shared_ptr<const World> world, TrafficOptions o, double ego_speed,
                 double car_s, double top_mph, double car_v)
      : ego{world.get(), 500, 2, ego_speed},
        traffic(world, OneCar(o), 4.6, 2.4, 3, ego.View()) {
    TrafficCar& c = traffic.mutable_cars()[0];
    c.spawned = true;
    c.lane = 0;
    c.s = car_s;
    c.d = 2;
    c.top_speed = top_mph / units::kSimMpsToMph;
    c.v = car_v;
    traffic.Place(c);
  }
  static TrafficOptions OneCar(TrafficOptions o) {
    o.cars = 1;
    o.lane_changes = false;
    o.respawn_distance = 1000;
    o.brake_gap_max = 35;
    return o;
  }
  void Step(int tick) {
    ego.Step();
    traffic.Tick(ego.View(), tick);
  }
  const TrafficCar& car() const { return traffic.cars()[0]; }
};

std::pair<double, double> QueueBehindSlowEgo(std::shared_ptr<const World> world, double delay) {
  TrafficOptions o;
  o.brake_delay = delay;
  CarBehindGhost run(world, o, 14.6, 440, 59.1, 20);
  int hard = 0, ticks = 0;
  double v_min = 1e9;
  for (int tick = 0; tick < 4000; ++tick) {
    run.Step(tick);
    if (tick >= 2500) {
      ++ticks;
      if (run.car().accel < -7) ++hard;
      v_min = std::min(v_min, run.car().v);
    }
    // Never runs into the ego.
    EXPECT_GT(world->line->DiffS(run.ego.s, run.car().s), 4.6) << "tick " << tick;
  }
  return {static_cast<double>(hard) / ticks, v_min};
}

TEST(Traffic, BrakeDelaySustainsTheQueuedBrakeThrottleCycle) {
  FRENETIC_REQUIRE_UDACITY(world);
  // Without a lag the cycle dies out into tick-long brake pulses; with the calibrated 0.2 s
  // the car keeps braking hard ~10-20% of the time and dips several m/s below its leader, as
  // the recorded queued cars do (10-16% of samples, down to ~10 m/s).
  const auto [share0, vmin0] = QueueBehindSlowEgo(world, 0.0);
  const auto [share2, vmin2] = QueueBehindSlowEgo(world, 0.2);
  EXPECT_GT(share2, 0.06);
  EXPECT_LT(share2, 0.3);
  EXPECT_LT(vmin2, 12.0);
  EXPECT_GT(vmin2, 2.0);
  EXPECT_GT(vmin0, vmin2 + 1.0);
  // A lag of 0.4 s already lets the cycle grow to near standstill.
  EXPECT_LT(QueueBehindSlowEgo(world, 0.4).second, vmin2);
}

// Car 0 (top 50 mph) starts 8 m behind car 1, which is held at 13.1 m/s; the ego is far away in
// lane 2. Returns car 0's lowest speed over 10 s.
double LowestSpeedBehindSlowLeader(std::shared_ptr<const World> world, bool to_leader_mph) {
  TrafficOptions o;
  o.cars = 2;
  o.lane_changes = false;
  o.respawn_distance = 5000;
  o.brake_to_leader_mph = to_leader_mph;
  Ghost ego{world.get(), 300, 10, 0};
  Traffic traffic(world, o, 4.6, 2.4, 3, ego.View());
  auto put = [&](int id, double s, double v, double top) {
    TrafficCar& c = traffic.mutable_cars()[id];
    c.spawned = true;
    c.lane = 0;
    c.s = s;
    c.d = 2;
    c.v = v;
    c.top_speed = top;
    c.wander_amp = 0;
    traffic.Place(c);
  };
  put(0, 1000, 20, 50 / units::kSimMpsToMph);
  put(1, 1000 + 8 + 4.6, 13.1, 13.1);
  TrafficCar& leader = traffic.mutable_cars()[1];
  leader.slow_left = 1e9;  // held at 13.1 m/s
  leader.slow_speed = 13.1;
  double v_min = 1e9;
  for (int tick = 0; tick < 500; ++tick) {
    traffic.Tick(ego.View(), tick);
    v_min = std::min(v_min, traffic.cars()[0].v);
  }
  return v_min;
}

// Cut-ins (cut-in scenario): a car in the next lane 6-15 m ahead of the ego pulls in front of
// it, unless it is much slower than the ego or below the §8.5 lane-change speed. Returns the
// number of cut-ins over 10 s with the car at `car_speed` and the ego at 20 m/s.
int CutInsWithCarAt(std::shared_ptr<const World> world, double car_speed) {
  TrafficOptions o;
  o.cars = 1;
  o.lane_changes = false;
  o.respawn_distance = 5000;
  o.cut_in_rate = 50;  // as soon as allowed
  o.cut_in_min_gap = 6;
  o.cut_in_max_gap = 15;
  o.cut_in_max_closing = 5;
  o.event_cooldown = 0.5;
  Ghost ego{world.get(), 1000, 6, 20};
  Traffic traffic(world, o, 4.6, 2.4, 5, ego.View());
  TrafficCar& c = traffic.mutable_cars()[0];
  int cut_ins = 0;
  for (int tick = 0; tick < 500; ++tick) {
    // Keep the car in lane 0, 10 m ahead of the ego at a fixed speed.
    c.spawned = true;
    c.changing = false;
    c.lane = 0;
    c.d = 2;
    c.s = world->line->WrapS(ego.s + 10 + 4.6);
    c.v = c.top_speed = car_speed;
    c.wander_amp = 0;
    traffic.Place(c);
    traffic.Tick(ego.View(), tick);
    cut_ins = traffic.stats().cut_ins;
    ego.Step();
  }
  return cut_ins;
}

TEST(Traffic, OnlyCarsNearTheEgosSpeedCutIn) {
  FRENETIC_REQUIRE_UDACITY(world);
  EXPECT_GT(CutInsWithCarAt(world, 18.0), 0);  // 2 m/s slower: cuts in
  EXPECT_EQ(CutInsWithCarAt(world, 12.0), 0);  // 8 m/s slower: would be unavoidable
  EXPECT_EQ(CutInsWithCarAt(world, 5.0), 0);   // below 15 mph, even for a slow ego
}

TEST(Traffic, TooCloseCarBrakesToItsLeadersSpeedReadAsMph) {
  FRENETIC_REQUIRE_UDACITY(world);
  // §8.3: the desired speed is the leader's 13.1 m/s taken as 13.1 mph = 5.86 m/s; the recorded
  // deep dips end there. It creeps up to it while still too close, so it never goes lower.
  const double quirk = LowestSpeedBehindSlowLeader(world, true);
  EXPECT_NEAR(quirk, 13.1 / units::kSimMpsToMph, 0.5);
  // Without the quirk it brakes for as long as the gap is short: well below that.
  EXPECT_LT(LowestSpeedBehindSlowLeader(world, false), quirk - 2.0);
}

// One 47 mph car behind a ghost ego held at 15.65 m/s in its lane (car 5 behind car 10 in the
// advanced recording). Returns the lowest and highest speed over the last 30 s and the number
// of brake onsets there.
struct Cycle {
  double v_min = 1e9, v_max = 0;
  int onsets = 0;
};
Cycle FollowSteadyLeader(std::shared_ptr<const World> world, double delay, double release) {
  TrafficOptions o;
  o.brake_delay = delay;
  o.brake_release_delay = release;
  CarBehindGhost run(world, o, 15.65, 475, 46.9, 17);
  Cycle c;
  bool was_braking = false;
  for (int tick = 0; tick < 4000; ++tick) {
    run.Step(tick);
    if (tick < 2500) continue;
    const double v = run.car().v;
    c.v_min = std::min(c.v_min, v);
    c.v_max = std::max(c.v_max, v);
    const bool braking = run.car().accel < -5;
    if (braking && !was_braking) ++c.onsets;
    was_braking = braking;
  }
  return c;
}

TEST(Traffic, ReleaseDelayKeepsASteadyFollowersCycleAsRecorded) {
  FRENETIC_REQUIRE_UDACITY(world);
  // Recorded: 16.9 -> 13.8 m/s about every 4 s. Braking at once and letting go 0.1 s late
  // sustains that cycle; with no lag it decays to short pulses close to the leader's speed.
  const Cycle fitted = FollowSteadyLeader(world, 0.0, 0.1);
  EXPECT_GT(fitted.v_min, 12.8);
  EXPECT_LT(fitted.v_min, 14.5);
  EXPECT_GT(fitted.v_max, 16.2);
  EXPECT_GE(fitted.onsets, 6);  // 30 s at ~4 s a cycle
  EXPECT_LE(fitted.onsets, 10);
  const Cycle none = FollowSteadyLeader(world, 0.0, 0.0);
  EXPECT_GT(none.v_min, fitted.v_min + 0.5);
  // A negative release delay means the same lag both ways.
  const Cycle same = FollowSteadyLeader(world, 0.1, -1);
  const Cycle both = FollowSteadyLeader(world, 0.1, 0.1);
  EXPECT_EQ(same.v_min, both.v_min);
  EXPECT_EQ(same.onsets, both.onsets);
}

// Free cruise speed / top speed of one lone car after 60 s.
double CruiseFraction(std::shared_ptr<const World> world, double top_mph, double drag,
                      double linear_drag) {
  TrafficOptions o;
  o.cars = 1;
  o.respawn_distance = 5000;
  o.max_accel = 4.6;
  o.drag = drag;
  o.linear_drag = linear_drag;
  Ghost ego{world.get(), 500, 10, 16};  // right lane, never in the car's way
  Traffic traffic(world, o, 4.6, 2.4, 5, ego.View());
  TrafficCar& car = traffic.mutable_cars()[0];
  car.spawned = true;
  car.lane = 0;
  car.s = 600;
  car.d = 2;
  car.top_speed = top_mph / units::kSimMpsToMph;
  car.v = car.top_speed;
  traffic.Place(car);
  double sum = 0;
  int n = 0;
  for (int tick = 0; tick < 3000; ++tick) {
    ego.Step();
    traffic.Tick(ego.View(), tick);
    if (tick >= 1500) {
      sum += traffic.cars()[0].v;
      ++n;
    }
  }
  return sum / n / car.top_speed;
}

TEST(Traffic, LinearDragCruisesAtTheRecordedFractionOfTopSpeed) {
  FRENETIC_REQUIRE_UDACITY(world);
  // The recordings: free cruise is ~83% of the top speed for 40.6 and 59.1 mph cars alike.
  const double slow = CruiseFraction(world, 40.6, 0, 0.079);
  const double fast = CruiseFraction(world, 59.1, 0, 0.079);
  EXPECT_NEAR(slow, 0.832, 0.015);
  EXPECT_NEAR(fast, 0.832, 0.015);
  EXPECT_LT(std::abs(slow - fast), 0.01);
  // Quadratic drag cannot hold one fraction: slow cars cruise relatively faster.
  const double q_slow = CruiseFraction(world, 40.6, 0.004, 0);
  const double q_fast = CruiseFraction(world, 59.1, 0.004, 0);
  EXPECT_GT(q_slow - q_fast, 0.03);
}

TEST(Traffic, SameSeedSameTrafficBitForBit) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto run = [&](std::uint64_t seed) {
    Ghost ego{world.get(), 300, 6, 18};
    Traffic traffic(world, TrafficOptions(), 4.6, 2.4, seed, ego.View());
    for (int tick = 0; tick < 3000; ++tick) {
      ego.Step();
      traffic.Tick(ego.View(), tick);
      traffic.Frame(ego.View());
    }
    std::vector<plan::SensorCar> rows;
    traffic.FillSensorFusion(&rows);
    std::vector<double> flat;
    for (const auto& r : rows) flat.insert(flat.end(), {r.x, r.y, r.vx, r.vy, r.s, r.d});
    return flat;
  };
  EXPECT_EQ(run(11), run(11));
  EXPECT_NE(run(11), run(12));
}

// The §8.5 rule on a scripted set-up: car 0 cruises behind a slow car 1; car 2 may sit in the
// lane car 0 wants. The ego is far behind in lane 2.
class LaneChangeRule : public ::testing::Test {
 protected:
  void SetUp() override {
    world_ = testing::UdacityWorld();
    if (!world_) GTEST_SKIP() << "Udacity map absent";
    TrafficOptions o;
    o.cars = 3;
    o.spawn_speed_quirk = false;
    ego_ = Ghost{world_.get(), 900, 10, 0};
    traffic_ = std::make_unique<Traffic>(world_, o, 4.6, 2.4, 5, ego_.View());
  }
  void Set(int id, int lane, double s, double v, double slow_speed = -1) {
    TrafficCar& c = traffic_->mutable_cars()[id];
    c.spawned = true;
    c.queued = false;
    c.lane = lane;
    c.changing = false;
    c.s = s;
    c.d = 2 + 4 * lane;
    c.v = v;
    c.top_speed = v;
    c.wander_amp = 0;
    c.last_change_tick = -1000;
    c.clear_counts = {0, 0, 0};
    c.slow_left = 0;
    if (slow_speed >= 0) {
      c.slow_left = 1e9;  // keeps it slow and in its lane
      c.slow_speed = slow_speed;
    }
    traffic_->Place(c);
  }
  void Park(int id) {
    TrafficCar& c = traffic_->mutable_cars()[id];
    c.spawned = false;
    c.x = -5000;
    c.y = -5000;
  }
  // Runs up to `ticks` ticks; returns the tick of car 0's lane change or -1.
  int Run(int ticks, int* lane_after) {
    const int lane0 = traffic_->cars()[0].lane;
    for (int t = 0; t < ticks; ++t) {
      traffic_->Tick(ego_.View(), t);
      if (traffic_->cars()[0].lane != lane0) {
        *lane_after = traffic_->cars()[0].lane;
        return t;
      }
    }
    *lane_after = lane0;
    return -1;
  }
  std::shared_ptr<const World> world_;
  Ghost ego_;
  std::unique_ptr<Traffic> traffic_;
};

// A car held at a crawl (0.3 m/s) and one cruising at 15 m/s, both wandering 0.5 m with a 10 s
// period: over 20 s, the largest angle (rad) between each car's heading and the road's, and how
// far (m) each moved across the road ([0]: the crawling car, [1]: the cruising one).
struct Sway {
  double angle[2] = {0, 0}, across[2] = {0, 0};
};
Sway SwayOver20s(Traffic& traffic, const EgoView& ego, const World& world) {
  Sway out;
  double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
  for (int t = 0; t < 1000; ++t) {
    traffic.Tick(ego, t);
    for (int id = 0; id < 2; ++id) {
      const TrafficCar& c = traffic.cars()[id];
      const double road = world.line->ToCartesian(c.s, c.d).heading;
      out.angle[id] = std::max(out.angle[id], std::abs(std::remainder(c.heading - road, 2 * M_PI)));
      lo[id] = std::min(lo[id], c.d);
      hi[id] = std::max(hi[id], c.d);
    }
  }
  for (int id = 0; id < 2; ++id) out.across[id] = hi[id] - lo[id];
  return out;
}

TEST_F(LaneChangeRule, ACarAtACrawlDoesNotSlideSideways) {
  for (const double full_speed : {5.0, 0.0}) {
    TrafficOptions o;
    o.cars = 3;
    o.spawn_speed_quirk = false;
    o.lane_changes = false;
    o.wander_full_speed = full_speed;
    traffic_ = std::make_unique<Traffic>(world_, o, 4.6, 2.4, 5, ego_.View());
    Set(0, 0, 300, 0.3, 0.3);  // held at 0.3 m/s
    Set(1, 2, 500, 15);
    Park(2);
    for (int id = 0; id < 2; ++id) {
      TrafficCar& c = traffic_->mutable_cars()[id];
      c.wander_amp = 0.5;
      c.wander_w1 = c.wander_w2 = 2 * M_PI / 10;
      c.wander_p1 = c.wander_p2 = 0;
    }
    const Sway sway = SwayOver20s(*traffic_, ego_.View(), *world_);
    // Cruising, the wander is the same either way: about its full 1 m across, a degree or two off.
    EXPECT_GT(sway.across[1], 0.9) << full_speed;
    EXPECT_LT(sway.angle[1], 0.05) << full_speed;
    if (full_speed > 0) {
      // At a crawl it moves 6 m along the road in the 20 s, and its wander as far as at 5 m/s
      // over those 6 m: a third of a metre across, a few degrees off the road.
      EXPECT_LT(sway.across[0], 0.5);
      EXPECT_LT(sway.angle[0], 0.1);
    } else {
      // In time alone it slides the whole wander across, its box turned tens of degrees.
      EXPECT_GT(sway.across[0], 0.9);
      EXPECT_GT(sway.angle[0], 0.5);
    }
  }
}

TEST_F(LaneChangeRule, BlockedCarMovesToTheFreeMiddleLaneAfterFiftyEvaluations) {
  Set(0, 0, 1000, 18);
  Set(1, 0, 1030, 8, 8);
  Park(2);
  int lane = -1;
  const int at = Run(1500, &lane);
  EXPECT_EQ(lane, 1);
  EXPECT_GT(at, 50);  // more than 50 passing evaluations, only near waypoints
}

TEST_F(LaneChangeRule, NoChangeWhenTheTargetLaneHasACarWithinTwentyMetres) {
  Set(0, 0, 1000, 18);
  Set(1, 0, 1030, 8, 8);
  Set(2, 1, 1000, 8, 8);  // alongside in the middle lane, as slow as the blocked pair
  int lane = -1;
  EXPECT_EQ(Run(1500, &lane), -1);
  EXPECT_EQ(lane, 0);
}

TEST_F(LaneChangeRule, NoChangeWhenNotBlocked) {
  Set(0, 0, 1000, 18);
  Park(1);
  Park(2);
  int lane = -1;
  EXPECT_EQ(Run(1500, &lane), -1);
}

TEST_F(LaneChangeRule, MiddleLaneCarOnlyEverGoesLeft) {
  // Left lane occupied alongside, right lane free: the failing left test resets the right
  // lane's counter too, so the car never moves right.
  Set(0, 1, 1000, 18);
  Set(1, 1, 1030, 8, 8);
  Set(2, 0, 1000, 8, 8);
  int lane = -1;
  EXPECT_EQ(Run(1500, &lane), -1);
  // Both free: it goes left.
  Set(0, 1, 2000, 18);
  Set(1, 1, 2030, 8, 8);
  Park(2);
  EXPECT_GT(Run(1500, &lane), 50);
  EXPECT_EQ(lane, 0);
}

}  // namespace
}  // namespace frenetic::sim

#include "frenetic/eval/oracle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>


namespace frenetic::sim {
namespace {

// A car moving at constant speed along a lane centre: s(t) = s0 + v t.
struct Mover {
  int id;
  double s0, v, d;
};

// A trace of `seconds` s, a row every 0.1 s: the ego at ego_v m/s from s = 0 in lane ego_lane
// (4 m lanes), and the movers (no wrap: max_s 0).
OracleTrace Trace(double seconds, double ego_v, int ego_lane, const std::vector<Mover>& movers) {
  OracleTrace trace(0.0);
  for (int i = 0; i <= static_cast<int>(std::lround(seconds / 0.1)); ++i) {
    const double t = 0.1 * i;
    std::vector<plan::SensorCar> cars;
    for (const Mover& m : movers) {
      plan::SensorCar c;
      c.id = m.id;
      c.s = m.s0 + m.v * t;
      c.d = m.d;
      cars.push_back(c);
    }
    trace.Add(t, ego_v * t, 4.0 * ego_lane + 2.0, ego_v, cars);
  }
  return trace;
}

OracleOptions Lanes(int n) {
  OracleOptions o;
  o.lanes = n;
  return o;
}

TEST(Oracle, OnAnEmptyRoadReachesTheTopSpeedAsFastAsItsAccelerationAllows) {
  const OracleOptions o = Lanes(3);
  const OracleResult r = SearchOracle(Trace(20.0, 10.0, 1, {}), o);
  ASSERT_EQ(r.windows.size(), 1u);
  EXPECT_DOUBLE_EQ(r.seconds, 20.0);
  EXPECT_NEAR(r.driven_m, 200.0, 1e-9);
  // From 10 m/s, +2 m/s per 0.5 s stage (5 m/s^2 on the 1 m/s grid) to 22, then 22.2: the
  // shortfall against 22.2 m/s all along is about (12.2 m/s)^2 / (2 x 4 m/s^2).
  EXPECT_LT(r.distance_m, 22.2 * 20.0);
  EXPECT_GT(r.distance_m, 22.2 * 20.0 - 22.0);
  EXPECT_GT(r.mph(), r.driven_mph());
  EXPECT_EQ(r.windows[0].lanes.size(), 40u);
  EXPECT_EQ(r.windows[0].driven_lanes, std::string(40, '1'));
}

TEST(Oracle, BehindASlowCarOnAOneLaneRoadItCanOnlyFollow) {
  const OracleOptions o = Lanes(1);
  // A car 40 m ahead at 15 m/s; the ego too at 15 m/s. It may close to 4.6 m + 0.5 s x 15 m/s.
  const OracleResult r = SearchOracle(Trace(20.0, 15.0, 0, {{0, 40.0, 15.0, 2.0}}), o);
  const double room = 40.0 - (o.gap + o.headway * 15.0);
  EXPECT_LE(r.distance_m, 15.0 * 20.0 + room + 1e-9);
  EXPECT_GT(r.distance_m, 15.0 * 20.0 + room - 8.0);
}

TEST(Oracle, OnTwoLanesItPassesTheSlowCar) {
  const OracleOptions o = Lanes(2);
  const OracleResult r = SearchOracle(Trace(20.0, 15.0, 0, {{0, 40.0, 15.0, 2.0}}), o);
  EXPECT_GT(r.distance_m, 15.0 * 20.0 + 60.0);
  EXPECT_NE(r.windows[0].lanes.find('1'), std::string::npos) << r.windows[0].lanes;
  EXPECT_NE(r.windows[0].lanes.find('/'), std::string::npos) << r.windows[0].lanes;
}

TEST(Oracle, AQueueAlongsideInTheOtherLaneKeepsItBehindItsLeader) {
  const OracleOptions o = Lanes(2);
  // Lane 0: a slow leader 30 m ahead. Lane 1: a queue at the same speed, 8 m apart (too close
  // to slip between), from 16 m behind the ego to 40 m ahead.
  std::vector<Mover> movers = {{0, 30.0, 15.0, 2.0}};
  for (int i = 0; i < 8; ++i) movers.push_back({1 + i, -16.0 + 8.0 * i, 15.0, 6.0});
  const OracleResult blocked = SearchOracle(Trace(20.0, 15.0, 0, movers), o);
  const OracleResult open = SearchOracle(Trace(20.0, 15.0, 0, {movers[0]}), o);
  EXPECT_LE(blocked.distance_m, 15.0 * 20.0 + 30.0 + 1e-9);
  EXPECT_GT(open.distance_m, blocked.distance_m + 80.0);
}

TEST(Oracle, AFasterCarFromBehindInItsLaneIsTakenToBrakeForIt) {
  const OracleOptions o = Lanes(1);
  // Recorded as if it drove through the ego (the traffic brakes for a car ahead instead).
  const OracleResult alone = SearchOracle(Trace(20.0, 15.0, 0, {}), o);
  const OracleResult with = SearchOracle(Trace(20.0, 15.0, 0, {{0, -30.0, 24.0, 2.0}}), o);
  EXPECT_DOUBLE_EQ(with.distance_m, alone.distance_m);
}

TEST(Oracle, ACarThatAppearsIsIgnoredForItsGraceOnly) {
  // A car parked off the road jumps onto the ego's lane at s = 104 m at t = 5 s and stops
  // there, just ahead of where the search can be by then (~97 m at ~22 m/s): too close to stop.
  OracleTrace trace(0.0);
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.1 * i;
    std::vector<plan::SensorCar> cars(1);
    cars[0].id = 0;
    cars[0].d = t < 5.0 ? -280.0 : 2.0;
    cars[0].s = t < 5.0 ? -500.0 : 104.0;
    trace.Add(t, 10.0 * t, 2.0, 10.0, cars);
  }
  // The jump restarts the car's time on the road.
  const auto& rows = trace.rows();
  EXPECT_NEAR(trace.cars()[rows[49].first].since, 4.9, 1e-9);
  EXPECT_NEAR(trace.cars()[rows[50].first].since, 0.0, 1e-9);
  EXPECT_NEAR(trace.cars()[rows[55].first].since, 0.5, 1e-9);
  OracleOptions o = Lanes(1);
  // Ignored for 1 s, it is already behind the search when it counts: no hindrance.
  EXPECT_GT(SearchOracle(trace, o).distance_m, 22.2 * 20.0 - 22.0);  // as on an empty road
  // Counted at once, it blocks every way: nothing better than the ego as it drove.
  o.spawn_grace = 0;
  const OracleResult r = SearchOracle(trace, o);
  EXPECT_EQ(r.windows[0].lanes.find_first_not_of('?'), std::string::npos) << r.windows[0].lanes;
  EXPECT_DOUBLE_EQ(r.distance_m, r.driven_m);
}

TEST(Oracle, MovingInFrontOfACarInTheNextLaneNeedsRoomBehindIt) {
  // Lane 0: a leader 12 m ahead at the ego's 12 m/s (it may close up 1.4 m). Lane 1: free ahead,
  // a car 7 m behind the ego at 12 m/s: enough for a car length, not for 5 m of room more.
  const std::vector<Mover> movers = {{0, 12.0, 12.0, 2.0}, {1, -7.0, 12.0, 6.0}};
  OracleOptions o = Lanes(2);
  o.room_behind = 0;
  const OracleResult tight = SearchOracle(Trace(20.0, 12.0, 0, movers), o);
  o.room_behind = 5.0;
  const OracleResult roomy = SearchOracle(Trace(20.0, 12.0, 0, movers), o);
  EXPECT_GT(tight.distance_m, 12.0 * 20.0 + 100.0) << tight.windows[0].lanes;
  // With the room it can only stay behind one of the two 12 m/s cars.
  EXPECT_LE(roomy.distance_m, 12.0 * 20.0 + 1.5) << roomy.windows[0].lanes;
  // A car closing in from behind needs a second of its closing speed more: 7 m is too little
  // for one 3 m/s faster even with no room at all.
  o.room_behind = 0;
  const OracleResult closing =
      SearchOracle(Trace(20.0, 12.0, 0, {movers[0], {1, -7.0, 15.0, 6.0}}), o);
  EXPECT_LT(closing.windows[0].lanes.find('/'), closing.windows[0].lanes.size());
  EXPECT_LT(closing.distance_m, tight.distance_m);
}

TEST(Oracle, WindowsStartFromTheEgoAsItDroveAndAddUp) {
  const OracleOptions o = Lanes(3);
  const OracleResult r = SearchOracle(Trace(50.0, 10.0, 1, {}), o);
  ASSERT_EQ(r.windows.size(), 3u);  // 20 + 20 + 10 s
  double best = 0, driven = 0;
  for (const OracleWindow& w : r.windows) {
    best += w.best_m;
    driven += w.driven_m;
  }
  EXPECT_DOUBLE_EQ(r.distance_m, best);
  EXPECT_DOUBLE_EQ(r.driven_m, driven);
  EXPECT_DOUBLE_EQ(r.windows[1].t, 20.0);
  // Each window starts again at 10 m/s, so the second is as long as the first.
  EXPECT_NEAR(r.windows[1].best_m, r.windows[0].best_m, 1e-9);
}

TEST(Oracle, BadOptionsAndEmptyTracesGiveNothing) {
  OracleOptions o;
  o.step = 0;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_NE(o.Validate().message().find("step"), std::string::npos);
  o = OracleOptions();
  o.change = 0.5;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_TRUE(OracleOptions().Validate().ok());
  EXPECT_EQ(SearchOracle(OracleTrace(100.0), OracleOptions()).distance_m, 0.0);
  // Rows out of order or not finite are skipped; one row is no drive.
  OracleTrace trace(100.0);
  trace.Add(1.0, 0.0, 2.0, 0.0, {});
  trace.Add(0.5, 0.0, 2.0, 0.0, {});
  trace.Add(2.0, NAN, 2.0, 0.0, {});
  trace.Add(2.0, 1.0, NAN, 0.0, {});
  trace.Add(2.0, 1.0, 2.0, INFINITY, {});
  EXPECT_EQ(trace.rows().size(), 1u);
  EXPECT_EQ(SearchOracle(trace, OracleOptions()).seconds, 0.0);
  // The ego's s jumping far back (a glitch) does not widen the search past what it can reach.
  trace.Add(10.0, -3000.0, 2.0, 10.0, {});
  const OracleResult r = SearchOracle(trace, Lanes(3));
  EXPECT_GT(r.seconds, 0.0);
  EXPECT_LE(r.windows[0].best_m, 22.2 * 9.0 + 1e-9);
}

TEST(Oracle, TheEgoSAndTheCarsWrapWithTheTrack) {
  // Track of 1000 m: the ego crosses s = 0 at 15 m/s and a car stays 40 m ahead of it.
  OracleTrace trace(1000.0);
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.1 * i;
    const double s = std::fmod(900.0 + 15.0 * t, 1000.0);
    std::vector<plan::SensorCar> cars(1);
    cars[0].id = 0;
    cars[0].d = 2.0;
    cars[0].s = std::fmod(s + 40.0, 1000.0);
    trace.Add(t, s, 2.0, 15.0, cars);
  }
  ASSERT_EQ(trace.rows().size(), 201u);
  EXPECT_NEAR(trace.rows().back().ego_s, 300.0, 1e-6);
  const OracleResult r = SearchOracle(trace, Lanes(1));
  EXPECT_NEAR(r.driven_m, 300.0, 1e-6);
  EXPECT_LE(r.distance_m, 300.0 + 40.0);
}

}  // namespace
}  // namespace frenetic::sim

namespace frenetic::sim {
namespace {

// Lane 0: the ego at 15 m/s and a car at 5 m/s 60 m ahead of it. Lane 1: a queue at 15 m/s,
// 8 m apart (too close to slip between), from 10 m ahead of the ego on. The way past the slow
// car: into lane 1 behind the queue while there is time, past the slow car at 15 m/s, and back
// into lane 0 ahead of it. Sped up in lane 0 instead, the ego is soon held behind the slow car
// with the queue alongside: a dead end.
std::vector<Mover> Trap() {
  std::vector<Mover> movers = {{0, 60.0, 5.0, 2.0}};
  for (int i = 0; i < 30; ++i) movers.push_back({1 + i, 10.0 + 8.0 * i, 15.0, 6.0});
  return movers;
}

TEST(Oracle, ForesightOfTheWholeWindowRecedingFindsWhatTheWholeSearchFinds) {
  OracleOptions o = Lanes(2);
  const OracleTrace trace = Trace(20.0, 15.0, 0, Trap());
  const OracleResult whole = SearchOracle(trace, o);
  o.foresight = 20.0;
  const OracleResult receding = SearchOracle(trace, o);
  ASSERT_EQ(whole.windows.size(), 1u);
  ASSERT_EQ(receding.windows.size(), 1u);
  const OracleWindow& w = receding.windows[0];
  EXPECT_EQ(receding.stuck_windows, 0);
  EXPECT_EQ(w.stuck_stage, -1);
  EXPECT_EQ(w.lanes.size(), 40u);
  EXPECT_EQ(w.speeds.size(), 40u);
  // Past the slow car (the ego as it drove went through it: 300 m).
  EXPECT_GT(whole.windows[0].search_m, 300.0 + 50.0) << whole.windows[0].lanes;
  EXPECT_NE(whole.windows[0].lanes.find('1'), std::string::npos) << whole.windows[0].lanes;
  // Taking the first stage of the best way and searching again from there finds the same way,
  // up to what the 0.5 m bins of the whole search kept of it.
  EXPECT_NEAR(w.search_m, whole.windows[0].search_m, 1.0) << w.lanes;
  EXPECT_NE(w.lanes.find('1'), std::string::npos) << w.lanes;
  // The window went through: its figures are the search's own.
  EXPECT_DOUBLE_EQ(receding.through_seconds, 20.0);
  EXPECT_DOUBLE_EQ(receding.through_search_m, w.search_m);
  EXPECT_DOUBLE_EQ(receding.through_driven_m, w.driven_m);
  EXPECT_DOUBLE_EQ(receding.foresight, 20.0);
}

TEST(Oracle, ShortForesightDrivesIntoTheTrapThatTheWholeWindowAvoids) {
  OracleOptions o = Lanes(2);
  const OracleTrace trace = Trace(20.0, 15.0, 0, Trap());
  const OracleWindow full = SearchOracle(trace, o).windows[0];
  const double whole = full.search_m;
  // 1 s ahead: lane 0 is the faster, until no way on is left behind the slow car.
  o.foresight = 1.0;
  const OracleResult one = SearchOracle(trace, o);
  ASSERT_EQ(one.windows.size(), 1u);
  EXPECT_EQ(one.stuck_windows, 1);
  EXPECT_GE(one.windows[0].stuck_stage, 1);
  EXPECT_LT(one.windows[0].stuck_stage, 10);
  EXPECT_EQ(one.windows[0].lanes.size(), static_cast<std::size_t>(one.windows[0].stuck_stage));
  EXPECT_EQ(one.windows[0].lanes.find('1'), std::string::npos) << one.windows[0].lanes;
  EXPECT_LT(one.windows[0].search_m, 80.0);
  // Its best_m is floored at the ego's (which drove through the car, as no search may); a
  // stuck window counts in no figure of the windows gone through.
  EXPECT_DOUBLE_EQ(one.windows[0].best_m, one.windows[0].driven_m);
  EXPECT_DOUBLE_EQ(one.through_seconds, 0.0);
  // 3 s ahead: it sees the trap in time, later than the whole search, and gets past it.
  o.foresight = 3.0;
  const OracleResult three = SearchOracle(trace, o);
  EXPECT_EQ(three.stuck_windows, 0);
  EXPECT_GT(three.windows[0].search_m, 300.0) << three.windows[0].lanes;
  EXPECT_LE(three.windows[0].search_m, whole + 1.0) << three.windows[0].lanes;
  EXPECT_GT(three.windows[0].lanes.find('/'), full.lanes.find('/')) << three.windows[0].lanes;
  o.foresight = 0.3;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_NE(o.Validate().message().find("foresight"), std::string::npos);
}

}  // namespace
}  // namespace frenetic::sim

// The search planner's lattice: bundle counts and families for a given start state and the
// shipped grid, its boundary conditions, and the following law.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "plan/search/stages_testing.h"

namespace frenetic::plan::search {
namespace {

using testing::SceneCar;
using testing::Stages;

// A straight-ish stretch of the Udacity loop; the middle lane, 20 m/s.
using testing::kS;

// Centred in the middle lane as this cycle's context moves it (the lane centres depend on s and
// speed only, so a second context build keeps them).
void PrepareCentred(Stages& st, double speed, double d_d = 0,
                    const std::vector<SceneCar>& cars = {}) {
  st.Prepare({kS, speed, 0, 6.0, d_d, 0}, cars);
  st.Prepare({kS, speed, 0, st.ws.lane_center[1], d_d, 0}, cars);
}

// The lattice of PrepareCentred at 20 m/s, after a search where nothing passed or not
// (Workspace::none_passed_last).
void GenerateCentred(Stages& st, bool box_in) {
  PrepareCentred(st, 20);
  st.ws.none_passed_last = box_in;
  st.lattice.Generate();
}

// The shipped grid alone, without the lane-limit speeds a bend adds (kS is on a gentle bend).
PlannerConfig GridOnly() {
  PlannerConfig c = testing::DefaultConfig();
  EXPECT_TRUE(c.Set("grid.lane_limit_speeds", 0).ok());
  return c;
}

int Count(const Workspace& ws, cost::LonKind kind) {
  int n = 0;
  for (const LonTraj& l : ws.lon) n += l.kind == kind;
  return n;
}

TEST(SearchLatticeTest, ReachableSpeedFollowsTheVehiclesAccelerationRule) {
  // Without a vehicle: limits.max_accel throughout.
  EXPECT_DOUBLE_EQ(ReachableSpeed(VehicleLimits{}, 9.0, 10.0, 6.0), 64.0);
  // CommonRoad's KS2: 11.5 m/s^2 up to 7.319 m/s, then a v_switch / v. From 30 m/s for 6 s:
  // v^2 = 30^2 + 2 a v_switch T; from 2 m/s the first 0.46 s at a, the rest by the same law.
  VehicleLimits ks2;
  ks2.max_accel = 11.5;
  ks2.switch_speed = 7.319;
  EXPECT_NEAR(ReachableSpeed(ks2, 9.0, 30.0, 6.0), std::sqrt(900 + 2 * 11.5 * 7.319 * 6), 1e-9);
  const double t1 = (7.319 - 2.0) / 11.5;
  EXPECT_NEAR(ReachableSpeed(ks2, 9.0, 2.0, 6.0),
              std::sqrt(7.319 * 7.319 + 2 * 11.5 * 7.319 * (6 - t1)), 1e-9);
  EXPECT_NEAR(ReachableSpeed(ks2, 9.0, 2.0, 0.2), 2.0 + 11.5 * 0.2, 1e-12);
  // Check by integrating dv/dt with small steps.
  double v = 2.0;
  for (int i = 0; i < 600000; ++i) v += 1e-5 * (v > 7.319 ? 11.5 * 7.319 / v : 11.5);
  EXPECT_NEAR(ReachableSpeed(ks2, 9.0, 2.0, 6.0), v, 1e-3);
}

TEST(SearchLatticeTest, TheCurvePrefilterDropsWhatTheBendRulesOut) {
  REQUIRE_UDACITY_MAP();
  // kS lies on a gentle bend: at 20 m/s with a total acceleration limit of 0.5 m/s^2, many
  // longitudinal trajectories ask more than the bend allows. With the prefilter none of those
  // that are left does (at the samples within the check horizon, by the same bound); without it
  // they are there.
  auto with = [](int on) {
    PlannerConfig c = testing::DefaultConfig();
    EXPECT_TRUE(c.Set("check.curve_prefilter", on).ok());
    return c;
  };
  Stages off(with(0)), on(with(1));
  off.cfg.limits.max_accel = on.cfg.limits.max_accel =
      0.5;  // below the config's range: a test-only limit
  PrepareCentred(off, 20);
  PrepareCentred(on, 20);
  off.lattice.Generate();
  on.lattice.Generate();
  EXPECT_LT(on.ws.lon.size(), off.ws.lon.size());
  ASSERT_GT(on.ws.lon.size(), 0u);
  const Workspace& ws = on.ws;
  // The bound's reach across is as wide as a candidate passing the limit checks may go (the
  // off-road check's d limits on this uniform road, and the chords' 1.5 m), not the lane
  // borders at the start.
  EXPECT_GE(ws.max_abs_d, std::max({std::abs(ws.road_left), std::abs(ws.road_right),
                                    std::abs(on.cfg.limits.d_min), std::abs(on.cfg.limits.d_max)}) +
                              1.5 - 1e-9);
  const int n = ws.n_samples;
  int near_limit = 0;
  for (int i = 0; i < static_cast<int>(ws.lon.size()); ++i) {
    for (int k = 1; k < n && k * on.cfg.score.dt <= on.cfg.check.horizon + 1e-9; ++k) {
      const double s = ws.lon_s[i * n + k], v = ws.lon_sd[i * n + k];
      const int b = static_cast<int>(std::floor((s - ws.kappa_s0) / Workspace::kEdgeBin));
      ASSERT_TRUE(b >= 0 && b < static_cast<int>(ws.abs_kappa.size()));
      const double kappa = ws.abs_kappa[b];
      const double a = v * v * kappa * std::max(0.0, 1 - kappa * ws.max_abs_d);
      EXPECT_LE(a, 1.15 * 0.5 + 1e-9) << "lon " << i << " sample " << k;
      near_limit += a > 0.5;
    }
  }
  EXPECT_GT(near_limit, 0) << "the bound kept some within its slack";
}

TEST(SearchLatticeTest, NoLaneMovePairsWithATrajectoryFasterThanTheVehicle) {
  REQUIRE_UDACITY_MAP();
  // Following a leader at 29 m/s (the top speed is 22.1 m/s): those longitudinal trajectories
  // end faster than the vehicle drives. They are marked, no lane move pairs with them, and the
  // XY check would have rejected every such pair; the others keep their pairs.
  Stages st(GridOnly());
  PrepareCentred(st, 20, 0, {{kS + 30, 6.0, 29.0}});
  ASSERT_GT(st.ws.speed_share, 0.5);
  ASSERT_LT(st.ws.speed_share, 1.0) << "the bend's curvature and the road's width count";
  st.lattice.Generate();
  const Workspace& ws = st.ws;
  std::vector<int> pairs(ws.lon.size(), 0);
  for (size_t c = 0; c < ws.cand_lon.size(); ++c) ++pairs[ws.cand_lon[c]];
  int too_fast = 0;
  for (int i = 0; i < static_cast<int>(ws.lon.size()); ++i) {
    const LonTraj& l = ws.lon[i];
    if (!l.too_fast) {
      EXPECT_GT(pairs[i], 0) << "lon " << i;
      continue;
    }
    ++too_fast;
    EXPECT_EQ(pairs[i], 0) << "lon " << i;
    EXPECT_EQ(l.kind, cost::LonKind::kFollowing) << "lon " << i;
    for (int j = 0; j < static_cast<int>(ws.lat.size()); ++j) {
      if (l.lane >= 0 && l.lane != ws.lat[j].lane) continue;
      st.ws.FillTicksForLimits({l.traj, ws.lat[j].traj});
      Reject why = Reject::kCount;
      EXPECT_GT(st.limits.Violation(&why, true), 0) << "lon " << i << " lat " << j;
      // Over the speed limit itself, in XY (ticks 0.02 s apart), not only another limit.
      double top = 0;
      map::CartesianPose prev = st.line->ToCartesian(ws.tk_s[1], ws.tk_d[1]);
      for (int t = 2; t <= ws.n_ticks; ++t) {
        const map::CartesianPose p = st.line->ToCartesian(ws.tk_s[t], ws.tk_d[t]);
        top = std::max(top, std::hypot(p.x - prev.x, p.y - prev.y) / kTickSeconds);
        prev = p;
      }
      EXPECT_GT(top, st.cfg.limits.max_speed) << "lon " << i << " lat " << j;
    }
  }
  EXPECT_GT(too_fast, 0);
  // A leader at the ego's pace: none is.
  Stages slow(GridOnly());
  PrepareCentred(slow, 20, 0, {{kS + 30, 6.0, 20.0}});
  slow.lattice.Generate();
  for (const LonTraj& l : slow.ws.lon) EXPECT_FALSE(l.too_fast);
}

TEST(SearchLatticeTest, FreeRoadCentredInTheMiddleLane) {
  REQUIRE_UDACITY_MAP();
  Stages st(GridOnly());
  PrepareCentred(st, 20);
  st.lattice.Generate();
  const Workspace& ws = st.ws;
  const Settings& c = st.cfg;
  // Per duration every end speed and a stop; braking once: levels x targets.
  EXPECT_EQ(Count(ws, cost::LonKind::kVelocityKeeping), c.grid.speeds * c.grid.durations);
  EXPECT_EQ(Count(ws, cost::LonKind::kStopping), c.grid.durations);
  EXPECT_EQ(Count(ws, cost::LonKind::kBraking), c.brake.decels * c.brake.targets);
  EXPECT_EQ(Count(ws, cost::LonKind::kFollowing), 0);
  EXPECT_EQ(Count(ws, cost::LonKind::kAccelerating), c.grid.accels);  // below the limit: runs up
  ASSERT_EQ(ws.lon.size(), 90u) << "the shipped grid: 12 x 6 + 6 + 3 x 3 + 3";
  // Own lane centred and at rest: one move; each neighbour: every duration plus the delays.
  int per_lane[3] = {};
  for (const LatTraj& l : ws.lat) ++per_lane[l.lane];
  EXPECT_EQ(per_lane[1], 1);
  EXPECT_EQ(per_lane[0], c.lat.durations * c.lat.offsets + c.lat.delays);
  EXPECT_EQ(per_lane[2], c.lat.durations * c.lat.offsets + c.lat.delays);
  int delayed = 0;
  for (const LatTraj& l : ws.lat) delayed += l.traj.delay > 0;
  EXPECT_EQ(delayed, 2 * c.lat.delays);
  // No lane-bound longitudinal trajectory: every pair is a candidate, lon-major.
  ASSERT_EQ(ws.cand_lon.size(), ws.lon.size() * ws.lat.size());
  EXPECT_EQ(ws.cand_lon[1], 0);
  EXPECT_EQ(ws.cand_lat[1], 1);
  // Samples start at the start state; the lateral moves end at their lane's centre.
  for (size_t i = 0; i < ws.lon.size(); ++i) {
    EXPECT_DOUBLE_EQ(ws.lon_s[i * ws.n_samples], kS);
    EXPECT_DOUBLE_EQ(ws.lon_sd[i * ws.n_samples], 20);
    EXPECT_GT(ws.lon[i].jerk2, -1e-12);
  }
  for (const LatTraj& l : ws.lat) {
    EXPECT_NEAR(l.traj.At(l.traj.end_time()).p, ws.lane_center[l.lane] + l.offset, 1e-9);
  }
}

TEST(SearchLatticeTest, NoBrakingFamilyBelowOneMetrePerSecondAndNoStopWhenDisabled) {
  REQUIRE_UDACITY_MAP();
  Stages slow(GridOnly());
  PrepareCentred(slow, 0.5);
  slow.lattice.Generate();
  EXPECT_EQ(Count(slow.ws, cost::LonKind::kBraking), 0);
  EXPECT_EQ(slow.ws.lon.size(), 81u);

  PlannerConfig config = GridOnly();
  ASSERT_TRUE(config.Set("grid.stop", 0).ok());
  Stages no_stop(config);
  PrepareCentred(no_stop, 20);
  no_stop.lattice.Generate();
  EXPECT_EQ(Count(no_stop.ws, cost::LonKind::kStopping), 0);
  EXPECT_EQ(no_stop.ws.lon.size(), 84u);
}

// At a crawl (a queue) the own lane's only lateral move holds d: a move to the centre there turns
// the car far off the lane's heading for the little way it drives. At speed, every duration.
TEST(SearchLatticeTest, AtACrawlOffTheCentreItHoldsItsD) {
  REQUIRE_UDACITY_MAP();
  for (const double speed : {1.0, 10.0}) {
    Stages st;
    PrepareCentred(st, speed);
    const double d = st.ws.lane_center[1] + 0.4;
    st.Prepare({kS, speed, 0, d, 0, 0});
    st.lattice.Generate();
    int own = 0, holds = 0;
    for (const LatTraj& l : st.ws.lat) {
      if (l.lane != 1) continue;
      ++own;
      holds += std::abs(l.traj.At(l.traj.end_time()).p - d) < 1e-9;
    }
    EXPECT_EQ(holds, speed < 2.0 ? 1 : 0) << speed << " m/s";
    EXPECT_EQ(own, speed < 2.0 ? 1 : st.cfg.lat.durations * st.cfg.lat.offsets) << speed << " m/s";
  }
}

TEST(SearchLatticeTest, MovingLaterallyGetsEveryDurationAndNoDelayedStart) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  PrepareCentred(st, 20, /*d_d=*/1.0);
  st.lattice.Generate();
  EXPECT_EQ(st.ws.lat.size(), 3u * st.cfg.lat.durations * st.cfg.lat.offsets);
  for (const LatTraj& l : st.ws.lat) {
    EXPECT_EQ(l.traj.delay, 0);
    EXPECT_DOUBLE_EQ(l.traj.poly.V(0), 1.0) << "a move starts from the current d'";
  }
}

TEST(SearchLatticeTest, AstrideALineWithTheTimerNearlyOutMovesOffInTimeAndNeverWaits) {
  REQUIRE_UDACITY_MAP();
  // At rest across, 0.7 m past the line at d = 8 m between the middle and the right lane
  // (udacity seed 837's state), with 108 of the lane-line timer's 135 ticks gone (0.54 s left).
  Stages st;
  PrepareCentred(st, 20);
  auto generate = [&](int straddle, double d = 8.7) {
    st.Prepare({kS, 20, 0, d, 0, 0});
    st.ws.straddle_at_start = straddle;
    st.lattice.Generate();
  };
  // How many candidates of lateral moves shorter than the grid's shortest keep every limit,
  // the timer's included, or (shorter false) how many of the grid's own durations do; *all:
  // how many there are, *timer: how many fail the lane-line timer first.
  auto passing = [&](bool shorter, int* all = nullptr, int* timer = nullptr) {
    int n = 0;
    for (int c = 0; c < static_cast<int>(st.ws.cand_lon.size()); ++c) {
      const LatTraj& l = st.ws.lat[st.ws.cand_lat[c]];
      if ((l.traj.duration < st.cfg.lat.min_duration - 1e-9) != shorter) continue;
      if (all != nullptr) ++*all;
      st.ws.FillTicks(st.ws.Candidate(c));
      Reject why = Reject::kCount;
      n += st.limits.Violation(&why, true) <= 0;
      if (timer != nullptr) *timer += why == Reject::kLaneLine;
    }
    return n;
  };
  generate(108);
  int exits = 0;
  for (const LatTraj& l : st.ws.lat) {
    EXPECT_EQ(l.traj.delay, 0) << "a move that waits holds the ego astride";
    if (l.traj.duration < st.cfg.lat.min_duration - 1e-9) {
      ++exits;
      EXPECT_TRUE(l.lane == 1 || l.lane == 2) << l.lane;
      EXPECT_GE(l.traj.duration, 0.6);
    }
  }
  EXPECT_EQ(exits, 2) << "one to each lane beside the line";
  int grid = 0, late = 0;
  EXPECT_EQ(passing(false, &grid, &late), 0);
  EXPECT_GT(2 * late, grid) << "most of the grid's moves leave the line too late";
  EXPECT_GT(passing(true), 0) << "a move off the line in time";
  // With the timer just started: the grid's moves do, and no shorter one is added; a lane
  // change that waits is still never offered astride a line.
  generate(1);
  for (const LatTraj& l : st.ws.lat) {
    EXPECT_GE(l.traj.duration, st.cfg.lat.min_duration - 1e-9);
    EXPECT_EQ(l.traj.delay, 0);
  }
  EXPECT_GT(passing(false), 0);
  // Within a lane the lane changes that wait are there as before.
  generate(0, st.ws.lane_center[1]);
  int waits = 0;
  for (const LatTraj& l : st.ws.lat) waits += l.traj.delay > 0;
  EXPECT_GT(waits, 0);
}

TEST(SearchLatticeTest, FollowsTheLeaderInItsLaneOnlyWithTheTimeGapLaw) {
  REQUIRE_UDACITY_MAP();
  Stages st(GridOnly());
  const double v_lead = 15;
  PrepareCentred(st, 20, 0, {{kS + 40, 6.0, v_lead}});
  st.lattice.Generate();
  const Workspace& ws = st.ws;
  const Settings& c = st.cfg;
  ASSERT_EQ(Count(ws, cost::LonKind::kFollowing), c.grid.durations * c.grid.follow_gaps);
  const double follow_d0 = st.config.value("grid.follow_d0");
  const double follow_tau = st.config.value("grid.follow_tau");
  int following_pairs = 0;
  for (size_t i = 0; i < ws.cand_lon.size(); ++i) {
    const LonTraj& l = ws.lon[ws.cand_lon[i]];
    if (l.kind != cost::LonKind::kFollowing) continue;
    ++following_pairs;
    EXPECT_EQ(ws.lat[ws.cand_lat[i]].lane, 1) << "following is bound to the leader's lane";
  }
  // Only the own lane's single move pairs with them, but for those faster than the vehicle
  // drives on the way (the shortest close 40 m less the gap in a second or two, from 20 m/s:
  // they overshoot the top speed).
  int too_fast = 0;
  for (int i = 0; i < static_cast<int>(ws.lon.size()); ++i) {
    const LonTraj& l = ws.lon[i];
    if (l.kind != cost::LonKind::kFollowing || !l.too_fast) continue;
    ++too_fast;
    // Faster than the top speed along s within the check horizon (the share is at most 1).
    double top = 0;
    for (int k = 1; k < ws.n_samples && k * c.score.dt <= c.check.horizon + 1e-9; ++k) {
      top = std::max(top, ws.lon_sd[i * ws.n_samples + k]);
    }
    EXPECT_GT(top, c.limits.max_speed) << "lon " << i << " T " << l.traj.duration;
  }
  EXPECT_GT(too_fast, 0);
  EXPECT_LT(too_fast, c.grid.follow_gaps * c.grid.durations / 2);
  EXPECT_EQ(following_pairs + too_fast, c.grid.durations * c.grid.follow_gaps);
  // (No constant-acceleration run: the leader is within 100 m.)
  EXPECT_EQ(ws.cand_lon.size(), 87u * ws.lat.size() + following_pairs);
  for (const LonTraj& l : ws.lon) {
    if (l.kind != cost::LonKind::kFollowing) continue;
    EXPECT_EQ(l.lane, 1);
    EXPECT_EQ(l.lead, 0);
    const double T = l.traj.duration;
    // The leader at constant speed; the gap D0 + tau v, plus the longer gap's extra distance.
    const double target = kS + 40 + v_lead * T - (follow_d0 + follow_tau * v_lead) - l.param;
    EXPECT_NEAR(l.traj.At(T).p, target, 0.05) << "T " << T;
    EXPECT_NEAR(l.traj.At(T).v, v_lead, 1e-3);
    EXPECT_GE(l.param, 0);
  }
}

TEST(SearchLatticeTest, YieldsToACarAlongsideInTheNeighbourLane) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  PrepareCentred(st, 20, 0, {{kS - 5, 2.0, 20}});
  st.lattice.Generate();
  int yield = 0;
  for (const LonTraj& l : st.ws.lon) {
    if (l.kind == cost::LonKind::kFollowing) {
      EXPECT_EQ(l.lane, 0);
      ++yield;
    }
  }
  EXPECT_EQ(yield, st.cfg.grid.durations * st.cfg.grid.follow_gaps);
}

TEST(SearchLatticeTest, GapTargetsEndBetweenTwoCarsOfTheNeighbourLane) {
  REQUIRE_UDACITY_MAP();
  PlannerConfig c = GridOnly();
  ASSERT_TRUE(c.Set("grid.gap_targets", 2).ok());
  Stages st(c);
  // The left lane: cars 30 m apart at 18 m/s around the ego, and one far ahead.
  const std::vector<SceneCar> cars = {{kS - 15, 2.0, 18}, {kS + 15, 2.0, 18}, {kS + 120, 2.0, 18}};
  PrepareCentred(st, 20, 0, cars);
  st.lattice.Generate();
  const Workspace& ws = st.ws;
  const double margin = st.config.value("check.margin_s");
  int in_gaps = 0;
  for (const LonTraj& l : ws.lon) {
    if (l.kind != cost::LonKind::kFollowing || l.lane != 0) continue;
    const double T = l.traj.duration, s = l.traj.At(T).p;
    // Gap targets end in the middle of a gap, clear of both cars' bumpers and margins: the
    // nearer gap (between the first two cars) and the next one.
    const double behind = kS - 15 + 18 * T, ahead = kS + 15 + 18 * T, far = kS + 120 + 18 * T;
    const double sep = ws.car_sep_s[0] + margin;
    if (std::abs(s - 0.5 * (behind + ahead)) < 0.05 && s > behind + sep && s < ahead - sep)
      ++in_gaps;
    if (std::abs(s - 0.5 * (ahead + far)) < 0.05) ++in_gaps;
    EXPECT_NEAR(l.traj.At(T).v, 18, 1e-3);
  }
  EXPECT_EQ(in_gaps, 2 * st.cfg.grid.durations);
  // None without the setting.
  Stages off(GridOnly());
  PrepareCentred(off, 20, 0, cars);
  off.lattice.Generate();
  int following = 0;
  for (const LonTraj& l : off.ws.lon) following += l.kind == cost::LonKind::kFollowing;
  EXPECT_LT(following, Count(ws, cost::LonKind::kFollowing));
}

TEST(SearchLatticeTest, MakeLonHitsEachFamilysEndCondition) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  PrepareCentred(st, 20);
  const LonTraj vk = st.lattice.MakeLon(cost::LonKind::kVelocityKeeping, -1, 12.0, 4.0);
  EXPECT_NEAR(vk.traj.At(4.0).v, 12.0, 1e-9);
  EXPECT_NEAR(vk.traj.At(4.0).a, 0.0, 1e-9);
  const LonTraj stop = st.lattice.MakeLon(cost::LonKind::kStopping, -1, 30.0, 4.0);
  EXPECT_NEAR(stop.traj.At(4.0).p, kS + 30.0, 1e-9);
  EXPECT_NEAR(stop.traj.At(4.0).v, 0.0, 1e-9);
  const LonTraj brake = st.lattice.MakeLon(cost::LonKind::kBraking, -1, 5.0, 2.0);
  EXPECT_DOUBLE_EQ(brake.traj.At(1.0).a, -5.0);
  EXPECT_NEAR(brake.traj.At(2.0).v, 10.0, 1e-12);
  // A constant acceleration at once, then the speed reached is held.
  const LonTraj run = st.lattice.MakeLon(cost::LonKind::kAccelerating, -1, 1.5, 1.0);
  EXPECT_DOUBLE_EQ(run.traj.At(0.5).a, 1.5);
  EXPECT_NEAR(run.traj.At(1.0).v, 21.5, 1e-12);
  EXPECT_NEAR(run.traj.At(3.0).v, 21.5, 1e-12);
  EXPECT_NEAR(run.traj.At(3.0).a, 0.0, 1e-12);
}

// From a standstill the lattice offers constant-acceleration runs up to the fastest lane's limit
// (grid.min_accel to grid.max_accel, reaching it in v / a), none once within 1 m/s of it.
TEST(SearchLatticeTest, RunsUpToTheLimitAtConstantAccelerationBelowIt) {
  REQUIRE_UDACITY_MAP();
  Stages st(GridOnly());
  PrepareCentred(st, 0.0);
  st.lattice.Generate();
  const Settings& c = st.cfg;
  const double* lim = st.ws.ctx.lane_speed_limit;
  const double vmax = std::max({lim[0], lim[1], lim[2]});
  ASSERT_EQ(Count(st.ws, cost::LonKind::kAccelerating), c.grid.accels);
  double top = 0;
  for (const LonTraj& l : st.ws.lon) {
    if (l.kind != cost::LonKind::kAccelerating) continue;
    EXPECT_EQ(l.lane, -1);
    EXPECT_GE(l.param, c.grid.accel_min);
    EXPECT_LE(l.param, c.grid.accel_max);
    EXPECT_NEAR(l.traj.duration, vmax / l.param, 1e-9);
    EXPECT_NEAR(l.traj.At(l.traj.duration).v, vmax, 1e-9);
    top = std::max(top, l.param);
  }
  EXPECT_DOUBLE_EQ(top, c.grid.accel_max);
  Stages fast(GridOnly());
  PrepareCentred(fast, vmax - 0.5);
  fast.lattice.Generate();
  EXPECT_EQ(Count(fast.ws, cost::LonKind::kAccelerating), 0);
  // On a free road only: not with a car 90 m ahead in another lane, nor one 15 m behind.
  for (const SceneCar& car : {SceneCar{kS + 90, 10.0, 20.0}, SceneCar{kS - 15, 2.0, 20.0}}) {
    Stages busy(GridOnly());
    PrepareCentred(busy, 0.0, 0, {car});
    busy.lattice.Generate();
    EXPECT_EQ(Count(busy.ws, cost::LonKind::kAccelerating), 0) << car.s - kS;
  }
  Stages far(GridOnly());
  PrepareCentred(far, 0.0, 0, {{kS + 110, 10.0, 20.0}});
  far.lattice.Generate();
  EXPECT_EQ(Count(far.ws, cost::LonKind::kAccelerating), c.grid.accels);
}

// With a vehicle's limits and grid.limit_ramps: to each end speed of the grid at least 1 m/s
// above the ego's, a constant acceleration at 97% of what the vehicle holds at that speed
// (a_max v_switch / v above the switch speed), even with a car 15 m behind, where the free-road
// runs are not offered. Neither without the setting nor without a vehicle.
TEST(SearchLatticeTest, LimitRampsRunAtTheVehiclesLimitInAnyTraffic) {
  REQUIRE_UDACITY_MAP();
  const auto config = [](bool ramps, double vehicle_accel) {
    PlannerConfig c = GridOnly();
    EXPECT_TRUE(c.Set("grid.accels", 0).ok());
    EXPECT_TRUE(c.Set("grid.limit_ramps", ramps ? 1 : 0).ok());
    EXPECT_TRUE(c.Set("vehicle.max_accel", vehicle_accel).ok());
    EXPECT_TRUE(c.Set("vehicle.switch_speed", 7.319).ok());
    return c;
  };
  const std::vector<SceneCar> behind = {{kS - 15, 2.0, 20.0}};
  Stages st(config(true, 9.775));
  PrepareCentred(st, 10.0, 0, behind);
  st.lattice.Generate();
  std::set<double> grid;  // the end speeds of velocity keeping
  for (const LonTraj& l : st.ws.lon) {
    if (l.kind == cost::LonKind::kVelocityKeeping) {
      grid.insert(std::round(l.traj.At(l.traj.duration).v * 1e6) / 1e6);
    }
  }
  int expected = 0;
  for (const double v : grid) expected += v - 10.0 >= 1.0;
  ASSERT_GT(expected, 3);
  EXPECT_EQ(Count(st.ws, cost::LonKind::kAccelerating), expected);
  for (const LonTraj& l : st.ws.lon) {
    if (l.kind != cost::LonKind::kAccelerating) continue;
    const double end = l.traj.At(l.traj.duration).v;
    EXPECT_EQ(l.lane, -1);
    EXPECT_TRUE(std::any_of(grid.begin(), grid.end(), [end](double v) {
      return std::abs(v - end) < 1e-6;
    })) << end;
    const double limit =
        std::min(end > 7.319 ? 9.775 * 7.319 / end : 9.775, st.cfg.limits.max_accel);
    EXPECT_NEAR(l.param, 0.97 * limit, 1e-12) << end;
    // At once, not from the present acceleration.
    EXPECT_NEAR(l.traj.At(0.5 * l.traj.duration).a, l.param, 1e-9);
  }
  for (const auto& [ramps, accel] : {std::pair{false, 9.775}, std::pair{true, 0.0}}) {
    Stages off(config(ramps, accel));
    PrepareCentred(off, 10.0, 0, behind);
    off.lattice.Generate();
    EXPECT_EQ(Count(off.ws, cost::LonKind::kAccelerating), 0) << ramps << " " << accel;
  }
}

// After a search where nothing passed (Workspace::none_passed_last), the lateral moves end at
// grid.escape_lat_offsets offsets, escape_lat_offset_step apart, around each lane's centre
// instead of grid.lat_offsets: out to a lane's edge, where two lanes of cars may pass by.
TEST(SearchLatticeTest, AfterABoxInTheLateralEndsReachTheLanesEdges) {
  REQUIRE_UDACITY_MAP();
  PlannerConfig c = GridOnly();
  ASSERT_TRUE(c.Set("grid.escape_lat_offsets", 5).ok());
  ASSERT_TRUE(c.Set("grid.escape_lat_offset_step", 1.0).ok());
  ASSERT_TRUE(c.Set("grid.escape_lat_duration", 0.0).ok());  // the offsets alone (tested below)
  Stages st(c);
  for (const bool escape : {false, true}) {
    GenerateCentred(st, escape);
    std::set<double> offsets;
    int neighbour = 0;
    for (const LatTraj& l : st.ws.lat) {
      offsets.insert(l.offset);
      neighbour += l.lane == 0 && l.traj.delay == 0;
    }
    if (escape) {
      EXPECT_EQ(offsets, (std::set<double>{-2.0, -1.0, 0.0, 1.0, 2.0}));
      EXPECT_EQ(neighbour, st.cfg.lat.durations * 5);
    } else {
      EXPECT_EQ(offsets, (std::set<double>{0.0}));  // the shipped grid.lat_offsets: 1
      EXPECT_EQ(neighbour, st.cfg.lat.durations);
    }
  }
  // Odd counts only (0: the same as grid.lat_offsets).
  EXPECT_FALSE(c.Set("grid.escape_lat_offsets", 4).ok());
}

// After a search where nothing passed, grid.escape_lat_duration adds a quicker move to each
// lane but the own one the ego is centred in (a lane change, or back to the lane's centre, in
// 1.5 s instead of lat_min_duration's 2), and none otherwise.
TEST(SearchLatticeTest, AfterABoxEachLaneGetsAQuickerMove) {
  REQUIRE_UDACITY_MAP();
  struct Case {
    double quick;  // grid.escape_lat_duration
    bool box_in;
    std::set<int> quick_lanes;
  };
  for (const Case& k : {Case{1.5, false, {}}, Case{1.5, true, {0, 2}}, Case{0.0, true, {}}}) {
    PlannerConfig c = GridOnly();
    ASSERT_TRUE(c.Set("grid.escape_lat_duration", k.quick).ok());
    ASSERT_TRUE(c.Set("grid.lat_min_duration", 2.0).ok());
    Stages st(c);
    GenerateCentred(st, k.box_in);
    std::set<int> quick_lanes;
    for (const LatTraj& l : st.ws.lat) {
      EXPECT_GE(l.traj.duration, k.quick > 0 && k.box_in ? k.quick : 2.0);
      if (l.traj.duration < 2.0) quick_lanes.insert(l.lane);
    }
    EXPECT_EQ(quick_lanes, k.quick_lanes) << k.quick << " " << k.box_in;
  }
}

// On a bend the outer lanes' limits are lower than the fastest lane's: each such lane gets
// velocity keeping to exactly its own limit, for every duration, paired only with its own lane.
TEST(SearchLatticeTest, SlowerLanesOfABendGetTheirOwnLimit) {
  REQUIRE_UDACITY_MAP();
  Stages st;
  const Settings& c = st.cfg;
  double bend = -1;
  for (double s = 0; s < st.line->length() && bend < 0; s += 25) {
    st.Prepare({s, 20, 0, 6.0, 0, 0});
    const double* lim = st.ws.ctx.lane_speed_limit;
    if (std::max({lim[0], lim[1], lim[2]}) - std::min({lim[0], lim[1], lim[2]}) > 0.5) bend = s;
  }
  ASSERT_GE(bend, 0) << "the Udacity loop has bends";
  st.lattice.Generate();
  const Workspace& ws = st.ws;
  const double* lim = ws.ctx.lane_speed_limit;
  const double vmax = std::max({lim[0], lim[1], lim[2]});
  int slower = 0;
  for (int l = 0; l < c.road.num_lanes; ++l) slower += lim[l] < vmax - 0.05;
  ASSERT_GT(slower, 0);
  int bound = 0;
  for (size_t i = 0; i < ws.lon.size(); ++i) {
    const LonTraj& l = ws.lon[i];
    if (l.kind != cost::LonKind::kVelocityKeeping || l.lane < 0) continue;
    ++bound;
    EXPECT_LT(lim[l.lane], vmax - 0.05);
    EXPECT_NEAR(l.traj.poly.V(l.traj.duration), lim[l.lane], 1e-9);
  }
  EXPECT_EQ(bound, slower * c.grid.durations);
  for (size_t k = 0; k < ws.cand_lon.size(); ++k) {
    const LonTraj& l = ws.lon[ws.cand_lon[k]];
    if (l.lane >= 0) {
      EXPECT_EQ(l.lane, ws.lat[ws.cand_lat[k]].lane);
    }
  }

  // Switched off, the grid alone.
  PlannerConfig off = testing::DefaultConfig();
  ASSERT_TRUE(off.Set("grid.lane_limit_speeds", 0).ok());
  Stages plain(off);
  plain.Prepare({bend, 20, 0, 6.0, 0, 0});
  plain.lattice.Generate();
  EXPECT_EQ(Count(plain.ws, cost::LonKind::kVelocityKeeping), c.grid.speeds * c.grid.durations);
}

// A goal region crossed turned: swerves into it, each paired only with the lon trajectories that
// put it inside at its end, and checked up to there; none for a region kept in a lane.
TEST(SearchLatticeTest, SwervesIntoARegionCrossedTurnedEndInsideItAndAreCheckedUpToThere) {
  REQUIRE_UDACITY_MAP();
  Stages st(GridOnly());
  PrepareCentred(st, 20);
  Workspace& ws = st.ws;
  cost::GoalRegion g;
  g.s_lo = kS + 50;
  g.s_hi = kS + 90;
  g.d_lo = ws.lane_center[1] - 1;
  g.d_hi = ws.lane_center[1] + 1;
  g.t_lo = 0;
  g.t_hi = 5;
  g.h_lo = 0.2;  // moving right, turned 0.2 to 0.5 (tangents)
  g.h_hi = 0.5;
  ws.goals[0] = g;
  ws.num_goals = 1;
  st.lattice.Generate();
  int swerves = 0, paired = 0;
  for (size_t j = 0; j < ws.lat.size(); ++j) {
    const LatTraj& l = ws.lat[j];
    if (!l.swerve()) continue;
    ++swerves;
    EXPECT_EQ(l.goal, 0);
    const traj::State1d end = l.traj.At(l.traj.end_time());
    EXPECT_GE(end.p, g.d_lo - 1e-9);
    EXPECT_LE(end.p, g.d_hi + 1e-9);
    EXPECT_GT(end.v, 0.2 * 20 - 1e-9) << "across at the heading, at the start's speed or more";
    EXPECT_GE(end.a, -1e-9) << "still turning into the region or not, never out of it";
  }
  EXPECT_GT(swerves, 0);
  for (size_t c = 0; c < ws.cand_lon.size(); ++c) {
    const LatTraj& l = ws.lat[ws.cand_lat[c]];
    if (!l.swerve()) {
      EXPECT_EQ(ws.CheckTicks(static_cast<int>(c)), ws.n_ticks);
      continue;
    }
    ++paired;
    ASSERT_TRUE(ws.SwerveEndsInside(ws.cand_lon[c], ws.cand_lat[c]));
    const traj::State1d lon = ws.lon[ws.cand_lon[c]].traj.At(l.traj.end_time());
    EXPECT_GE(lon.p, g.s_lo);
    EXPECT_LE(lon.p, g.s_hi);
    const int ticks = ws.CheckTicks(static_cast<int>(c));
    EXPECT_LT(ticks, ws.n_ticks);
    EXPECT_NEAR(ticks * kTickSeconds, l.traj.end_time(), kTickSeconds);
    EXPECT_LE(ws.CheckSteps(static_cast<int>(c)), ws.n_steps);
  }
  EXPECT_GT(paired, 0);
  EXPECT_LT(paired, swerves * static_cast<int>(ws.lon.size())) << "the others are left out";
  // Turned less than kTurnedHeading: a region kept in a lane, no swerve.
  ws.goals[0].h_lo = 0.5 * cost::kTurnedHeading;
  st.lattice.Generate();
  for (const LatTraj& l : ws.lat) EXPECT_FALSE(l.swerve());
}

// A swerve that ended between two of the problem's steps, its goal not met: it goes on as it
// goes for one more step (constant lateral acceleration), while that is in the region; not
// long past its end.
TEST(SearchLatticeTest, ASwerveThatEndedBeforeItsGoalGoesOnOneStepAtATime) {
  REQUIRE_UDACITY_MAP();
  Stages st(GridOnly());
  PrepareCentred(st, 20, 4.0);  // moving right at 4 m/s
  Workspace& ws = st.ws;
  ws.start.d_dd = 2.0;
  cost::GoalRegion g;
  g.s_lo = kS - 10;
  g.s_hi = kS + 30;
  g.d_lo = ws.start.d - 1;
  g.d_hi = ws.start.d + 1;
  g.t_lo = 0;
  g.t_hi = 5;
  g.h_lo = 0.15;
  g.h_hi = 0.5;
  ws.goals[0] = g;
  ws.num_goals = 1;
  ws.have_prev_traj = true;
  ws.prev_swerve_goal = 0;
  ws.prev_traj.lat = {};
  ws.prev_traj.lat.duration = 1.0;
  ws.prev_elapsed = 1.05;  // 0.05 s past its end
  st.lattice.Generate();
  int late = 0;
  for (const LatTraj& l : ws.lat) {
    if (!l.swerve() || std::abs(l.traj.duration - 0.1) > 1e-12) continue;
    ++late;
    const traj::State1d end = l.traj.At(0.1);
    EXPECT_NEAR(end.p, ws.start.d + 4.0 * 0.1 + 0.5 * 2.0 * 0.01, 1e-9);
    EXPECT_NEAR(end.v, 4.0 + 2.0 * 0.1, 1e-9);
    EXPECT_NEAR(end.a, 2.0, 1e-9);
  }
  EXPECT_EQ(late, 1);
  // Long past its end: none.
  ws.prev_elapsed = 2.0;
  st.lattice.Generate();
  for (const LatTraj& l : ws.lat) {
    EXPECT_FALSE(l.swerve() && std::abs(l.traj.duration - 0.1) < 1e-12);
  }
}

}  // namespace
}  // namespace frenetic::plan::search

// The predictor on the Udacity map: sensor-fusion glitches repaired, parked cars dropped, braking
// and lane changes extrapolated, and the traffic's lane-change rule as ghost predictions.
#include "plan/predictor.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/road.h"
#include "plan/search/stages_testing.h"

namespace frenetic::plan {
namespace {

TEST(PredictorTest, RepairsGlitchesAndDropsParkedCars) {
  REQUIRE_UDACITY_MAP();
  const auto line = search::testing::UdacityLine();
  PredictorOptions o;
  auto pred = MakeConstantVelocityPredictor(line, o);
  const map::CartesianPose a = line->ToCartesian(200, 6);
  const map::CartesianPose parked = line->ToCartesian(220, -280);
  std::vector<SensorCar> rows = {
      {0, a.x, a.y, 17.6 * std::cos(a.heading), 17.6 * std::sin(a.heading), 0, 0},  // s=d=0
      {1, parked.x, parked.y, 0, 0, 6719, -280}};
  pred->Observe(rows, 150, 0.06);
  ASSERT_EQ(pred->cars().size(), 1u);
  EXPECT_NEAR(pred->cars()[0].s, 50, 0.1);
  EXPECT_NEAR(pred->cars()[0].d, 6, 0.05);
  EXPECT_NEAR(pred->cars()[0].v_s, 17.6, 0.05);
  // The spawn spike: 2.24x for one message -> the unit slip undone.
  rows[0].vx *= 2.237;
  rows[0].vy *= 2.237;
  pred->Observe(rows, 150, 0.06);
  EXPECT_NEAR(pred->cars()[0].v_s, 17.6, 0.05);
  EXPECT_NEAR(pred->Predict(0, 2.0).s, 50 + 2 * 17.6, 0.2);
  // A first reading above the cap is the unit slip: m/s written as mph.
  rows[0].id = 7;
  pred->Observe(rows, 150, 0.06);
  EXPECT_NEAR(pred->cars()[0].v_s, 17.6 * 2.237 / 2.2369, 0.1);
  // A car last seen slow long ago and fast now is fast (a stale reading proves no glitch), and
  // its lateral motion is kept.
  const map::CartesianPose b = line->ToCartesian(210, 6);
  const double h = b.heading;
  std::vector<SensorCar> slow = {{3, b.x, b.y, 4.7 * std::cos(h), 4.7 * std::sin(h), 0, 0}};
  pred->Observe(slow, 150, 1.0);
  // 17.6 along the lane, 2.5 m/s to the left (the right normal is (sin h, -cos h)).
  std::vector<SensorCar> fast = {{3, b.x, b.y, 17.6 * std::cos(h) - 2.5 * std::sin(h),
                                  17.6 * std::sin(h) + 2.5 * std::cos(h), 0, 0}};
  pred->Observe(fast, 150, 20.0);
  ASSERT_EQ(pred->cars().size(), 1u);
  EXPECT_NEAR(pred->cars()[0].v_s, 17.6, 0.05);
  EXPECT_NEAR(pred->cars()[0].v_d, -2.5, 0.05);
}

// The manoeuvre-aware predictor: a braking car keeps braking (for brake_horizon), a car moving
// across lanes reaches the next lane's centre and stops there.
TEST(PredictorTest, ExtrapolatesBrakingAndLaneChanges) {
  REQUIRE_UDACITY_MAP();
  const auto line = search::testing::UdacityLine();
  PredictorOptions o;
  auto pred = MakeManoeuvrePredictor(line, o);
  const map::CartesianPose p = line->ToCartesian(300, 9.0);
  const double h = p.heading;
  auto row = [&](double v, double v_d) {
    return std::vector<SensorCar>{{1, p.x, p.y, v * std::cos(h) + v_d * std::sin(h),
                                   v * std::sin(h) - v_d * std::cos(h), 0, 0}};
  };
  pred->Observe(row(20.0, 0.0), 280, 0.0);
  pred->Observe(row(19.4, -2.0), 280, 0.1);  // -6 m/s^2, moving left at 2 m/s
  ASSERT_EQ(pred->cars().size(), 1u);
  EXPECT_NEAR(pred->cars()[0].a_s, -6.0, 0.05);
  EXPECT_NEAR(pred->cars()[0].d_target, 6.0, 1e-9);  // the middle lane's centre
  const Predictor::Prediction at1 = pred->Predict(0, 1.0), at3 = pred->Predict(0, 3.0);
  EXPECT_NEAR(at1.v, 13.4, 0.1);
  EXPECT_NEAR(at1.d, 7.0, 0.05);
  EXPECT_NEAR(at1.v_d, -2.0, 1e-9);
  EXPECT_NEAR(at3.d, 6.0, 1e-9);  // arrived, and stays
  EXPECT_EQ(at3.v_d, 0.0);
  EXPECT_NEAR(at3.v, 19.4 - 6.0 * 2.0, 0.1);  // braked for brake_horizon (2 s), then holds
  // The constant-velocity predictor ignores both.
  auto cv = MakeConstantVelocityPredictor(line, o);
  cv->Observe(row(20.0, 0.0), 280, 0.0);
  cv->Observe(row(19.4, -2.0), 280, 0.1);
  EXPECT_NEAR(cv->Predict(0, 3.0).v, 19.4, 0.05);
  EXPECT_NEAR(cv->Predict(0, 3.0).d, 9.0, 0.05);
}

// With follow_gap, a braking car close behind a slower leader in its lane is predicted to brake
// until the gap (bumpers, the leader at its present speed) has opened to follow_gap; a braking
// car with no leader that close keeps brake_horizon, and so does every car with follow_gap 0.
TEST(PredictorTest, BrakingBehindALeaderLastsUntilTheGapOpens) {
  REQUIRE_UDACITY_MAP();
  const auto line = search::testing::UdacityLine();
  // Ego at s = 200; the follower at s = 240, 17 m/s, braking at 6 m/s^2 (read 0.1 s apart), and
  // a leader at 15 m/s `ahead` m further on (centre to centre), or none.
  const auto predicted_speed = [&](double follow_gap, double ahead) {
    PredictorOptions o;
    o.follow_gap = follow_gap;
    auto pred = MakeManoeuvrePredictor(line, o);
    for (const double t : {0.0, 0.1}) {
      std::vector<SensorCar> rows;
      const double v = 17.0 - 6.0 * t, s = 240 + 17.0 * t - 3.0 * t * t;
      const map::CartesianPose p = line->ToCartesian(s, 6.0);
      rows.push_back({0, p.x, p.y, v * std::cos(p.heading), v * std::sin(p.heading), s, 6.0});
      if (ahead > 0) {
        const double sl = 240 + ahead + 15.0 * t;
        const map::CartesianPose q = line->ToCartesian(sl, 6.0);
        rows.push_back(
            {1, q.x, q.y, 15.0 * std::cos(q.heading), 15.0 * std::sin(q.heading), sl, 6.0});
      }
      pred->Observe(rows, 200, t);
    }
    const TrackedCar& c = pred->cars()[0];
    EXPECT_NEAR(c.a_s, -6.0, 0.05);
    if (ahead > 0) {
      // The time the gap takes to open: gap + (15 - v) t + 3 t^2 = follow_gap.
      const TrackedCar& l = pred->cars()[1];
      const double gap = l.s - c.s - 0.5 * (l.length + c.length), b = l.v_s - c.v_s;
      const double t = (-b + std::sqrt(b * b + 2 * 6.0 * (follow_gap - gap))) / 6.0;
      if (gap < follow_gap) {
        EXPECT_GT(t, 0.3);
        EXPECT_LT(t, 1.9);
        EXPECT_NEAR(pred->Predict(0, 3.0).v, c.v_s + c.a_s * t, 0.05);
      }
    }
    return pred->Predict(0, 3.0).v;
  };
  const double horizon = 17.0 - 0.6 - 6.0 * 2.0;  // braked for brake_horizon (2 s), then holds
  EXPECT_NEAR(predicted_speed(0, 20), horizon, 0.1);
  EXPECT_GT(predicted_speed(18, 20), horizon + 3);     // the gap opens within about 1.3 s
  EXPECT_NEAR(predicted_speed(18, 40), horizon, 0.1);  // the leader is already far enough
  EXPECT_NEAR(predicted_speed(18, 0), horizon, 0.1);   // no leader: a hard brake of its own
}

// A lane drop (a zipper merge, an on-ramp's acceleration lane): a car in the lane that ends
// moves into the lane beside over the last merge_time s before the end, in both predictors; not
// when the end is no drop (a lane leaving the road), nor when the car reaches it past the
// horizon, nor with merge_time 0.
TEST(PredictorTest, ACarWhoseLaneDropsMergesBeforeTheEnd) {
  const std::vector<map::ReferenceLine::Point> pts = {{0, 0}, {400, 0}};
  auto line = map::ReferenceLine::FitOpen(pts, map::ReferenceLine::Options(), "straight");
  ASSERT_TRUE(line.ok()) << line.message();
  auto road_with = [&](bool drops) {
    map::LaneProfile left{{0, 400}, {0, 0}, {3.5, 3.5}};
    map::LaneProfile right{{0, 150}, {3.5, 3.5}, {7, 7}};
    right.drops = drops;
    auto road = map::Road::Make(*line, {left, right}, "drop");
    EXPECT_TRUE(road.ok()) << road.message();
    return *road;
  };
  PredictorOptions o;
  o.merge_time = 3.0;
  o.future_horizon = 8.0;
  // d is right of the line: y = -d. Car 1 in the right lane at s 100, 10 m/s: its front reaches
  // the end (s 150) after (50 - 2.4) / 10 = 4.76 s. Car 2 there at 5 m/s: after 29.5 s.
  const std::vector<SensorCar> rows = {{1, 100, -5.25, 10, 0, 0, 0, 4.8, 1.8},
                                       {2, 20, -5.25, 5, 0, 0, 0, 4.8, 1.8},
                                       {3, 120, -1.75, 10, 0, 0, 0, 4.8, 1.8},
                                       {4, 149, -5.25, 10, 0, 0, 0, 4.8, 1.8}};
  for (const bool manoeuvres : {false, true}) {
    SCOPED_TRACE(manoeuvres ? "manoeuvres" : "constant velocity");
    auto pred = manoeuvres ? MakeManoeuvrePredictor(road_with(true), o)
                           : MakeConstantVelocityPredictor(road_with(true), o);
    pred->Observe(rows, 0, 0.0);
    ASSERT_EQ(pred->cars().size(), 4u);
    EXPECT_NEAR(pred->Predict(0, 1.0).d, 5.25, 1e-6);       // not yet
    EXPECT_NEAR(pred->Predict(0, 1.76 + 1.5).d, 3.5, 0.01);  // half way over
    EXPECT_NEAR(pred->Predict(0, 1.76 + 1.5).v_d, -3.5 / 3.0, 1e-6);
    EXPECT_NEAR(pred->Predict(0, 4.8).d, 1.75, 1e-6);  // in the lane that goes on
    EXPECT_NEAR(pred->Predict(0, 4.8).s, 148, 0.01);    // at its speed all along
    EXPECT_NEAR(pred->Predict(1, 6.0).d, 5.25, 1e-6);   // the end is past the horizon
    EXPECT_NEAR(pred->Predict(2, 4.8).d, 1.75, 1e-6);   // the lane that goes on
    // A car at the end already moves over in 1 s, not at once.
    EXPECT_NEAR(pred->Predict(3, 0.5).d, 3.5, 1e-6);
    EXPECT_NEAR(pred->Predict(3, 1.0).d, 1.75, 1e-6);
  }
  auto no_drop = MakeConstantVelocityPredictor(road_with(false), o);
  no_drop->Observe(rows, 0, 0.0);
  EXPECT_NEAR(no_drop->Predict(0, 4.8).d, 5.25, 1e-6);
  o.merge_time = 0;
  auto off = MakeConstantVelocityPredictor(road_with(true), o);
  off->Observe(rows, 0, 0.0);
  EXPECT_NEAR(off->Predict(0, 4.8).d, 5.25, 1e-6);
}

// Lane-change ghosts (udacity-sim.md §8.5): a car braking behind a leader, faster than 15 mph,
// with its target lane clear within 20 m, is also predicted changing lanes (left from the
// middle lane, to the middle from the outer ones) after the rule's onset; not when the target
// lane is taken, not without a leader, not within 20 m of the ego.
TEST(PredictorTest, BrakingCarsBehindALeaderMayChangeLanes) {
  REQUIRE_UDACITY_MAP();
  const auto line = search::testing::UdacityLine();
  PredictorOptions o;
  o.lane_change_ghosts = true;
  // Ego at s = 200. Cars given at t = 0 as (s, d, v), all braking at 3 m/s^2 since then,
  // observed every 0.1 s from `from` to `to`.
  using Cars = std::vector<std::array<double, 3>>;
  auto observe = [&](Predictor& pred, const Cars& cars, double from, double to,
                     double ego_d = NAN) {
    for (double t = from; t <= to + 1e-9; t += 0.1) {
      std::vector<SensorCar> rows;
      for (size_t i = 0; i < cars.size(); ++i) {
        const auto [s0, d, v0] = cars[i];
        const double v = v0 - 3.0 * t, s = s0 + v0 * t - 1.5 * t * t;
        const map::CartesianPose p = line->ToCartesian(s, d);
        rows.push_back({static_cast<int>(i), p.x, p.y, v * std::cos(p.heading),
                        v * std::sin(p.heading), s, d});
      }
      pred.Observe(rows, 200, t, {}, ego_d);
    }
  };
  auto ghosts = [](const Predictor& pred) {
    int n = 0;
    for (const TrackedCar& c : pred.cars()) n += c.ghost;
    return n;
  };
  const Cars middle = {{240, 6.0, 15.0}, {255, 6.0, 12.0}};  // braking behind a leader
  {
    // A middle-lane car 40 m ahead: a ghost to the left, after the rule's onset.
    auto pred = MakeManoeuvrePredictor(line, o);
    observe(*pred, middle, 0.0, 0.1);
    ASSERT_EQ(ghosts(*pred), 1);
    const int g = static_cast<int>(pred->cars().size()) - 1;
    const TrackedCar& ghost = pred->cars()[g];
    EXPECT_EQ(ghost.id, 0);
    EXPECT_NEAR(ghost.d_target, 2.0, 1e-9);
    EXPECT_NEAR(pred->Predict(g, 0.5).d, 6.0, 0.05);  // waits for the onset
    EXPECT_NEAR(pred->Predict(g, 6.0).d, 2.0, 1e-9);   // then ends in the left lane
    EXPECT_NEAR(pred->Predict(0, 6.0).d, 6.0, 0.05);   // the car itself stays
    // Still so a second later: the onset has passed, the move starts at once.
    observe(*pred, middle, 0.2, 1.2);
    ASSERT_EQ(ghosts(*pred), 1);
    EXPECT_LT(pred->Predict(static_cast<int>(pred->cars().size()) - 1, 0.5).d, 6.0 - 0.5);
    // Switched off: none.
    o.lane_change_ghosts = false;
    auto plain = MakeManoeuvrePredictor(line, o);
    o.lane_change_ghosts = true;
    observe(*plain, middle, 0.0, 0.1);
    EXPECT_EQ(ghosts(*plain), 0);
  }
  {
    // A right-lane car: to the middle lane.
    auto pred = MakeManoeuvrePredictor(line, o);
    observe(*pred, {{240, 10.0, 15.0}, {255, 10.0, 12.0}}, 0.0, 0.1);
    ASSERT_EQ(ghosts(*pred), 1);
    EXPECT_NEAR(pred->cars().back().d_target, 6.0, 1e-9);
  }
  auto none = [&](const Cars& cars) {
    auto pred = MakeManoeuvrePredictor(line, o);
    observe(*pred, cars, 0.0, 0.1);
    return ghosts(*pred) == 0;
  };
  EXPECT_TRUE(none({{240, 6.0, 15.0}, {255, 6.0, 12.0}, {250, 2.0, 15.0}}));  // left lane taken
  EXPECT_TRUE(none({{240, 6.0, 15.0}}));                                      // no leader
  EXPECT_TRUE(none({{215, 6.0, 15.0}, {230, 6.0, 12.0}}));                    // within 20 m
  EXPECT_TRUE(none({{240, 6.0, 6.0}, {250, 6.0, 4.0}}));                      // under 15 mph
  // Within 20 m, the rule minds the ego only when it is near the target lane: with the ego in
  // the right lane (8 m from the left lane's centre) the car may move left right beside it,
  // and even from just behind it; never from 20 m behind.
  auto ghosts_with_ego = [&](const Cars& cars, double ego_d) {
    auto pred = MakeManoeuvrePredictor(line, o);
    observe(*pred, cars, 0.0, 0.1, ego_d);
    return ghosts(*pred);
  };
  const Cars near = {{215, 6.0, 15.0}, {230, 6.0, 12.0}};
  EXPECT_EQ(ghosts_with_ego(near, 2.0), 0);   // the ego in the left lane
  EXPECT_EQ(ghosts_with_ego(near, 4.5), 0);   // moving out of it: still minded
  EXPECT_EQ(ghosts_with_ego(near, 10.0), 1);  // the right lane
  EXPECT_EQ(ghosts_with_ego({{195, 6.0, 15.0}, {210, 6.0, 12.0}}, 10.0), 1);
  EXPECT_EQ(ghosts_with_ego({{175, 6.0, 15.0}, {190, 6.0, 12.0}}, 10.0), 0);
}

}  // namespace
}  // namespace frenetic::plan

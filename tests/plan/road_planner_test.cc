// The search planner on roads other than the Udacity loop (map::Road): open lines, lanes that
// end, trucks longer than the configured car, recorded futures. A small closed loop written
// here drives the ego exactly along its own path, 5 ticks (0.1 s) per exchange, as the
// CommonRoad runner does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "frenetic/map/reference_line.h"
#include "frenetic/map/road.h"
#include "frenetic/plan/planner.h"
#include "frenetic/plan/planner_config.h"
#include "plan/predictor.h"

namespace frenetic::plan {
namespace {

constexpr double kLane = 3.5;

PlannerConfig RoadConfig() {
  auto c = PlannerConfig::LoadDefault();
  EXPECT_TRUE(c.ok()) << c.message();
  PlannerConfig config = c.ok() ? *c : PlannerConfig::Defaults();
  config.PinDeadlines();
  EXPECT_TRUE(config.Set("prediction.lane_change_ghosts", 0).ok());
  EXPECT_TRUE(config.Set("check.ego_length", 4.5).ok());
  EXPECT_TRUE(config.Set("check.ego_width", 1.6).ok());
  return config;
}

std::shared_ptr<const map::ReferenceLine> Straight(double length) {
  const std::vector<map::ReferenceLine::Point> pts = {{0, 0}, {length, 0}};
  auto line = map::ReferenceLine::FitOpen(pts, map::ReferenceLine::Options(), "straight");
  EXPECT_TRUE(line.ok()) << line.message();
  return *line;
}

// `lanes` lanes of kLane m right of the line over [0, length]; lane `drop` (if >= 0) ends at
// drop_at.
std::shared_ptr<const map::Road> Road(double length, int lanes, int drop = -1,
                                      double drop_at = 0) {
  std::vector<map::LaneProfile> profiles;
  for (int l = 0; l < lanes; ++l) {
    const double end = l == drop ? drop_at : length;
    profiles.push_back({{0, end}, {l * kLane, l * kLane}, {(l + 1) * kLane, (l + 1) * kLane}});
  }
  auto road = map::Road::Make(Straight(length), profiles, "test road");
  EXPECT_TRUE(road.ok()) << road.message();
  return *road;
}

struct RoadCar {
  int id;
  double s, d, v, length, width;
  double vd = 0, d_end = 0;  // moves across at vd (m/s, right positive) until d reaches d_end
  double a = 0;              // m/s^2 along the road, until at rest
  // The car's d after t more seconds.
  double DAt(double t) const {
    if (vd == 0) return d;
    const double moved = d + vd * t;
    return vd > 0 ? std::min(moved, d_end) : std::max(moved, d_end);
  }
};

class OpenLoop {
 public:
  OpenLoop(std::shared_ptr<const map::Road> road, double s0, double d0, double v0)
      : road_(std::move(road)) {
    auto p = MakePlanner("search", RoadConfig(), road_);
    EXPECT_TRUE(p.ok()) << p.message();
    planner_ = std::move(p.value());
    const map::CartesianPose pose = road_->line().ToCartesian(s0, d0);
    x_ = pose.x;
    y_ = pose.y;
    yaw_ = pose.heading;
    speed_ = v0;
  }

  std::vector<RoadCar> cars;
  bool record_futures = false;  // hand the planner every car's future (constant velocity)
  double min_gap = 1e9;         // smallest distance between the ego's box and a car's, m
  double min_gap_first = 1e9;   // the same for cars[0] alone
  double max_excess = -1e9;     // largest reach of the ego's box past the road's edges, m
  double ego_s = 0, ego_d = 0;

  Telemetry Make() const {
    Telemetry t;
    t.x = x_;
    t.y = y_;
    t.yaw = yaw_;
    t.speed = speed_;
    t.previous_path_x = path_x_;
    t.previous_path_y = path_y_;
    for (const RoadCar& c : cars) {
      const map::CartesianPose p = road_->line().ToCartesian(c.s, c.d);
      SensorCar row{c.id, p.x, p.y, c.v * std::cos(p.heading), c.v * std::sin(p.heading), c.s, c.d};
      row.length = c.length;
      row.width = c.width;
      t.sensor_fusion.push_back(row);
      if (!record_futures) continue;
      CarFuture f;
      f.id = c.id;
      f.dt = 0.1;
      double s = c.s, v = c.v;
      for (int k = 0; k < 80; ++k) {
        const map::CartesianPose q = road_->line().ToCartesian(s, c.DAt(0.1 * k));
        f.x.push_back(q.x);
        f.y.push_back(q.y);
        f.v.push_back(v);
        f.heading.push_back(q.heading);
        for (int i = 0; i < 5; ++i) {  // as Cycle moves it, tick by tick
          s += v * kTickSeconds;
          v = std::max(0.0, v + c.a * kTickSeconds);
        }
      }
      t.futures.push_back(std::move(f));
    }
    return t;
  }

  // One exchange and 5 ticks along the path.
  const PlanResult& Cycle() {
    const PlanResult& r = planner_->Plan(Make());
    EXPECT_GE(r.x.size(), static_cast<size_t>(kMinPathPoints));
    path_x_ = r.x;
    path_y_ = r.y;
    for (int i = 0; i < 5 && path_x_.size() >= 2; ++i) {
      speed_ = std::hypot(path_x_[0] - x_, path_y_[0] - y_) / kTickSeconds;
      x_ = path_x_[0];
      y_ = path_y_[0];
      yaw_ = std::atan2(path_y_[1] - y_, path_x_[1] - x_);
      path_x_.erase(path_x_.begin());
      path_y_.erase(path_y_.begin());
      for (RoadCar& c : cars) {
        c.s += c.v * kTickSeconds;
        c.v = std::max(0.0, c.v + c.a * kTickSeconds);
        c.d = c.DAt(kTickSeconds);
      }
      Measure();
    }
    return r;
  }

 private:
  // Boxes aligned with the (straight) road: the ego's turned by its yaw.
  void Measure() {
    const map::FrenetPoint f = road_->line().ToFrenet(x_, y_);
    ego_s = f.s;
    ego_d = f.d;
    const double c = std::abs(std::cos(yaw_)), sn = std::abs(std::sin(yaw_));
    const double half_s = 0.5 * (4.5 * c + 1.6 * sn), half_d = 0.5 * (4.5 * sn + 1.6 * c);
    for (const RoadCar& car : cars) {
      const double gap = std::max(std::abs(car.s - f.s) - 0.5 * car.length - half_s,
                                  std::abs(car.d - f.d) - 0.5 * car.width - half_d);
      min_gap = std::min(min_gap, gap);
      if (&car == &cars.front()) min_gap_first = std::min(min_gap_first, gap);
    }
    const map::Road::Span e = road_->EdgesAt(f.s);
    ASSERT_TRUE(e.exists) << "the ego left the road's stretch at s " << f.s;
    max_excess = std::max({max_excess, e.left - (f.d - half_d), (f.d + half_d) - e.right});
  }

  std::shared_ptr<const map::Road> road_;
  std::unique_ptr<Planner> planner_;
  double x_ = 0, y_ = 0, yaw_ = 0, speed_ = 0;
  std::vector<double> path_x_, path_y_;
};

TEST(RoadPlannerTest, PassesATruckOnAnOpenRoadWithoutTouchingIt) {
  // A 16.5 m truck at 12 m/s in the ego's lane 70 m ahead; the ego at 25 m/s. With the
  // configured 4.8 m car the planner would cut back in front of its cab.
  OpenLoop loop(Road(1200, 2), 20, 1.5 * kLane, 25);
  loop.cars = {{1, 90, 1.5 * kLane, 12, 16.5, 2.55}};
  for (int k = 0; k < 200; ++k) loop.Cycle();
  EXPECT_GT(loop.min_gap, 0.2);
  EXPECT_GT(loop.ego_s, loop.cars[0].s + 30) << "the ego never passed the truck";
  EXPECT_LT(loop.max_excess, 0.0);
}

TEST(RoadPlannerTest, FollowsATruckByItsRearBumper) {
  // A 20 m truck at 12 m/s 60 m ahead in the ego's lane, the other lane taken by a convoy at
  // the same speed: the ego must follow the truck, whose rear is 10 m behind its centre.
  OpenLoop loop(Road(1000, 2), 10, 1.5 * kLane, 20);
  loop.cars = {{1, 70, 1.5 * kLane, 12, 20, 2.5}};
  for (int i = 0; i < 12; ++i) loop.cars.push_back({10 + i, -40.0 + 11 * i, 0.5 * kLane, 12, 6, 2});
  for (int k = 0; k < 150; ++k) loop.Cycle();
  EXPECT_GT(loop.min_gap, 0.0);
  EXPECT_GT(loop.min_gap_first, 5.0);  // 12 m/s: a time gap of ~1 s at least
  EXPECT_LT(loop.ego_s, loop.cars[0].s) << "the ego got past the truck";
}

TEST(RoadPlannerTest, LeavesALaneThatEndsBeforeItsEnd) {
  // Two lanes; the right one (the ego's) ends at 250 m.
  OpenLoop loop(Road(1000, 2, /*drop=*/1, /*drop_at=*/250), 10, 1.5 * kLane, 20);
  double changed_at = -1;  // s where the ego's centre crossed into the left lane
  for (int k = 0; k < 150; ++k) {
    loop.Cycle();
    if (changed_at < 0 && loop.ego_d < kLane) changed_at = loop.ego_s;
  }
  // Well before the end, as a driver who sees the lane end ahead (not at the last moment the
  // off-road check forces it).
  EXPECT_GT(changed_at, 0);
  EXPECT_LT(changed_at, 250 - 80) << "changed lanes at s " << changed_at;
  EXPECT_GT(loop.ego_s, 300);
  EXPECT_LT(loop.ego_d, kLane) << "the ego is not in the lane that continues";
  EXPECT_LT(loop.max_excess, 0.0) << "the ego's box left the road";
}

TEST(RoadPlannerTest, StopsBehindALaneEndWhenTheOtherLaneIsTaken) {
  // The right lane ends at 120 m; a long convoy fills the left lane alongside at the ego's speed.
  OpenLoop loop(Road(1000, 2, 1, 120), 10, 1.5 * kLane, 12);
  for (int i = 0; i < 6; ++i) loop.cars.push_back({10 + i, -20.0 + 12 * i, 0.5 * kLane, 12, 10, 2});
  for (int k = 0; k < 120; ++k) loop.Cycle();
  EXPECT_GT(loop.min_gap, 0.0);
  EXPECT_LT(loop.max_excess, 0.0);
}

TEST(RoadPlannerTest, RecordedFuturesAreWhatThePredictorPredicts) {
  auto road = Road(500, 2);
  PredictorOptions o;
  auto pred = MakeConstantVelocityPredictor(road, o);
  const map::CartesianPose p = road->line().ToCartesian(100, 1.75);
  SensorCar row{7, p.x, p.y, 10, 0, 100, 1.75};
  // Recorded: it brakes to rest in 2 s and moves 3.5 m right meanwhile.
  CarFuture f;
  f.id = 7;
  f.dt = 0.1;
  double s = 100;
  for (int k = 0; k <= 20; ++k) {
    const double v = 10 - 0.5 * k;
    const map::CartesianPose q = road->line().ToCartesian(s, 1.75 + 3.5 * k / 20.0);
    f.x.push_back(q.x);
    f.y.push_back(q.y);
    f.v.push_back(v);
    f.heading.push_back(q.heading);
    s += v * 0.1;
  }
  const std::vector<SensorCar> rows = {row};
  const std::vector<CarFuture> futures = {f};
  pred->Observe(rows, 90, 0.0, futures);
  ASSERT_EQ(pred->cars().size(), 1u);
  EXPECT_TRUE(pred->cars()[0].recorded);
  const Predictor::Prediction at1 = pred->Predict(0, 1.0);  // sample 10
  EXPECT_NEAR(at1.d, 1.75 + 1.75, 1e-3);
  EXPECT_NEAR(at1.v, 5.0, 1e-6);
  const Predictor::Prediction after = pred->Predict(0, 5.0);  // past the end: at rest
  EXPECT_NEAR(after.s, pred->Predict(0, 2.0).s, 1e-9);
  // A future with a NaN is not used: constant velocity instead.
  std::vector<CarFuture> bad = futures;
  bad[0].x[3] = NAN;
  pred->Observe(rows, 90, 0.0, bad);
  EXPECT_FALSE(pred->cars()[0].recorded);
  EXPECT_NEAR(pred->Predict(0, 1.0).s, 10 + 10.0, 1e-6);
}

TEST(RoadPlannerTest, ACarToComeIsAbsentUntilItsFutureStarts) {
  // A car not there yet (no row) enters 1.5 s from now 40 m behind the ego at 30 m/s, as a
  // recorded car entering the map behind does. Before then it is out of reach (kAbsentS); from
  // then on it is its recording. A future that starts later for a car that has a row is that
  // row's car, not a second one.
  auto road = Road(500, 2);
  PredictorOptions o;
  auto pred = MakeConstantVelocityPredictor(road, o);
  CarFuture f;
  f.id = 9;
  f.dt = 0.1;
  f.start = 1.5;
  f.length = 12;
  f.width = 2.5;
  for (int k = 0; k <= 40; ++k) {
    const map::CartesianPose q = road->line().ToCartesian(60 + 3.0 * k, 1.75);
    f.x.push_back(q.x);
    f.y.push_back(q.y);
    f.v.push_back(30);
    f.heading.push_back(q.heading);
  }
  const std::vector<CarFuture> futures = {f};
  pred->Observe({}, 100, 0.0, futures);
  ASSERT_EQ(pred->cars().size(), 1u);
  const TrackedCar& car = pred->cars()[0];
  EXPECT_EQ(car.id, 9);
  EXPECT_TRUE(car.recorded);
  EXPECT_DOUBLE_EQ(car.appears, 1.5);
  EXPECT_DOUBLE_EQ(car.length, 12);
  EXPECT_DOUBLE_EQ(car.s, kAbsentS);
  EXPECT_DOUBLE_EQ(pred->Predict(0, 0.0).s, kAbsentS);
  EXPECT_DOUBLE_EQ(pred->Predict(0, 1.49).s, kAbsentS);
  EXPECT_NEAR(pred->Predict(0, 1.5).s, -40.0, 1e-6);  // its first sample, relative to the ego
  EXPECT_NEAR(pred->Predict(0, 2.5).s, -40.0 + 30.0, 1e-6);
  EXPECT_NEAR(pred->Predict(0, 2.5).d, 1.75, 1e-6);
  EXPECT_NEAR(pred->Predict(0, 2.5).v, 30.0, 1e-6);
  // With a row of the same id it is that row's car only.
  const map::CartesianPose p = road->line().ToCartesian(80, 1.75);
  const std::vector<SensorCar> rows = {{9, p.x, p.y, 10, 0, 80, 1.75}};
  pred->Observe(rows, 100, 0.0, futures);
  ASSERT_EQ(pred->cars().size(), 1u);
  EXPECT_DOUBLE_EQ(pred->cars()[0].appears, 0.0);
  EXPECT_NEAR(pred->Predict(0, 0.0).s, -20.0, 1e-6);
  // Out of range (its first sample 300 m away), or a bad start: no car.
  CarFuture far = f;
  for (double& x : far.x) x += 300;
  CarFuture bad = f;
  bad.start = NAN;
  pred->Observe({}, 100, 0.0, std::vector<CarFuture>{far, bad});
  EXPECT_TRUE(pred->cars().empty());
}

TEST(RoadPlannerTest, RecordedFuturesPredictAsFreshWhenTheRecordingMovesOn) {
  // A bend (300 m radius), three recorded cars: one changing lanes, one braking, one cruising.
  // The predictor keeps its projections of the samples from cycle to cycle (each cycle's
  // recording starts a step later): every prediction must be the one a fresh predictor makes,
  // bit for bit, with the recording's step a stride of two (0.1 s) or one (0.2 s).
  std::vector<map::ReferenceLine::Point> pts;
  for (int i = 0; i <= 60; ++i) {
    const double a = i * 10.0 / 300.0;
    pts.push_back({300 * std::sin(a), 300 * (1 - std::cos(a))});
  }
  auto line = map::ReferenceLine::FitOpen(pts, map::ReferenceLine::Options(), "bend");
  ASSERT_TRUE(line.ok()) << line.message();
  std::vector<map::LaneProfile> profiles;
  for (int l = 0; l < 3; ++l) {
    profiles.push_back({{0, 600}, {l * kLane, l * kLane}, {(l + 1) * kLane, (l + 1) * kLane}});
  }
  auto road = map::Road::Make(*line, profiles, "bend");
  ASSERT_TRUE(road.ok()) << road.message();
  const map::ReferenceLine& ln = (*road)->line();
  const RoadCar cars[] = {{1, 60, 0.5 * kLane, 20, 4.8, 2.0, 1.2, 1.5 * kLane},
                          {2, 90, 1.5 * kLane, 18, 4.8, 2.0, 0, 0, -3},
                          {3, 40, 2.5 * kLane, 25, 12, 2.5}};
  for (const double dt : {0.1, 0.2}) {
    SCOPED_TRACE(dt);
    PredictorOptions o;
    o.num_lanes = 3;
    o.lane_width = kLane;
    auto kept = MakeManoeuvrePredictor(*road, o);
    for (int step = 0; step < 12; ++step) {
      std::vector<SensorCar> rows;
      std::vector<CarFuture> futures;
      for (const RoadCar& c : cars) {
        CarFuture f;
        f.id = c.id;
        f.dt = dt;
        for (int q = step; q <= step + 60; ++q) {
          const double t = q * dt;
          const double v = std::max(c.v + c.a * t, 0.0);
          const double tv = c.a < 0 ? std::min(t, c.v / -c.a) : t;
          const map::CartesianPose p =
              ln.ToCartesian(c.s + c.v * tv + 0.5 * c.a * tv * tv, c.DAt(t));
          f.x.push_back(p.x);
          f.y.push_back(p.y);
          f.v.push_back(v);
          f.heading.push_back(p.heading);
        }
        rows.push_back({c.id, f.x[0], f.y[0], f.v[0] * std::cos(f.heading[0]),
                        f.v[0] * std::sin(f.heading[0]), c.s, c.d, c.length, c.width});
        futures.push_back(f);
      }
      const double ego_s = 50 + 20 * step * dt, now = step * dt;
      kept->Observe(rows, ego_s, now, futures);
      auto fresh = MakeManoeuvrePredictor(*road, o);
      fresh->Observe(rows, ego_s, now, futures);
      ASSERT_EQ(kept->cars().size(), 3u);
      ASSERT_EQ(fresh->cars().size(), 3u);
      for (int i = 0; i < 3; ++i) {
        ASSERT_TRUE(kept->cars()[i].recorded);
        for (double t = 0; t <= 9; t += 0.05) {
          const Predictor::Prediction a = kept->Predict(i, t), b = fresh->Predict(i, t);
          ASSERT_EQ(a.s, b.s) << "car " << i << " step " << step << " t " << t;
          ASSERT_EQ(a.d, b.d) << "car " << i << " step " << step << " t " << t;
          ASSERT_EQ(a.v, b.v) << "car " << i << " step " << step << " t " << t;
          ASSERT_EQ(a.v_d, b.v_d) << "car " << i << " step " << step << " t " << t;
        }
      }
    }
  }
}

TEST(RoadPlannerTest, AvoidsACutInItIsToldAbout) {
  // A car in the left lane 8 m ahead at the ego's speed cuts into the ego's lane over 1.5 s
  // while braking at 5 m/s^2; its rows give no lateral speed or deceleration (a predictor alone
  // sees it keep its lane and speed). With its recorded future the planner keeps clear of it.
  OpenLoop loop(Road(800, 2), 10, 1.5 * kLane, 20);
  loop.record_futures = true;
  RoadCar cutter{3, 18, 0.5 * kLane, 20, 4.8, 2.0};
  cutter.vd = kLane / 1.5;
  cutter.d_end = 1.5 * kLane;
  cutter.a = -5;
  loop.cars = {cutter};
  for (int k = 0; k < 60; ++k) loop.Cycle();
  EXPECT_GT(loop.min_gap, 0.0);
}

}  // namespace
}  // namespace frenetic::plan

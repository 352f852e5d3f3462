#include "frenetic/map/road.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace frenetic::map {
namespace {

std::shared_ptr<const ReferenceLine> Straight(double length) {
  const std::vector<ReferenceLine::Point> pts = {{0, 0}, {length, 0}};
  auto line = ReferenceLine::FitOpen(pts, ReferenceLine::Options(), "straight");
  EXPECT_TRUE(line.ok()) << line.message();
  return *line;
}

// Two 3.5 m lanes right of the line for 0..300 m, and an on-ramp lane to their right from 50
// to 200 m that narrows from 4 m to 3.5 m.
std::vector<LaneProfile> OnRampLanes() {
  LaneProfile a{{0, 300}, {0, 0}, {3.5, 3.5}};
  LaneProfile b{{0, 300}, {3.5, 3.5}, {7, 7}};
  LaneProfile ramp{{50, 200}, {7, 7}, {11, 10.5}};
  ramp.speed_limit = 20;
  return {a, b, ramp};
}

TEST(RoadTest, UniformIsTheUdacityLayoutEverywhere) {
  const auto road = Road::Uniform(Straight(100), 3, 4.0);
  EXPECT_TRUE(road->uniform());
  EXPECT_EQ(road->num_lanes(), 3);
  EXPECT_EQ(road->lane_width(), 4.0);
  for (double s : {-1e6, 0.0, 55.5, 1e9}) {
    const Road::Span m = road->LaneAt(1, s);
    EXPECT_TRUE(m.exists);
    EXPECT_EQ(m.left, 4.0);
    EXPECT_EQ(m.right, 8.0);
    EXPECT_EQ(m.centre(), 6.0);
  }
  EXPECT_FALSE(road->LaneAt(3, 0).exists);
  EXPECT_FALSE(road->LaneAt(-1, 0).exists);
  const Road::Span e = road->EdgesAt(10);
  EXPECT_EQ(e.left, 0);
  EXPECT_EQ(e.right, 12);
  EXPECT_EQ(road->LaneOf(0, 10.5), 2);
  EXPECT_EQ(road->LaneOf(0, 12.5), -1);
}

TEST(RoadTest, LanesBeginEndAndNarrow) {
  auto made = Road::Make(Straight(300), OnRampLanes(), "ramp");
  ASSERT_TRUE(made.ok()) << made.message();
  const Road& road = **made;
  EXPECT_FALSE(road.uniform());
  EXPECT_EQ(road.lane_width(), 3.5);
  EXPECT_FALSE(road.LaneAt(2, 49).exists);
  const Road::Span mid = road.LaneAt(2, 125);
  ASSERT_TRUE(mid.exists);
  EXPECT_DOUBLE_EQ(mid.right, 10.75);
  EXPECT_DOUBLE_EQ(mid.centre(), 8.875);
  EXPECT_FALSE(road.LaneAt(2, 200.5).exists);
  EXPECT_EQ(road.LaneBegin(2), 50);
  EXPECT_EQ(road.LaneEnd(2), 200);
  EXPECT_EQ(road.SpeedLimit(2), 20);
  EXPECT_TRUE(std::isinf(road.SpeedLimit(0)));
  EXPECT_DOUBLE_EQ(road.EdgesAt(10).right, 7);
  EXPECT_DOUBLE_EQ(road.EdgesAt(100).right, 11 - 0.5 / 3);
  EXPECT_FALSE(road.EdgesAt(301).exists);
  EXPECT_EQ(road.LaneOf(100, 1.0), 0);
  EXPECT_EQ(road.LaneOf(100, 8.0), 2);
  EXPECT_EQ(road.LaneOf(20, 8.0), -1);
  // A move across ends in the centre of the lane half a lane on in its direction (its own, when
  // still short of it); none past the edge, and none toward a centre already passed.
  EXPECT_DOUBLE_EQ(road.CentreToward(100, 2.5, +1.0), 5.25);
  EXPECT_DOUBLE_EQ(road.CentreToward(100, 1.0, +1.0), 1.75);
  EXPECT_DOUBLE_EQ(road.CentreToward(100, 4.0, -1.0), 1.75);
  EXPECT_TRUE(std::isnan(road.CentreToward(20, 6.0, +1.0)));  // no ramp yet; own centre behind
  EXPECT_DOUBLE_EQ(road.CentreToward(100, 6.0, +1.0), road.LaneAt(2, 100).centre());  // the ramp
  EXPECT_TRUE(std::isnan(road.CentreToward(100, 1.0, -1.0)));  // own centre behind, no lane left
}

TEST(RoadTest, BadProfilesFailNamingTheLane) {
  auto lanes = OnRampLanes();
  lanes[1].right[1] = 3.0;  // right of its left border no more
  auto r = Road::Make(Straight(300), lanes, "net.xml");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.message(), "net.xml: lane 1: right border not right of the left one at station 1");
  lanes = OnRampLanes();
  lanes[2].s = {50, 50};
  r = Road::Make(Straight(300), lanes, "net.xml");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("lane 2: stations must increase"), std::string::npos) << r.message();
  lanes = OnRampLanes();
  lanes[0].left[0] = NAN;
  EXPECT_FALSE(Road::Make(Straight(300), lanes, "net.xml").ok());
  EXPECT_FALSE(Road::Make(Straight(300), {}, "net.xml").ok());
  lanes = OnRampLanes();
  lanes[0].s.pop_back();
  EXPECT_FALSE(Road::Make(Straight(300), lanes, "net.xml").ok());
}

}  // namespace
}  // namespace frenetic::map

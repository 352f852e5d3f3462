// BuildRoad: lanelets joined into a map::Road (route, skeleton, lanes), on hand-made scenarios
// and on every shared example file.
#include "frenetic/commonroad/road_builder.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "commonroad/scenario_xml.h"

namespace frenetic::commonroad {
namespace {

using testing::AddCurvedRoad;
using testing::AddSplitExit;
using testing::AddStraightRoad;
using testing::AddTwoWayRoad;
using testing::AddZipperMerge;
using testing::GoalLaneletXml;
using testing::GoalRectangleXml;
using testing::GoalTimeOnlyXml;
using testing::Lane;
using testing::LaneletXml;
using testing::Line;
using testing::Parse;
using testing::ScenarioXml;

BuiltRoad Build(const Scenario& sc, int problem = 0) {
  auto r = BuildRoad(sc, sc.problems.at(problem));
  EXPECT_TRUE(r.ok()) << r.message();
  return r.ok() ? *r : BuiltRoad{};
}

// Two 3.5 m lanes at s = 100 about lanelet 1's centre line (the reference): lane 0 left of it.
void ExpectLanesBesideLanelet1(const BuiltRoad& b) {
  const map::Road::Span left = b.road->LaneAt(0, 100), right = b.road->LaneAt(1, 100);
  ASSERT_TRUE(left.exists && right.exists);
  EXPECT_NEAR(left.left, -5.25, 0.01);
  EXPECT_NEAR(left.right, -1.75, 0.01);
  EXPECT_NEAR(right.left, -1.75, 0.01);
  EXPECT_NEAR(right.right, 1.75, 0.01);
}

TEST(RoadBuilderTest, TwoLanesOfAStraightRoad) {
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(1, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(50, 50)});
  const Scenario sc = Parse(xml);
  const BuiltRoad b = Build(sc);
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.start_lanelet, 1);
  EXPECT_EQ(b.route, std::vector<int>{1});
  ASSERT_EQ(b.road->num_lanes(), 2);
  EXPECT_EQ(b.lane_lanelets, (std::vector<std::vector<int>>{{2}, {1}}));
  // The reference is lanelet 1's centre (y = -1.75): lanelet 2 is left of it.
  ExpectLanesBesideLanelet1(b);
  EXPECT_NEAR(b.road->line().length(), 300, 0.5);
  EXPECT_NEAR(b.road->lane_width(), 3.5, 0.01);
}

TEST(RoadBuilderTest, TheOppositeLaneOfATwoWayRoadIsAnOncomingLaneOnTheLeft) {
  ScenarioXml xml;
  AddTwoWayRoad(xml, 300).Problem(1, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(50, 50)});
  const BuiltRoad b = Build(Parse(xml));
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.route, std::vector<int>{1});
  ASSERT_EQ(b.road->num_lanes(), 2);
  EXPECT_EQ(b.lane_lanelets, (std::vector<std::vector<int>>{{2}, {1}}));
  EXPECT_TRUE(b.road->Oncoming(0));
  EXPECT_FALSE(b.road->Oncoming(1));
  EXPECT_FALSE(b.road->Oncoming(2));
  // Its bounds read in the road's direction: the shared centre line is its right border.
  ExpectLanesBesideLanelet1(b);
  EXPECT_NEAR(b.road->LaneEnd(0) - b.road->LaneBegin(0), b.road->LaneEnd(1) - b.road->LaneBegin(1),
              0.01);
  // A one-way road has none.
  ScenarioXml one_way;
  AddStraightRoad(one_way, 300).Problem(1, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(50, 50)});
  const BuiltRoad o = Build(Parse(one_way));
  ASSERT_NE(o.road, nullptr);
  EXPECT_FALSE(o.road->Oncoming(0) || o.road->Oncoming(1));
}

TEST(RoadBuilderTest, ALaneDropKeepsTheReferenceOnTheLaneThatGoesOn) {
  // Right lane 1 (0-150 m) ends; the left lane is 2 (0-150) then 3 (150-300). The ego starts in
  // lane 1; the goal is lanelet 3.
  ScenarioXml xml;
  LaneletXml r1 = Lane(1, Line(0, 150, 0), Line(0, 150, -3.5));
  r1.adjacent_left = {{2, true}};
  LaneletXml l2 = Lane(2, Line(0, 150, 3.5), Line(0, 150, 0));
  l2.adjacent_right = {{1, true}};
  l2.successors = {3};
  LaneletXml l3 = Lane(3, Line(150, 300, 3.5), Line(150, 300, 0));
  l3.predecessors = {2};
  xml.Lanelet(r1).Lanelet(l2).Lanelet(l3).Problem(1, {10, -1.75}, 0, 20,
                                                  {GoalLaneletXml(3, 0, 100)});
  const Scenario sc = Parse(xml);
  const BuiltRoad b = Build(sc);
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.route, (std::vector<int>{1, 2, 3}));
  // The reference follows the lane that reaches the goal's section, not the start's.
  EXPECT_EQ(b.skeleton, (std::vector<int>{2, 3}));
  ASSERT_EQ(b.road->num_lanes(), 2);
  EXPECT_EQ(b.lane_lanelets, (std::vector<std::vector<int>>{{2, 3}, {1}}));
  // The right lane ends where lanelet 1 does (the network's ends are closed): a lane drop.
  // Both lanes run on 300 m before the map's start, the left one 300 m past the map's end.
  EXPECT_NEAR(b.road->LaneEnd(1), 150, 1.0);
  EXPECT_NEAR(b.road->LaneBegin(1), -300, 1.0);
  EXPECT_NEAR(b.road->LaneEnd(0), 600, 1.0);
  EXPECT_GT(b.road->LaneEnd(0), 290);
  EXPECT_NEAR(b.map_end, 300, 1.0);  // where the run-on starts
  // Its traffic has to move over before the end (the predictions' merge); the left lane's
  // end is the map's, no drop.
  EXPECT_TRUE(b.road->Drops(1));
  EXPECT_FALSE(b.road->Drops(0));
  // The left lane's centre is y = 1.75 in XY everywhere (the line itself).
  for (double s : {20.0, 120.0, 160.0, 250.0}) {
    const map::Road::Span a = b.road->LaneAt(0, s);
    ASSERT_TRUE(a.exists) << s;
    const map::CartesianPose p = b.road->line().ToCartesian(s, a.centre());
    EXPECT_NEAR(p.y, 1.75, 0.05) << "s " << s;
    EXPECT_NEAR(a.width(), 3.5, 0.1) << "s " << s;
  }
}

TEST(RoadBuilderTest, CurvedRoadKeepsItsWidth) {
  ScenarioXml xml;
  AddCurvedRoad(xml, 150, 1.2).Problem(1, {0, 0}, 0, 15, {GoalTimeOnlyXml(40, 40)});
  const BuiltRoad b = Build(Parse(xml));
  ASSERT_NE(b.road, nullptr);
  ASSERT_EQ(b.road->num_lanes(), 1);
  for (double s = 10; s < 170; s += 20) {
    const map::Road::Span a = b.road->LaneAt(0, s);
    ASSERT_TRUE(a.exists) << s;
    EXPECT_NEAR(a.width(), 4.0, 0.05) << s;
    EXPECT_NEAR(a.centre(), 0.0, 0.2) << s;
  }
}

TEST(RoadBuilderTest, ABorderDrawnInTwoPointsIsExactWhereTheLineBendsOffIt) {
  // The reference line follows 25 into 28, and the smooth fit bends (it overshoots before the
  // junction) where the borders, two points each over 160 m, run straight: the lanes' borders
  // are read at stations at most kStationStep apart, not at the lanelets' points alone.
  ScenarioXml xml;
  AddZipperMerge(xml).Problem(1, {-110, 8.75}, 0, 9, {GoalLaneletXml(24, 84, 85)});
  const BuiltRoad b = Build(Parse(xml));
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.skeleton.front(), 25);
  ASSERT_EQ(b.road->num_lanes(), 2);
  const map::ReferenceLine& line = b.road->line();
  double bend = 0;  // how far the line strays from lanelet 25's centre (y 8.75) before x = -20
  for (double x = -175; x <= -25; x += 1.0) {
    const map::FrenetPoint f = line.ToFrenet(x, 8.75);
    bend = std::max(bend, std::abs(f.d));
    // Both borders of the left lane (lane 0) where they really are, y = 10.5 and y = 7.
    const map::Road::Span lane = b.road->LaneAt(0, f.s);
    ASSERT_TRUE(lane.exists) << x;
    EXPECT_NEAR(line.ToCartesian(f.s, lane.left).y, 10.5, 0.02) << "x " << x;
    EXPECT_NEAR(line.ToCartesian(f.s, lane.right).y, 7.0, 0.02) << "x " << x;
  }
  EXPECT_GT(bend, 0.05);  // the scene tests what it means to: the line does bend off the border
  // A lanelet's stations: its two points and enough between them, at most kStationStep apart.
  const Scenario sc = Parse(xml);
  const LaneletStations st = ProjectLanelet(*sc.FindLanelet(25), line);
  ASSERT_GE(st.s.size(), 80u);
  for (size_t i = 1; i < st.s.size(); ++i) EXPECT_LE(st.s[i] - st.s[i - 1], kStationStep + 0.1) << i;
}

TEST(RoadBuilderTest, ALaneletOfAbsurdExtentIsProjectedAtBoundedCost) {
  // A hostile file's border segment of 1e7 m: at most 1000 stations between two points.
  const std::vector<map::ReferenceLine::Point> poly{{0, -1.75}, {300, -1.75}};
  auto line = map::ReferenceLine::FitOpen(poly, map::ReferenceLine::Options(), "test");
  ASSERT_TRUE(line.ok()) << line.message();
  Lanelet l;
  l.left = {{0, 0}, {1e7, 0}};
  l.right = {{0, -3.5}, {1e7, -3.5}};
  const LaneletStations st = ProjectLanelet(l, **line);
  EXPECT_LE(st.s.size(), 1001u);
  for (size_t i = 0; i < st.s.size(); ++i) {
    EXPECT_TRUE(std::isfinite(st.s[i]) && std::isfinite(st.left[i]) && std::isfinite(st.right[i]));
  }
}

TEST(RoadBuilderTest, TheHalfOfAZipperMergeOffTheReferenceTapersOffItsLane) {
  // The reference follows 25 into 28; 26 goes on into 27, which converges onto 28 with no
  // adjacency between them. Lane 1 (26) goes on into 27 as far as 27 lies beside 28, a taper
  // that ends near where the merge does (x = 0: where it is narrower than 0.5 m), not where 26
  // does (x = -20).
  ScenarioXml xml;
  AddZipperMerge(xml).Problem(1, {-110, 8.75}, 0, 9, {GoalLaneletXml(24, 84, 85)});
  const BuiltRoad b = Build(Parse(xml));
  ASSERT_NE(b.road, nullptr);
  ASSERT_EQ(b.road->num_lanes(), 2);
  EXPECT_EQ(b.lane_lanelets[1], (std::vector<int>{26, 27}));
  const map::ReferenceLine& line = b.road->line();
  EXPECT_GT(b.road->LaneEnd(1), line.ToFrenet(-6, 5.25).s);  // 26 ends at x = -20
  EXPECT_LT(b.road->LaneEnd(1), line.ToFrenet(1, 5.25).s);
  for (double x : {-15.0, -10.0, -5.0}) {
    const double s = line.ToFrenet(x, 5.25).s;
    const map::Road::Span left = b.road->LaneAt(0, s), right = b.road->LaneAt(1, s);
    ASSERT_TRUE(left.exists && right.exists) << x;
    // Lane 1 from lane 0's right border (28's, moving right) to 27's right border (y = 3.5).
    EXPECT_NEAR(right.left, left.right, 0.01) << x;
    EXPECT_NEAR(line.ToCartesian(s, right.right).y, 3.5, 0.05) << x;
    EXPECT_GT(right.width(), 0.5) << x;
    EXPECT_LT(right.width(), 3.5) << x;
  }
  // Its end is a lane drop: 27 leads into 24, the lane the reference goes on along.
  EXPECT_TRUE(b.road->Drops(1));
}

TEST(RoadBuilderTest, GoalByRectangleRoutesIntoItsLane) {
  ScenarioXml xml;
  AddStraightRoad(xml, 300).Problem(1, {10, -1.75}, 0, 20,
                                    {GoalRectangleXml({200, 1.75}, 10, 3, 0, 0, 100)});
  const BuiltRoad b = Build(Parse(xml));
  EXPECT_EQ(b.route, (std::vector<int>{1, 2}));
  EXPECT_EQ(b.skeleton, std::vector<int>{1});
}

TEST(RoadBuilderTest, LanesSharingABoundAreNeighboursWhenTheFileSaysNothing) {
  // As in DEU_Muc-2: two lanes side by side, neither naming the other; the goal is in the left
  // one, the ego in the right one.
  ScenarioXml xml;
  xml.Lanelet(Lane(1, Line(0, 300, 0), Line(0, 300, -3.5)))
      .Lanelet(Lane(2, Line(0, 300, 3.5), Line(0, 300, 0)))
      .Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, 0, 100)});
  const BuiltRoad b = Build(Parse(xml));
  EXPECT_EQ(b.route, (std::vector<int>{1, 2}));
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.road->num_lanes(), 2);
  // Lanes 10 m apart are not neighbours.
  ScenarioXml apart;
  apart.Lanelet(Lane(1, Line(0, 300, 0), Line(0, 300, -3.5)))
      .Lanelet(Lane(2, Line(0, 300, 13.5), Line(0, 300, 10)))
      .Problem(1, {10, -1.75}, 0, 20, {GoalLaneletXml(2, 0, 100)});
  const Scenario sc = Parse(apart);
  EXPECT_FALSE(BuildRoad(sc, sc.problems[0]).ok());
}

TEST(RoadBuilderTest, AnExitThatSplitsOffIsFollowedAndTheOtherHalfIsNoNeighbour) {
  // The ego in the left lane, the goal on the ramp that splits off the right lane. The ramp's
  // left bound crosses the straight half's right bound where it bends away (x 320-340): that
  // is no neighbour's bound, so the ramp's lane does not jump across the straight half.
  ScenarioXml xml;
  AddSplitExit(xml).Problem(1, {20, 1.75}, 0, 25, {GoalLaneletXml(5, 0, 200)});
  const BuiltRoad b = Build(Parse(xml));
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.route, (std::vector<int>{2, 1, 5}));
  EXPECT_EQ(b.skeleton, (std::vector<int>{1, 5}));
  EXPECT_EQ(b.lane_lanelets, (std::vector<std::vector<int>>{{2}, {1, 5}}));
  // The left lane ends at the fork (its own way on leads elsewhere); the right one goes on
  // along the ramp, 3.5 m wide about the line.
  EXPECT_NEAR(b.road->LaneEnd(0), 200, 1.0);
  // That end is no lane drop: its traffic goes on along 3, off this road, not into the ramp.
  EXPECT_FALSE(b.road->Drops(0));
  for (double s : {100.0, 250.0, 350.0}) {
    const map::Road::Span r = b.road->LaneAt(1, s);
    ASSERT_TRUE(r.exists) << s;
    EXPECT_NEAR(r.width(), 3.5, 0.1) << s;
    EXPECT_NEAR(r.centre(), 0.0, 0.1) << s;
  }
  // The straight half is the route when the goal lies on it.
  ScenarioXml on;
  AddSplitExit(on).Problem(1, {20, 1.75}, 0, 25, {GoalLaneletXml(4, 0, 200)});
  const BuiltRoad straight = Build(Parse(on));
  ASSERT_NE(straight.road, nullptr);
  EXPECT_EQ(straight.lane_lanelets, (std::vector<std::vector<int>>{{2, 3}, {1, 4}}));
}

TEST(RoadBuilderTest, TheHalvesOfALaneWideningIntoTwoAreNeighbours) {
  // Lanelet 1 widens from 3.5 m to 7 m (its right bound moving out) and splits into 4 (left
  // half) and 5 (right half), side by side from the fork; the file names no adjacency. The
  // halves are neighbours: the goal's half is the reference's lane, the other one beside it.
  ScenarioXml xml;
  std::vector<Vec2> widening;
  for (double x = 0; x <= 100; x += 10) widening.push_back({x, -3.5 - 0.035 * x});
  LaneletXml l1 = Lane(1, Line(0, 100, 0), widening);
  l1.successors = {4, 5};
  LaneletXml l4 = Lane(4, Line(100, 400, 0), Line(100, 400, -3.5));
  l4.predecessors = {1};
  LaneletXml l5 = Lane(5, Line(100, 400, -3.5), Line(100, 400, -7));
  l5.predecessors = {1};
  xml.Lanelet(l1).Lanelet(l4).Lanelet(l5).Problem(1, {10, -2}, 0, 20,
                                                  {GoalLaneletXml(5, 0, 100)});
  const BuiltRoad b = Build(Parse(xml));
  ASSERT_NE(b.road, nullptr);
  EXPECT_EQ(b.route, (std::vector<int>{1, 5}));
  EXPECT_EQ(b.lane_lanelets, (std::vector<std::vector<int>>{{4}, {1, 5}}));
}

TEST(RoadBuilderTest, FailuresNameTheProblem) {
  ScenarioXml far;
  AddStraightRoad(far, 300).Problem(7, {10, 50}, 0, 20, {GoalTimeOnlyXml(50, 50)});
  Scenario sc = Parse(far);
  auto r = BuildRoad(sc, sc.problems[0]);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.message(), "test.xml: planning problem 7: no lanelet within 5.000000 m of the initial position");
  // A goal on a lanelet the start cannot reach (the other direction's road).
  ScenarioXml apart;
  AddStraightRoad(apart, 300);
  std::vector<Vec2> l9 = Line(0, 300, -10), r9 = Line(0, 300, -6.5);
  std::reverse(l9.begin(), l9.end());
  std::reverse(r9.begin(), r9.end());
  apart.Lanelet(Lane(9, l9, r9))
      .Problem(8, {10, -1.75}, 0, 20, {GoalLaneletXml(9, 0, 100)});
  sc = Parse(apart);
  r = BuildRoad(sc, sc.problems[0]);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("planning problem 8: no route from lanelet 1"), std::string::npos)
      << r.message();
}

TEST(RoadBuilderTest, EverySharedFileGivesARoadHoldingItsStartAndGoal) {
  const std::filesystem::path dir = std::filesystem::path(FRENETIC_SHARED_DIR) / "commonroad";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "no " << dir;
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".xml") continue;
    ++files;
    auto sc = LoadScenario(entry.path().string());
    ASSERT_TRUE(sc.ok()) << sc.message();
    for (const PlanningProblem& p : sc->problems) {
      auto b = BuildRoad(*sc, p);
      ASSERT_TRUE(b.ok()) << b.message();
      const map::Road& road = *b->road;
      const map::FrenetPoint f = road.line().ToFrenet(p.initial.position.x, p.initial.position.y);
      EXPECT_GE(road.LaneOf(f.s, f.d), 0) << entry.path() << ": the start is on no lane";
      for (const GoalState& g : p.goals) {
        for (const Shape& shape : g.shapes) {
          const Vec2 c = shape.Centroid();
          const map::FrenetPoint fg = road.line().ToFrenet(c.x, c.y);
          EXPECT_GE(road.LaneOf(fg.s, fg.d), 0) << entry.path() << ": the goal is on no lane";
        }
      }
    }
  }
  EXPECT_GE(files, 13);
}

}  // namespace
}  // namespace frenetic::commonroad

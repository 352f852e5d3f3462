#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "commonroad/scenario_xml.h"
#include "frenetic/commonroad/scenario.h"

namespace frenetic::commonroad {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using testing::AddStraightRoad;
using testing::GoalLaneletXml;
using testing::GoalRectangleXml;
using testing::GoalTimeOnlyXml;
using testing::IntervalXml;
using testing::Lane;
using testing::LaneletXml;
using testing::Line;
using testing::LineOf;
using testing::ScenarioXml;

std::string StraightScenario() {
  ScenarioXml xml("ZAM_Straight-1_1_T-1");
  AddStraightRoad(xml);
  xml.StaticObstacle(30, 4, 2, {100, -1.75}, 0.1);
  xml.DynamicObstacle(31, 4.5, 1.8,
                      {{0, {20, 1.75}, 0, 10}, {1, {21, 1.75}, 0, 10}, {2, {22, 1.75}, 0, 10}});
  xml.Problem(100, {10, -1.75}, 0, 20,
              {GoalLaneletXml(1, 20, 40),
               GoalRectangleXml({150, -1.75}, 10, 3.5, 0, 0, 50,
                                IntervalXml("velocity", 15, 25) +
                                    IntervalXml("orientation", -0.2, 0.2)),
               GoalTimeOnlyXml(30, 30)});
  return xml.Str();
}

TEST(ScenarioReaderTest, ReadsAHandMadeStraightRoad) {
  const std::string xml = StraightScenario();
  const StatusOr<Scenario> s = ParseScenario(xml, "straight.xml");
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(s->benchmark_id, "ZAM_Straight-1_1_T-1");
  EXPECT_EQ(s->version, "2020a");
  EXPECT_EQ(s->source, "straight.xml");
  EXPECT_DOUBLE_EQ(s->dt, 0.1);
  EXPECT_THAT(s->tags, ::testing::ElementsAre("highway", "multi_lane"));

  ASSERT_EQ(s->lanelets.size(), 2u);
  const Lanelet* right = s->FindLanelet(1);
  ASSERT_NE(right, nullptr);
  EXPECT_EQ(right->left.size(), 31u);
  EXPECT_DOUBLE_EQ(right->right.back().x, 300);
  EXPECT_DOUBLE_EQ(right->right.back().y, -3.5);
  ASSERT_TRUE(right->adjacent_left.has_value());
  EXPECT_EQ(right->adjacent_left->id, 2);
  EXPECT_TRUE(right->adjacent_left->same_direction);
  EXPECT_FALSE(right->adjacent_right.has_value());
  EXPECT_EQ(right->left_marking, LineMarking::kDashed);
  EXPECT_EQ(right->right_marking, LineMarking::kSolid);
  EXPECT_THAT(right->types, ::testing::ElementsAre("interstate"));
  EXPECT_EQ(right->line, LineOf(xml, "<lanelet id=\"1\">"));
  EXPECT_NEAR(right->Length(), 300, 1e-9);
  EXPECT_EQ(s->FindLanelet(3), nullptr);

  ASSERT_EQ(s->obstacles.size(), 2u);
  const Obstacle* parked = s->FindObstacle(30);
  ASSERT_NE(parked, nullptr);
  EXPECT_EQ(parked->role, ObstacleRole::kStatic);
  EXPECT_EQ(parked->type, "parkedVehicle");
  ASSERT_EQ(parked->shape.shapes.size(), 1u);
  EXPECT_EQ(parked->shape.shapes[0].kind, Shape::Kind::kRectangle);
  EXPECT_DOUBLE_EQ(parked->shape.shapes[0].length, 4);
  EXPECT_TRUE(parked->StateAt(1000).has_value());  // static: always there
  const Obstacle* car = s->FindObstacle(31);
  ASSERT_NE(car, nullptr);
  EXPECT_EQ(car->role, ObstacleRole::kDynamic);
  EXPECT_EQ(car->trajectory.size(), 2u);
  ASSERT_TRUE(car->StateAt(2).has_value());
  EXPECT_DOUBLE_EQ(car->StateAt(2)->position.x, 22);
  EXPECT_FALSE(car->StateAt(3).has_value());  // gone after its trajectory
  EXPECT_FALSE(car->OccupancyAt(3).has_value());
  EXPECT_EQ(car->LastStep(), 2);
  const std::optional<ShapeGroup> occupied = car->OccupancyAt(1);
  ASSERT_TRUE(occupied.has_value());
  EXPECT_TRUE(occupied->Contains({21 + 2.2, 1.75}));
  EXPECT_FALSE(occupied->Contains({21 + 2.3, 1.75}));

  ASSERT_EQ(s->problems.size(), 1u);
  const PlanningProblem* p = s->FindProblem(100);
  ASSERT_NE(p, nullptr);
  EXPECT_DOUBLE_EQ(p->initial.position.x, 10);
  EXPECT_DOUBLE_EQ(*p->initial.velocity, 20);
  EXPECT_DOUBLE_EQ(*p->initial.orientation, 0);
  ASSERT_EQ(p->goals.size(), 3u);
  EXPECT_THAT(p->goals[0].lanelets, ::testing::ElementsAre(1));
  EXPECT_EQ(p->goals[0].time->start, 20);
  EXPECT_EQ(p->goals[0].time->end, 40);
  ASSERT_EQ(p->goals[1].shapes.size(), 1u);
  EXPECT_DOUBLE_EQ(p->goals[1].velocity->end, 25);
  EXPECT_DOUBLE_EQ(p->goals[1].orientation->start, -0.2);
  EXPECT_FALSE(p->goals[2].HasPosition());
  EXPECT_FALSE(p->goals[2].velocity.has_value());
}

// A file in map-projection coordinates (UTM-like: half a million metres east, four million
// north) is read into a frame centred on its lanelets, rounded to the kilometre: every position
// moved alike (lanelets, obstacles' states, the problem's start and goal shapes), shapes in an
// obstacle's own frame and everything else as they are. One near its origin stays put.
TEST(ScenarioReaderTest, AFileFarFromItsOriginIsReadIntoALocalFrame) {
  const Vec2 far{500000.25, 4000000.5};
  ScenarioXml xml;
  testing::AddStraightRoadAt(xml, far, 300)
      .DynamicObstacle(5, 4.8, 2, {{0, far + Vec2{40, -1.75}, 0.1, 8},
                                   {1, far + Vec2{40.8, -1.75}, 0.1, 8}})
      .Problem(1, far + Vec2{10, -1.75}, 0.2, 20,
               {GoalRectangleXml(far + Vec2{150, -1.75}, 10, 3, 0.3, 50, 90)});
  auto sc = ParseScenario(xml.Str(), "far.xml");
  ASSERT_TRUE(sc.ok()) << sc.message();
  // The lanelets span x 0..300, y -3.5..3.5 from `far`: their centre rounds to (500000, 4000000).
  EXPECT_EQ(sc->origin.x, 500000.0);
  EXPECT_EQ(sc->origin.y, 4000000.0);
  auto near = [](Vec2 a, Vec2 b) { return std::hypot(a.x - b.x, a.y - b.y) < 1e-6; };
  EXPECT_TRUE(near(sc->lanelets[0].left.front(), Vec2{0.25, 0.5}));
  EXPECT_TRUE(near(sc->lanelets[0].right.back(), Vec2{300.25, -3.0}));
  const Obstacle* car = sc->FindObstacle(5);
  ASSERT_NE(car, nullptr);
  EXPECT_TRUE(near(car->initial.position, Vec2{40.25, -1.25}));
  ASSERT_EQ(car->trajectory.size(), 1u);
  EXPECT_TRUE(near(car->trajectory[0].position, Vec2{41.05, -1.25}));
  EXPECT_EQ(car->initial.orientation, 0.1);  // orientations and sizes as they are
  ASSERT_EQ(car->shape.shapes.size(), 1u);
  EXPECT_TRUE(near(car->shape.shapes[0].center, Vec2{}));  // the obstacle's own frame
  const PlanningProblem& p = sc->problems[0];
  EXPECT_TRUE(near(p.initial.position, Vec2{10.25, -1.25}));
  ASSERT_EQ(p.goals[0].shapes.size(), 1u);
  EXPECT_TRUE(near(p.goals[0].shapes[0].center, Vec2{150.25, -1.25}));
  EXPECT_EQ(p.goals[0].shapes[0].orientation, 0.3);

  ScenarioXml home;
  AddStraightRoad(home, 300).Problem(1, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(0, 40)});
  auto sc_home = ParseScenario(home.Str(), "home.xml");
  ASSERT_TRUE(sc_home.ok()) << sc_home.message();
  EXPECT_EQ(sc_home->origin.x, 0.0);
  EXPECT_EQ(sc_home->origin.y, 0.0);
  EXPECT_EQ(sc_home->lanelets[0].right.back().x, 300.0);
  EXPECT_EQ(sc_home->problems[0].initial.position.y, -1.75);
}

TEST(ScenarioReaderTest, SpeedLimitComesFromAReferencedMaxSpeedSign) {
  ScenarioXml xml;
  LaneletXml l = Lane(1, Line(0, 100, 0), Line(0, 100, -3.5));
  l.signs = {7, 8};
  xml.Lanelet(l).SpeedSign(7, 22.22).SpeedSign(8, 13.88);
  xml.Lanelet(Lane(2, Line(0, 100, 3.5), Line(0, 100, 0)));
  xml.Problem(1, {5, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const StatusOr<Scenario> s = ParseScenario(xml.Str(), "signs.xml");
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_TRUE(s->FindLanelet(1)->speed_limit.has_value());
  EXPECT_DOUBLE_EQ(*s->FindLanelet(1)->speed_limit, 13.88);  // the lower of the two
  EXPECT_FALSE(s->FindLanelet(2)->speed_limit.has_value());
  ASSERT_EQ(s->signs.size(), 2u);
  EXPECT_EQ(s->FindSign(7)->elements[0].sign_id, "274");
}

TEST(ScenarioReaderTest, IntervalsInStatesAreReadAsTheirMidpoints) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Raw(
      "<dynamicObstacle id=\"5\">\n<type>car</type>\n<shape><circle><radius>1</radius></circle>"
      "</shape>\n<initialState>\n<position><rectangle><length>2</length><width>1</width>"
      "<center><x>40</x><y>2</y></center></rectangle></position>\n"
      "<orientation><intervalStart>-0.1</intervalStart><intervalEnd>0.3</intervalEnd>"
      "</orientation>\n<time><exact>0</exact></time>\n"
      "<velocity><intervalStart>8</intervalStart><intervalEnd>12</intervalEnd></velocity>\n"
      "</initialState>\n</dynamicObstacle>\n");
  xml.Problem(1, {5, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const StatusOr<Scenario> s = ParseScenario(xml.Str(), "intervals.xml");
  ASSERT_TRUE(s.ok()) << s.message();
  const Obstacle* o = s->FindObstacle(5);
  ASSERT_NE(o, nullptr);
  EXPECT_DOUBLE_EQ(*o->initial.orientation, 0.1);
  EXPECT_DOUBLE_EQ(*o->initial.velocity, 10);
  EXPECT_DOUBLE_EQ(o->initial.position.x, 40);  // the region's centroid
  EXPECT_EQ(o->shape.shapes[0].kind, Shape::Kind::kCircle);
  // No trajectory: the obstacle exists at its initial step only.
  EXPECT_TRUE(o->StateAt(0).has_value());
  EXPECT_FALSE(o->StateAt(1).has_value());
}

TEST(ScenarioReaderTest, UnknownElementsAreIgnored) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Raw("<trafficLight id=\"77\"><cycle><cycleElement><duration>5</duration><color>red</color>"
          "</cycleElement></cycle></trafficLight>\n<intersection id=\"78\"/>\n<somethingNew a=\"1\">"
          "<deep><er/></deep></somethingNew>\n");
  xml.Problem(1, {5, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const StatusOr<Scenario> s = ParseScenario(xml.Str(), "unknown.xml");
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(s->lanelets.size(), 2u);
}

TEST(ScenarioReaderTest, UnequalBoundCountsGiveAResampledCenterLine) {
  ScenarioXml xml;
  // The left bound has 11 points, the right one 3: pairs by index would be meaningless.
  xml.Lanelet(Lane(1, Line(0, 100, 2), Line(0, 100, -2, 50)));
  xml.Problem(1, {5, 0}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const StatusOr<Scenario> s = ParseScenario(xml.Str(), "unequal.xml");
  ASSERT_TRUE(s.ok()) << s.message();
  const Lanelet& l = s->lanelets[0];
  EXPECT_EQ(l.left.size(), 11u);
  EXPECT_EQ(l.right.size(), 3u);
  const std::vector<Vec2> center = l.CenterLine();
  ASSERT_EQ(center.size(), 11u);
  for (size_t i = 0; i < center.size(); ++i) {
    EXPECT_NEAR(center[i].x, 10.0 * i, 1e-9);
    EXPECT_NEAR(center[i].y, 0, 1e-9);
  }
  EXPECT_NEAR(l.Length(), 100, 1e-9);
  EXPECT_EQ(l.Polygon().size(), 14u);
}

TEST(ScenarioReaderTest, RepeatedBoundPointsAreKeptRawAndCleanedInHelpers) {
  ScenarioXml xml;
  std::vector<Vec2> left = Line(0, 100, 2);
  left.insert(left.begin() + 3, left[3]);  // a repeated point, as some real files have
  std::vector<Vec2> right = Line(0, 100, -2);
  right.insert(right.begin() + 3, right[3]);
  xml.Lanelet(Lane(1, left, right));
  xml.Problem(1, {5, 0}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  const StatusOr<Scenario> s = ParseScenario(xml.Str(), "repeat.xml");
  ASSERT_TRUE(s.ok()) << s.message();
  const Lanelet& l = s->lanelets[0];
  EXPECT_EQ(l.left.size(), 12u);
  EXPECT_EQ(l.CleanLeft().size(), 11u);
  EXPECT_EQ(l.CenterLine().size(), 11u);
  EXPECT_EQ(l.Polygon().size(), 22u);
}

// A malformed file gives one line naming the source, the offending element's line and the element.
struct MalformedCase {
  const char* name;
  std::string xml;
  std::string at;       // text on the line the error must name
  std::string element;  // in the error's element path
  std::string message;  // in the error
};
void PrintTo(const MalformedCase& c, std::ostream* os) { *os << c.name; }

std::string ValidBody() {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Problem(1, {5, -1.75}, 0, 10, {GoalLaneletXml(1, 10, 20)});
  return xml.Str();
}

std::string Replace(std::string text, std::string_view from, std::string_view to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string WithBody(std::string_view extra) {
  ScenarioXml xml;
  AddStraightRoad(xml);
  xml.Raw(extra);
  xml.Problem(1, {5, -1.75}, 0, 10, {GoalTimeOnlyXml(10, 20)});
  return xml.Str();
}

std::vector<MalformedCase> MalformedCases() {
  const std::string valid = ValidBody();
  const std::string obstacle_head =
      "<dynamicObstacle id=\"9\">\n<type>car</type>\n<shape><rectangle><length>4</length><width>2"
      "</width></rectangle></shape>\n<initialState>\n<position><point><x>1</x><y>1</y></point>"
      "</position>\n<orientation><exact>0</exact></orientation>\n<time><exact>0</exact></time>\n"
      "</initialState>\n";
  // The obstacle's set-based prediction: one occupancy of the time and shape given (the end of
  // the obstacle's element included).
  const auto occupancy_set = [](const std::string& time,
                                const std::string& shape =
                                    "<rectangle><length>4</length><width>2</width></rectangle>") {
    return "<occupancySet>\n<occupancy>\n<shape>" + shape + "</shape>\n<time>" + time +
           "</time>\n</occupancy>\n</occupancySet>\n</dynamicObstacle>\n";
  };
  return {
      {"WrongRoot", Replace(Replace(valid, "<commonRoad ", "<commonroad "), "</commonRoad>", "</commonroad>"), "<commonroad ", "commonroad",
       "root element must be <commonRoad>"},
      {"BadVersion", Replace(valid, "commonRoadVersion=\"2020a\"", "commonRoadVersion=\"2018b\""),
       "<commonRoad ", "commonRoad", "2018b"},
      {"MissingTimeStepSize", Replace(valid, "timeStepSize=\"0.1\"", ""), "<commonRoad ",
       "commonRoad", "timeStepSize"},
      {"NegativeTimeStepSize", Replace(valid, "timeStepSize=\"0.1\"", "timeStepSize=\"-0.1\""),
       "<commonRoad ", "commonRoad", "timeStepSize must be positive"},
      {"NaNCoordinate", Replace(valid, "<x>10</x>", "<x>nan</x>"), "<x>nan</x>",
       "lanelet 1/leftBound/point/x", "'nan' is not a finite number"},
      {"InfiniteCoordinate", Replace(valid, "<y>-3.5</y>", "<y>inf</y>"), "<y>inf</y>",
       "lanelet 1/rightBound/point/y", "not a finite number"},
      {"TextCoordinate", Replace(valid, "<x>20</x>", "<x>twenty</x>"), "<x>twenty</x>",
       "lanelet 1/leftBound/point/x", "'twenty'"},
      {"MissingY", Replace(valid, "<y>0</y></point>", "</point>"), "<x>0</x></point>",
       "lanelet 1/leftBound/point", "missing <y>"},
      {"MissingLeftBound",
       Replace(Replace(valid, "<leftBound>", "<leftBoundX>"), "</leftBound>", "</leftBoundX>"),
       "<lanelet id=\"1\">", "lanelet 1", "missing <leftBound>"},
      {"BoundWithOnePoint",
       WithBody("<lanelet id=\"3\">\n<leftBound>\n<point><x>0</x><y>9</y></point>\n</leftBound>\n"
                "<rightBound>\n<point><x>0</x><y>5</y></point>\n<point><x>9</x><y>5</y></point>\n"
                "</rightBound>\n</lanelet>\n"),
       "<leftBound>\n<point><x>0</x><y>9</y>", "lanelet 3/leftBound", "at least two <point>s"},
      // A misplaced digit in one point: the bound runs 10,000 km out and back, or away from
      // its partner (the road's samples every 2 m would take minutes and gigabytes).
      {"BoundPointFarOff", Replace(valid, "<x>10</x>", "<x>10000000</x>"), "<lanelet id=\"1\">",
       "lanelet 1", "a bound 2.00003e+07 m long (at most 100000 m; a point far off its line?)"},
      {"BoundsApart", Replace(valid, "<y>-3.5</y>", "<y>-350</y>"), "<lanelet id=\"1\">",
       "lanelet 1", "its bounds do not run side by side (left 300 m long, right 636.644 m, at most "
       "163.664 m apart; their ends 350 m and 3.5 m apart, at most 100 m)"},
      {"BoundSpikeMidway",
       Replace(valid, "<point><x>150</x><y>-3.5</y></point>",
               "<point><x>150</x><y>-203.5</y></point>"),
       "<lanelet id=\"1\">", "lanelet 1", "(left 300 m long, right 680.5 m, at most 168.05 m apart"},
      {"SecondRightBound",
       Replace(valid, "<laneletType>",
               "<rightBound>\n<point><x>0</x><y>-3.5</y></point>\n<point><x>9</x><y>-3.5</y>"
               "</point>\n</rightBound>\n<laneletType>"),
       "<rightBound>\n<point><x>0</x><y>-3.5</y></point>\n<point><x>9</x>", "lanelet 1/rightBound",
       "a second <rightBound>"},
      {"EmptyBound", WithBody("<lanelet id=\"3\">\n<leftBound>\n</leftBound>\n<rightBound>\n"
                              "</rightBound>\n</lanelet>\n"),
       "<leftBound>\n</leftBound>", "lanelet 3/leftBound", "at least two <point>s"},
      {"UnknownSuccessor", Replace(valid, "<laneletType>", "<successor ref=\"99\"/>\n<laneletType>"),
       "<successor ref=\"99\"/>", "lanelet 1/successor", "ref 99 names no lanelet"},
      {"UnknownAdjacent", Replace(valid, "<adjacentLeft ref=\"2\"", "<adjacentLeft ref=\"42\""),
       "<adjacentLeft ref=\"42\"", "lanelet 1/adjacentLeft", "ref 42 names no lanelet"},
      {"BadDrivingDir", Replace(valid, "drivingDir=\"same\"", "drivingDir=\"sideways\""),
       "drivingDir=\"sideways\"", "lanelet 1/adjacentLeft", "drivingDir"},
      {"UnknownGoalLanelet", Replace(valid, "<lanelet ref=\"1\"/>", "<lanelet ref=\"5\"/>"),
       "<lanelet ref=\"5\"/>", "planningProblem 1/goalState/position/lanelet",
       "ref 5 names no lanelet"},
      {"DuplicateLaneletId", Replace(valid, "<lanelet id=\"2\">", "<lanelet id=\"1\">"),
       "<lanelet id=\"1\">\n<leftBound>\n<point><x>0</x><y>3.5", "lanelet 1", "duplicate id"},
      {"NoPlanningProblem",
       Replace(valid, valid.substr(valid.find("<planningProblem"),
                                   valid.find("</planningProblem>\n") + 19 -
                                       valid.find("<planningProblem")),
               ""),
       "<commonRoad ", "commonRoad", "no <planningProblem>"},
      {"NoGoalState",
       Replace(valid, valid.substr(valid.find("<goalState>"),
                                   valid.find("</goalState>") + 12 - valid.find("<goalState>")),
               ""),
       "<planningProblem id=\"1\">", "planningProblem 1", "missing <goalState>"},
      {"MissingInitialVelocity",
       Replace(valid, "<velocity><exact>10</exact></velocity>\n", ""),
       "<initialState>", "planningProblem 1/initialState", "missing <velocity>"},
      {"GoalPoint",
       Replace(valid, "<lanelet ref=\"1\"/>", "<point><x>1</x><y>2</y></point>"),
       "<point><x>1</x><y>2</y></point>", "goalState/position/point", "not a point"},
      {"GoalIntervalReversed",
       Replace(valid, "<intervalStart>10</intervalStart><intervalEnd>20</intervalEnd>",
               "<intervalStart>20</intervalStart><intervalEnd>10</intervalEnd>"),
       "<intervalStart>20", "goalState/time", "intervalStart is after intervalEnd"},
      {"NegativeRectangle",
       WithBody("<staticObstacle id=\"9\">\n<type>unknown</type>\n<shape><rectangle><length>-4"
                "</length><width>2</width></rectangle></shape>\n<initialState>\n<position><point>"
                "<x>1</x><y>1</y></point></position>\n<orientation><exact>0</exact></orientation>"
                "\n<time><exact>0</exact></time>\n</initialState>\n</staticObstacle>\n"),
       "<length>-4", "staticObstacle 9/shape/rectangle", "length and width must be positive"},
      {"PolygonWithTwoPoints",
       WithBody("<staticObstacle id=\"9\">\n<type>unknown</type>\n<shape><polygon><point><x>0</x>"
                "<y>0</y></point><point><x>1</x><y>0</y></point></polygon></shape>\n<initialState>"
                "\n<position><point><x>1</x><y>1</y></point></position>\n<orientation><exact>0"
                "</exact></orientation>\n<time><exact>0</exact></time>\n</initialState>\n"
                "</staticObstacle>\n"),
       "<polygon>", "staticObstacle 9/shape/polygon", "three distinct points"},
      {"MissingShape",
       WithBody("<staticObstacle id=\"9\">\n<type>unknown</type>\n<initialState>\n<position><point>"
                "<x>1</x><y>1</y></point></position>\n<orientation><exact>0</exact></orientation>"
                "\n<time><exact>0</exact></time>\n</initialState>\n</staticObstacle>\n"),
       "<staticObstacle id=\"9\">", "staticObstacle 9", "missing <shape>"},
      {"EmptyOccupancy",
       WithBody(obstacle_head + "<occupancySet><occupancy/></occupancySet>\n</dynamicObstacle>\n"),
       "<occupancySet>", "dynamicObstacle 9/occupancySet/occupancy", "missing <shape>"},
      {"EmptyOccupancySet",
       WithBody(obstacle_head + "<occupancySet>\n</occupancySet>\n</dynamicObstacle>\n"),
       "<occupancySet>", "dynamicObstacle 9/occupancySet", "no <occupancy>"},
      {"OccupancyWithoutTime",
       WithBody(obstacle_head + "<occupancySet>\n<occupancy>\n<shape><rectangle><length>4</length>"
                                "<width>2</width></rectangle></shape>\n</occupancy>\n"
                                "</occupancySet>\n</dynamicObstacle>\n"),
       "<occupancy>", "dynamicObstacle 9/occupancySet/occupancy", "missing <time>"},
      {"OccupancyShapeless",
       WithBody(obstacle_head + occupancy_set("<exact>1</exact>", "<point/>")), "<shape><point/>",
       "occupancySet/occupancy/shape", "no <rectangle>, <circle> or <polygon>"},
      {"OccupancyFlatPolygon",
       WithBody(obstacle_head +
                occupancy_set("<exact>1</exact>",
                              "<polygon><point><x>0</x><y>0</y></point>"
                              "<point><x>1</x><y>0</y></point><point><x>0</x><y>0</y>"
                              "</point></polygon>")),
       "<shape><polygon>", "occupancy/shape/polygon", "three distinct points"},
      {"OccupancyNaNRadius",
       WithBody(obstacle_head +
                occupancy_set("<exact>1</exact>", "<circle><radius>nan</radius></circle>")),
       "<radius>nan", "occupancy/shape/circle/radius", "not a finite number"},
      {"OccupancyTimeFraction", WithBody(obstacle_head + occupancy_set("<exact>1.5</exact>")),
       "<time><exact>1.5", "dynamicObstacle 9/occupancySet/occupancy/time", "integers"},
      {"OccupancyTimeHuge", WithBody(obstacle_head + occupancy_set("<exact>1e300</exact>")),
       "<time><exact>1e300", "occupancy/time", "integers in [0, 100000000]"},
      {"OccupancyTimeReversed",
       WithBody(obstacle_head +
                occupancy_set("<intervalStart>5</intervalStart><intervalEnd>2</intervalEnd>")),
       "<intervalStart>5", "occupancy/time", "intervalStart is after intervalEnd"},
      {"OccupancyAtTheInitialStep",
       WithBody(obstacle_head +
                occupancy_set("<intervalStart>0</intervalStart><intervalEnd>2</intervalEnd>")),
       "<intervalStart>0", "occupancy/time", "time step 0 is not after the initial state's (0)"},
      {"OccupancyTimeMissingEnd",
       WithBody(obstacle_head + occupancy_set("<intervalStart>1</intervalStart>")),
       "<time><intervalStart>1", "occupancy/time", "missing <intervalEnd>"},
      {"TrajectoryAndOccupancySet",
       WithBody(obstacle_head +
                "<trajectory>\n<state>\n<position><point><x>1</x><y>1</y></point>"
                "</position>\n<orientation><exact>0</exact></orientation>\n<time>"
                "<exact>1</exact></time>\n</state>\n</trajectory>\n" +
                occupancy_set("<exact>2</exact>")),
       "<trajectory>", "dynamicObstacle 9/trajectory", "both <trajectory> and <occupancySet>"},
      {"TrajectoryGap",
       WithBody(obstacle_head + "<trajectory>\n<state>\n<position><point><x>1</x><y>1</y></point>"
                                "</position>\n<orientation><exact>0</exact></orientation>\n<time>"
                                "<exact>3</exact></time>\n</state>\n</trajectory>\n"
                                "</dynamicObstacle>\n"),
       "<state>", "dynamicObstacle 9/trajectory/state", "time step 3 where 1 was due"},
      {"StateTimeInterval",
       WithBody(obstacle_head + "<trajectory>\n<state>\n<position><point><x>1</x><y>1</y></point>"
                                "</position>\n<orientation><exact>0</exact></orientation>\n<time>"
                                "<intervalStart>1</intervalStart><intervalEnd>2</intervalEnd></time>"
                                "\n</state>\n</trajectory>\n</dynamicObstacle>\n"),
       "<intervalStart>1</intervalStart><intervalEnd>2", "dynamicObstacle 9/trajectory/state/time",
       "must be <exact>"},
      {"MissingOrientation",
       Replace(valid, "<orientation><exact>0</exact></orientation>\n", ""), "<initialState>",
       "planningProblem 1/initialState", "missing <orientation>"},
      {"BadId", Replace(valid, "<lanelet id=\"2\">", "<lanelet id=\"two\">"), "<lanelet id=\"two\">",
       "lanelet two", "attribute id 'two' is not an integer"},
      {"HugeTimeStep", Replace(valid, "<time><exact>0</exact></time>",
                               "<time><exact>99999999999</exact></time>"),
       "<exact>99999999999", "planningProblem 1/initialState/time/exact", "not an integer"},
      {"SyntaxError", Replace(valid, "</rightBound>", "</rightBond>"), "</rightBond>",
       "XML syntax error", "mismatch"},
      // Bytes that are not text in a value: escaped, so the line stays one line of valid UTF-8
      // (JSON output and terminals); well-formed UTF-8 is kept as it is.
      {"BytesThatAreNotText", Replace(valid, "<x>10</x>", "<x>1\xff\x01\xc3\n0</x>"),
       "<x>1\xff", "lanelet 1/leftBound/point/x", "'1\\xff\\x01\\xc3 0' is not a finite number"},
      {"WellFormedUtf8", Replace(valid, "<x>10</x>", "<x>1\xc3\xa9</x>"), "<x>1\xc3",
       "lanelet 1/leftBound/point/x", "'1\xc3\xa9' is not a finite number"},
  };
}

class MalformedTest : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(MalformedTest, GivesOneLineNamingTheElementAndItsLine) {
  const MalformedCase& c = GetParam();
  const StatusOr<Scenario> s = ParseScenario(c.xml, "bad.xml");
  ASSERT_FALSE(s.ok()) << c.name;
  const std::string& m = s.message();
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_NO_THROW((void)nlohmann::json(m).dump()) << "not UTF-8: " << m;
  const int line = LineOf(c.xml, c.at);
  ASSERT_GT(line, 0) << c.at;
  EXPECT_THAT(m, StartsWith("bad.xml:" + std::to_string(line) + ": ")) << m;
  EXPECT_THAT(m, HasSubstr(c.element)) << m;
  EXPECT_THAT(m, HasSubstr(c.message)) << m;
}

INSTANTIATE_TEST_SUITE_P(Cases, MalformedTest, ::testing::ValuesIn(MalformedCases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ScenarioReaderTest, AFileThatIsNotThereIsAnErrorNamingIt) {
  const StatusOr<Scenario> s = LoadScenario("/nonexistent/dir/x.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("/nonexistent/dir/x.xml"));
  const StatusOr<Scenario> d = LoadScenario("/");
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.message(), HasSubstr("not a file"));
}

TEST(ScenarioReaderTest, EmptyAndNonXmlInputAreErrors) {
  for (const std::string_view text : {std::string_view(""), std::string_view("hello"),
                                      std::string_view("<?xml version='1.0'?>"),
                                      std::string_view("\0\0\0", 3)}) {
    const StatusOr<Scenario> s = ParseScenario(text, "junk.xml");
    ASSERT_FALSE(s.ok());
    EXPECT_THAT(s.message(), StartsWith("junk.xml:1: "));
  }
}

// Whatever is done to a valid file, the reader parses it or gives one line of the documented
// form; it never crashes (the sanitizer build runs this too).
void FuzzOne(const std::string& text, const std::string& what) {
  const StatusOr<Scenario> s = ParseScenario(text, "fuzz.xml");
  if (s.ok()) {
    // What was read can be asked for at any step.
    for (const Obstacle& o : s->obstacles) {
      for (int k = o.initial.time_step - 1; k <= std::min(o.LastStep(), o.initial.time_step + 12);
           ++k) {
        const std::optional<State> st = o.StateAt(k);
        const std::optional<ShapeGroup> occupied = o.OccupancyAt(k);
        EXPECT_EQ(st.has_value(), occupied.has_value())
            << what << ": obstacle " << o.id << " step " << k;
        if (st && st->velocity) {
          EXPECT_TRUE(std::isfinite(*st->velocity)) << what;
        }
      }
    }
    return;
  }
  // "fuzz.xml:<line>: <something>", one line of valid UTF-8.
  const std::string& m = s.message();
  EXPECT_NO_THROW((void)nlohmann::json(m).dump()) << what << ": not UTF-8: " << m;
  const std::string_view prefix = "fuzz.xml:";
  bool form = m.compare(0, prefix.size(), prefix) == 0 && m.find('\n') == std::string::npos;
  size_t i = prefix.size();
  while (form && i < m.size() && m[i] >= '0' && m[i] <= '9') ++i;
  form = form && i > prefix.size() && m.compare(i, 2, ": ") == 0 && m.size() > i + 2;
  EXPECT_TRUE(form) << what << ": " << m;
}

void Fuzz(const std::string& base, int truncations, int mutations, uint32_t seed) {
  for (int i = 0; i < truncations; ++i) {
    const size_t cut = base.size() * i / truncations;
    FuzzOne(base.substr(0, cut), "truncated at " + std::to_string(cut));
  }
  std::mt19937 rng(seed);
  const std::string junk = "<>/=\"'&;0123456789.-+eE naNinf\n\x01\xff";
  for (int i = 0; i < mutations; ++i) {
    std::string text = base;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = rng() % text.size();
      switch (rng() % 4) {
        case 0:  // overwrite a byte
          text[at] = junk[rng() % junk.size()];
          break;
        case 1:  // delete a run
          text.erase(at, 1 + rng() % 40);
          break;
        case 2:  // duplicate a run
          text.insert(at, text.substr(rng() % text.size(), 1 + rng() % 200));
          break;
        default:  // swap digits for text (one char: GCC 12's -Wrestrict misreads a C string here)
          text.insert(text.begin() + static_cast<std::ptrdiff_t>(at), 'x');
          break;
      }
      if (text.empty()) text.assign(1, '<');
    }
    FuzzOne(text, "mutation " + std::to_string(i));
  }
}

TEST(ScenarioReaderFuzzTest, HandMadeFileTruncatedAndMutated) {
  Fuzz(StraightScenario(), 400, 600, 1);
}

TEST(ScenarioReaderFuzzTest, SetBasedFileTruncatedAndMutated) {
  ScenarioXml xml("ZAM_SetBased-1_1_S-1");
  AddStraightRoad(xml);
  xml.SetBasedObstacle(40, 4, 2, {0, {20, -1.75}, 0, 10},
                       {{1, 1, testing::RectangleXml(5, 2, {21.5, -1.75}, 0.1)},
                        {2, 4, testing::PolygonXml({{20, -3}, {27, -3}, {27, 0}, {20, 0}})},
                        {4, 4, testing::CircleXml(1, {27, 1.75})}});
  xml.Problem(100, {10, -1.75}, 0, 20, {GoalTimeOnlyXml(5, 10)});
  Fuzz(xml.Str(), 300, 600, 3);
}

TEST(ScenarioReaderFuzzTest, RealSetBasedFileTruncatedAndMutated) {
  const std::string path =
      std::string(FRENETIC_SHARED_DIR "/commonroad/us101/USA_US101-1_1_S-1.xml");
  std::ifstream in(path);
  if (!in) GTEST_SKIP() << path << " is absent";
  std::stringstream text;
  text << in.rdbuf();
  Fuzz(text.str(), 100, 200, 4);
}

TEST(ScenarioReaderFuzzTest, RealFileTruncatedAndMutated) {
  const std::string path = std::string(FRENETIC_SHARED_DIR "/commonroad/DEU_Muc-2_1_T-1.xml");
  std::ifstream in(path);
  if (!in) GTEST_SKIP() << path << " is absent";
  std::stringstream text;
  text << in.rdbuf();
  Fuzz(text.str(), 300, 300, 2);
}

}  // namespace
}  // namespace frenetic::commonroad

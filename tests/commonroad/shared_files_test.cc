// Every CommonRoad example in ../shared/commonroad (real files nobody on this project wrote) is
// read, with the counts its README gives and sanity checks on what was read.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "frenetic/commonroad/road_area.h"
#include "frenetic/commonroad/scenario.h"

namespace frenetic::commonroad {
namespace {

std::string SharedDir() { return std::string(FRENETIC_SHARED_DIR "/commonroad"); }

std::vector<std::string> SharedFiles() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(SharedDir(), ec)) {
    if (e.path().extension() == ".xml") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

struct Expected {
  int lanelets;
  int obstacles_min, obstacles_max;
};

// From the README and the files (static obstacles included).
const std::map<std::string, Expected> kExpected = {
    {"DEU_A9-2_1_T-1", {3, 2, 2}},        {"DEU_A99-1_1_T-1", {3, 5, 5}},
    {"DEU_A99-1_2_T-1", {3, 5, 5}},       {"DEU_B471-1_1_T-1", {2, 3, 3}},
    {"DEU_Hhr-1_1", {89, 0, 0}},          {"DEU_Muc-2_1_T-1", {2, 5, 5}},
    {"DEU_Muc-2_2_T-1", {2, 5, 5}},       {"DEU_Muc-4_1_T-1", {2, 2, 2}},
    {"DEU_Muc-4_2_T-1", {2, 2, 2}},       {"USA_US101-10_1_T-1", {12, 43, 44}},
    {"USA_US101-10_3_T-1", {12, 43, 44}}, {"USA_US101-10_4_T-1", {12, 43, 44}},
    {"ZAM_Ramp-1_1-T-1", {11, 3, 3}},
};

TEST(SharedFilesTest, EveryExampleIsReadWithTheExpectedContents) {
  const std::vector<std::string> files = SharedFiles();
  if (files.empty()) GTEST_SKIP() << SharedDir() << " holds no CommonRoad files";
  EXPECT_EQ(files.size(), kExpected.size());
  for (const std::string& path : files) {
    SCOPED_TRACE(path);
    const StatusOr<Scenario> s = LoadScenario(path);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(s->version, "2020a");
    EXPECT_DOUBLE_EQ(s->dt, 0.1);
    const auto expected = kExpected.find(s->benchmark_id);
    ASSERT_NE(expected, kExpected.end()) << s->benchmark_id;
    EXPECT_EQ(static_cast<int>(s->lanelets.size()), expected->second.lanelets);
    EXPECT_GE(static_cast<int>(s->obstacles.size()), expected->second.obstacles_min);
    EXPECT_LE(static_cast<int>(s->obstacles.size()), expected->second.obstacles_max);
    ASSERT_GE(s->problems.size(), 1u);

    // Every reference resolves. (Not every successor link is mirrored by a predecessor link:
    // ZAM_Ramp-1_1-T-1 has 4 -> 8 and 5 -> 6 without the way back.)
    for (const Lanelet& l : s->lanelets) {
      EXPECT_GE(l.CleanLeft().size(), 2u);
      EXPECT_GE(l.CleanRight().size(), 2u);
      EXPECT_GT(l.Length(), 0);
      for (int id : l.successors) EXPECT_NE(s->FindLanelet(id), nullptr);
      for (int id : l.predecessors) EXPECT_NE(s->FindLanelet(id), nullptr);
      if (l.adjacent_left) {
        EXPECT_NE(s->FindLanelet(l.adjacent_left->id), nullptr);
      }
      if (l.adjacent_right) {
        EXPECT_NE(s->FindLanelet(l.adjacent_right->id), nullptr);
      }
      for (int id : l.traffic_signs) EXPECT_NE(s->FindSign(id), nullptr);
    }
    for (const PlanningProblem& p : s->problems) {
      ASSERT_FALSE(p.goals.empty());
      for (const GoalState& g : p.goals) {
        for (int id : g.lanelets) EXPECT_NE(s->FindLanelet(id), nullptr);
        ASSERT_TRUE(g.time.has_value());
        EXPECT_LE(g.time->start, g.time->end);
      }
      // The ego starts on a lanelet.
      const bool on_lanelet =
          std::any_of(s->lanelets.begin(), s->lanelets.end(), [&](const Lanelet& l) {
            return PolygonContains(l.Polygon(), p.initial.position);
          });
      EXPECT_TRUE(on_lanelet) << "problem " << p.id;
      EXPECT_TRUE(p.initial.velocity.has_value());
      EXPECT_TRUE(p.initial.orientation.has_value());
    }
    // Dynamic obstacles move in steps of the scenario's dt from step 0.
    for (const Obstacle& o : s->obstacles) {
      EXPECT_FALSE(o.shape.shapes.empty());
      if (o.role == ObstacleRole::kStatic) continue;
      EXPECT_EQ(o.initial.time_step, 0);
      for (size_t i = 0; i < o.trajectory.size(); ++i) {
        EXPECT_EQ(o.trajectory[i].time_step, static_cast<int>(i) + 1);
      }
    }
    // The road is one piece without gaps between its lane sections, but in DEU_Muc-2: its two
    // lanelets are not adjacent, and their shared line differs by up to 9 mm, which leaves slivers
    // between them that CommonRoad's solution checker (and RoadArea) count as no road. (With its
    // open ends extended, DEU_Hhr-1_1's network encloses one area.)
    const bool gaps = s->benchmark_id.rfind("DEU_Muc-2_", 0) == 0;
    const RoadArea road = RoadArea::Build(s->lanelets);
    EXPECT_TRUE(road.SkippedLanelets().empty());
    const RoadArea closed = RoadArea::Build(s->lanelets, RoadArea::kDefaultTolerance, 0.0);
    if (gaps) {
      EXPECT_GT(closed.HoleCount(), 0);
      // Grown by a centimetre, the lanelets close the slivers.
      const RoadArea grown = RoadArea::Build(s->lanelets, 0.01, 0.0);
      EXPECT_EQ(grown.PolygonCount(), 1);
      EXPECT_EQ(grown.HoleCount(), 0);
    } else {
      EXPECT_EQ(road.PolygonCount(), 1);
      EXPECT_EQ(closed.PolygonCount(), 1);
      EXPECT_EQ(closed.HoleCount(), 0);
    }
    for (const PlanningProblem& p : s->problems) EXPECT_TRUE(road.Contains(p.initial.position));
  }
}

TEST(SharedFilesTest, SpecificContents) {
  const std::string dir = SharedDir();
  if (!std::filesystem::exists(dir + "/DEU_Muc-4_2_T-1.xml")) GTEST_SKIP() << dir << " absent";
  const StatusOr<Scenario> muc = LoadScenario(dir + "/DEU_Muc-4_2_T-1.xml");
  ASSERT_TRUE(muc.ok()) << muc.message();
  // Goal by lanelet at one time step; a 50 km/h sign (13.88 m/s) on both lanelets.
  ASSERT_EQ(muc->problems[0].goals.size(), 1u);
  EXPECT_EQ(muc->problems[0].goals[0].lanelets, std::vector<int>{34784});
  EXPECT_EQ(muc->problems[0].goals[0].time->start, 50);
  EXPECT_EQ(muc->problems[0].goals[0].time->end, 50);
  for (const Lanelet& l : muc->lanelets) {
    ASSERT_TRUE(l.speed_limit.has_value());
    EXPECT_DOUBLE_EQ(*l.speed_limit, 13.88);
  }

  const StatusOr<Scenario> b471 = LoadScenario(dir + "/DEU_B471-1_1_T-1.xml");
  ASSERT_TRUE(b471.ok()) << b471.message();
  // The static obstacle's shape is centred on its own origin and placed by its state.
  const Obstacle* parked = b471->FindObstacle(399);
  ASSERT_NE(parked, nullptr);
  EXPECT_EQ(parked->role, ObstacleRole::kStatic);
  const std::optional<ShapeGroup> at = parked->OccupancyAt(40);
  ASSERT_TRUE(at.has_value());
  EXPECT_TRUE(at->Contains({89.09705, 35.35895}));
  EXPECT_FALSE(at->Contains({0, 0}));

  const StatusOr<Scenario> us101 = LoadScenario(dir + "/USA_US101-10_1_T-1.xml");
  ASSERT_TRUE(us101.ok()) << us101.message();
  const GoalState& goal = us101->problems[0].goals[0];
  ASSERT_EQ(goal.shapes.size(), 1u);
  EXPECT_EQ(goal.shapes[0].kind, Shape::Kind::kRectangle);
  EXPECT_DOUBLE_EQ(goal.velocity->start, 9.7894);
  EXPECT_DOUBLE_EQ(goal.orientation->end, -0.6427);
  EXPECT_EQ(goal.time->start, 70);

  const StatusOr<Scenario> muc2 = LoadScenario(dir + "/DEU_Muc-2_2_T-1.xml");
  ASSERT_TRUE(muc2.ok()) << muc2.message();
  EXPECT_FALSE(muc2->problems[0].goals[0].HasPosition());  // a goal by time only
}

}  // namespace
}  // namespace frenetic::commonroad

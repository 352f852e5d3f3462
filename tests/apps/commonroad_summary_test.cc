// The summary of `frenetic commonroad` on reports made by hand: families, problems infeasible at
// start counted apart, unsolved problems by their first failure, the comparison with references.
#include "apps/commonroad_summary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace frenetic::apps::commonroad_cli {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

TEST(CommonRoadFamilyTest, CountryAndMapWithASitesNumberDropped) {
  EXPECT_EQ(Family("USA_US101-15_2_T-1"), "USA_US101");
  EXPECT_EQ(Family("USA_US101-1_1_S-1"), "USA_US101");
  EXPECT_EQ(Family("DEU_LocationALower26-1_261504_T-1579"), "DEU_LocationALower");
  EXPECT_EQ(Family("DEU_LocationALower30-1_30451_T-526"), "DEU_LocationALower");
  EXPECT_EQ(Family("DEU_LocationCUpper6-1_6150_T-225"), "DEU_LocationCUpper");
  EXPECT_EQ(Family("ZAM_Zip-1_16_T-1"), "ZAM_Zip");
  EXPECT_EQ(Family("DEU_Muc-4_2_T-1"), "DEU_Muc");
  EXPECT_EQ(Family("ZAM_Ramp-1_1-T-1"), "ZAM_Ramp");
  EXPECT_EQ(Family("DEU_Hhr-1_1"), "DEU_Hhr");
  // A road's number stays: the A9 and the A99 are different roads.
  EXPECT_EQ(Family("DEU_A9-2_1_T-1"), "DEU_A9");
  EXPECT_EQ(Family("DEU_A99-1_2_T-1"), "DEU_A99");
  EXPECT_EQ(Family("DEU_B471-1_1_T-1"), "DEU_B471");
  // Ids outside the convention.
  EXPECT_EQ(Family("hand_made"), "hand_made");
  EXPECT_EQ(Family("12345-1"), "12345");
  EXPECT_EQ(Family(""), "");
}

cr::Failure Fail(cr::FailureKind kind, int step) {
  cr::Failure f;
  f.kind = kind;
  f.step = step;
  return f;
}

ProblemReport Solved(int goal_step, std::vector<double> ms = {1, 2}) {
  ProblemReport p;
  p.verdict.solved = true;
  p.verdict.goal_step = goal_step;
  p.plan_ms = std::move(ms);
  p.costs = {{"WX1", 100}, {"JB1", 0.1 * goal_step}};
  return p;
}

ProblemReport Failed(std::vector<cr::Failure> failures, std::vector<double> ms = {3}) {
  ProblemReport p;
  p.verdict.failures = std::move(failures);
  p.plan_ms = std::move(ms);
  p.costs = {{"WX1", 50}, {"JB1", 1}};
  return p;
}

ProblemReport Infeasible() {
  ProblemReport p;
  const cr::Failure f = Fail(cr::FailureKind::kCollision, 0);
  p.verdict.failures = {f};
  p.verdict.infeasible_at_start = f;
  p.stop = "infeasible_at_start";
  return p;
}

ReferenceReport Reference(std::optional<int> goal_step, double wx1) {
  ReferenceReport r;
  r.file = "human.xml";
  r.goal_step = goal_step;
  r.costs = {{"WX1", wx1}, {"JB1", 3}};
  return r;
}

FileReport File(std::string id, std::vector<ProblemReport> problems) {
  FileReport f;
  f.path = id + ".xml";
  f.benchmark_id = std::move(id);
  f.problems = std::move(problems);
  return f;
}

TEST(CommonRoadSummaryTest, FirstFailureIsTheEarliestThenTheVerdictsOrderTheGoalLast) {
  using K = cr::FailureKind;
  EXPECT_EQ(FirstFailure(Failed({Fail(K::kGoal, 49), Fail(K::kCollision, 12)})), "collision");
  EXPECT_EQ(FirstFailure(Failed({Fail(K::kCollision, 12), Fail(K::kOffRoad, 12)})), "collision");
  // A run ends at its collision: the goal's miss is judged at that same last step.
  EXPECT_EQ(FirstFailure(Failed({Fail(K::kGoal, 30), Fail(K::kCollision, 30)})), "collision");
  EXPECT_EQ(FirstFailure(Failed({Fail(K::kGoal, 30), Fail(K::kOffRoad, 31)})), "off_road");
  EXPECT_EQ(FirstFailure(Failed({Fail(K::kGoal, 30)})), "goal");
  ProblemReport no_road = Failed({Fail(K::kTrajectory, 0)});
  no_road.road_error = "no lanelet under the ego";
  EXPECT_EQ(FirstFailure(no_road), "road");
}

TEST(CommonRoadSummaryTest, CollisionsWithACarNewInTheSceneAreCountedPerFamily) {
  using K = cr::FailureKind;
  // A car that came into the scene `entered` s before it hit (none: there from the start).
  const auto hit = [](std::optional<double> entered, int step = 12) {
    cr::Failure f = Fail(K::kCollision, step);
    f.obstacle_id = 7;
    f.entered_s = entered;
    return f;
  };
  const std::vector<FileReport> files = {
      File("DEU_LocationALower26-1_1_T-1", {Failed({hit(0.4)}), Failed({hit(1.0)}),
                                            Failed({hit(1.5)}), Failed({hit(std::nullopt)})}),
      // Counted only when the collision is the problem's first failure.
      File("DEU_LocationAUpper26-1_1_T-1",
           {Failed({Fail(K::kOffRoad, 5), hit(0.2)}), Failed({Fail(K::kGoal, 40), hit(0.3, 40)})}),
      File("USA_US101-15_2_T-1", {Failed({hit(std::nullopt)}), Solved(20)}),
  };
  const Summary s = Summarise(files);
  EXPECT_EQ(s.families.at("DEU_LocationALower").collisions_entering, 2);
  EXPECT_EQ(s.families.at("DEU_LocationAUpper").collisions_entering, 1);
  EXPECT_EQ(s.families.at("USA_US101").collisions_entering, 0);
  EXPECT_EQ(s.all.collisions_entering, 3);
  EXPECT_EQ(s.all.unsolved.at("collision"), 6);
  const json j = SummaryJson(s, {"constant-velocity", 2});
  EXPECT_EQ(j.at("collisions_entering"), 3);
  EXPECT_EQ(j.at("families").at("DEU_LocationALower").at("collisions_entering"), 2);
  EXPECT_THAT(SummaryText(s, {"constant-velocity", 2}),
              HasSubstr("\ncollisions with a car that came into the scene at most 1 s before it "
                        "hit (after the start): 3 of 6 (DEU_LocationALower 2, "
                        "DEU_LocationAUpper 1)\n"));
  // Without a collision among the unsolved, no such line.
  EXPECT_THAT(SummaryText(Summarise({File("USA_US101-15_2_T-1", {Solved(20)})}), {"recorded", 2}),
              ::testing::Not(HasSubstr("came into the scene")));
}

TEST(CommonRoadSummaryTest, TheRescuesPartOfThePlanningTimeIsReportedApart) {
  ProblemReport a = Solved(40, {1, 5, 9});
  a.rescue_ms = {0.5, 4, 0.5};
  ProblemReport b = Solved(20, {2});
  b.rescue_ms = {0.25};
  const Summary s = Summarise({File("DEU_LocationALower26-1_1_T-1", {a}),
                               File("USA_US101-15_2_T-1", {b})});
  EXPECT_EQ(s.all.rescue_ms, (std::vector<double>{0.5, 4, 0.5, 0.25}));
  const json j = SummaryJson(s, {"recorded", 2});
  EXPECT_EQ(j.at("rescue_ms"), json({{"p50", 0.5}, {"p99", 4.0}, {"max", 4.0}}));
  EXPECT_EQ(j.at("plan_ms"), json({{"p50", 2.0}, {"p99", 9.0}, {"max", 9.0}}));
  EXPECT_EQ(j.at("families").at("USA_US101").at("rescue_ms"),
            json({{"p50", 0.25}, {"p99", 0.25}, {"max", 0.25}}));
  EXPECT_THAT(SummaryText(s, {"recorded", 2}),
              HasSubstr("\n  of it the rescue's checks and searches: p50 0.50 ms, p99 4.00 ms, "
                        "max 4.00 ms\n"));
}

TEST(CommonRoadSummaryTest, InfeasibleAtStartIsCountedApartPerFamilyAndOverall) {
  using K = cr::FailureKind;
  const std::vector<FileReport> files = {
      File("DEU_LocationALower26-1_1_T-1", {Solved(40, {1, 5}), Infeasible()}),
      File("DEU_LocationALower30-1_2_T-1",
           {Failed({Fail(K::kGoal, 70), Fail(K::kCollision, 3)}, {2, 4, 6})}),
      File("USA_US101-15_2_T-1", {Failed({Fail(K::kOffRoad, 5)}), Solved(20, {7})}),
  };
  FileReport unreadable;
  unreadable.path = "broken.xml";
  unreadable.error = "broken.xml:3: bad";
  std::vector<FileReport> with_error = files;
  with_error.push_back(unreadable);
  const Summary s = Summarise(with_error);

  EXPECT_EQ(s.all.problems, 5);
  EXPECT_EQ(s.all.infeasible_at_start, 1);
  EXPECT_EQ(s.all.solved, 2);
  EXPECT_EQ(s.all.unsolved, (std::map<std::string, int>{{"collision", 1}, {"off_road", 1}}));
  // Every kind of each unsolved problem; the infeasible one's collision is not among them.
  EXPECT_EQ(s.failures, (std::map<std::string, int>{{"collision", 1}, {"goal", 1}, {"off_road", 1}}));
  EXPECT_EQ(s.unreadable_files, 1);
  ASSERT_EQ(s.families.size(), 2u);
  const Counts& highd = s.families.at("DEU_LocationALower");
  EXPECT_EQ(highd.problems, 3);
  EXPECT_EQ(highd.infeasible_at_start, 1);
  EXPECT_EQ(highd.solved, 1);
  EXPECT_EQ(highd.unsolved, (std::map<std::string, int>{{"collision", 1}}));
  EXPECT_EQ(highd.plan_ms, (std::vector<double>{1, 5, 2, 4, 6}));
  const Counts& us101 = s.families.at("USA_US101");
  EXPECT_EQ(us101.problems, 2);
  EXPECT_EQ(us101.solved, 1);
  EXPECT_EQ(us101.unsolved, (std::map<std::string, int>{{"off_road", 1}}));

  const json j = SummaryJson(s, {"recorded", 2});
  EXPECT_EQ(j.at("problems"), 5);
  EXPECT_EQ(j.at("infeasible_at_start"), 1);
  EXPECT_EQ(j.at("solved"), 2);
  EXPECT_EQ(j.at("solved_share"), 0.5);  // 2 of the 4 feasible at start
  EXPECT_EQ(j.at("unsolved"), json({{"collision", 1}, {"off_road", 1}}));
  const json& f = j.at("families").at("DEU_LocationALower");
  EXPECT_EQ(f.at("problems"), 3);
  EXPECT_EQ(f.at("infeasible_at_start"), 1);
  EXPECT_EQ(f.at("solved"), 1);
  EXPECT_EQ(f.at("solved_share"), 0.5);
  EXPECT_EQ(f.at("cycles"), 5);
  EXPECT_EQ(f.at("plan_ms"), json({{"p50", 4.0}, {"p99", 6.0}, {"max", 6.0}}));
  EXPECT_FALSE(j.contains("comparison"));  // no solution files

  const std::string text = SummaryText(s, {"recorded", 2});
  EXPECT_THAT(text, HasSubstr("\nsolved 2 / 4 problems feasible at start (1 infeasible at start, "
                              "5 in all; recorded predictions, KS2), 1 file(s) unreadable\n"));
  EXPECT_THAT(text, HasSubstr("\n  DEU_LocationALower         3           1      1 / 2      4.00"
                              "      6.00      6.00  collision 1\n"));
  // Two cycles (3 and 7 ms): the nearest rank takes the lower as the median.
  EXPECT_THAT(text, HasSubstr("\n  USA_US101                  2           0      1 / 2      3.00"
                              "      7.00      7.00  off_road 1\n"));
  EXPECT_THAT(text, HasSubstr("\n  all                        5           1      2 / 4"));
  EXPECT_THAT(text, HasSubstr("collision 1, off_road 1\n"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("vs the reference")));
}

TEST(CommonRoadSummaryTest, ComparisonCountsEachOutcomeOnce) {
  using K = cr::FailureKind;
  ProblemReport cheaper = Solved(40);  // WX1 100
  cheaper.reference = Reference(30, 120);
  ProblemReport dearer = Solved(40);
  dearer.reference = Reference(30, 80);
  ProblemReport only_ours = Solved(40);
  only_ours.reference = Reference(std::nullopt, 10);
  ProblemReport only_human = Failed({Fail(K::kCollision, 4)});
  only_human.reference = Reference(30, 500);
  ProblemReport neither = Failed({Fail(K::kGoal, 80)});
  neither.reference = Reference(std::nullopt, 500);
  ProblemReport infeasible = Infeasible();
  infeasible.reference = Reference(30, 500);
  ProblemReport without = Solved(10);  // no reference: not counted

  EXPECT_EQ(CompareOutcome(cheaper), Outcome::kBothReachGoal);
  EXPECT_EQ(OursCheaper(cheaper, "WX1"), true);
  EXPECT_EQ(OursCheaper(dearer, "WX1"), false);
  EXPECT_EQ(OursCheaper(only_ours, "WX1"), std::nullopt);
  EXPECT_EQ(CompareOutcome(only_human), Outcome::kOnlyReference);
  EXPECT_EQ(CompareOutcome(infeasible), Outcome::kInfeasibleAtStart);

  const Summary s = Summarise(
      {File("DEU_LocationCLower6-1_1_T-1",
            {cheaper, dearer, only_ours, only_human, neither, infeasible, without})},
      {{"DEU_LocationCLower6-1_1_T-1", "a.solution.xml"}, {"ZAM_Gone-1_1_T-1", "gone.xml"}});
  const Comparison& c = s.comparison;
  EXPECT_EQ(c.solution_files, 2);
  EXPECT_EQ(c.with_reference, 6);
  EXPECT_EQ(c.infeasible_at_start, 1);
  EXPECT_EQ(c.both_reach_goal, 2);
  EXPECT_EQ(c.ours_cheaper_wx1, 1);
  EXPECT_EQ(c.ours_cheaper_jb1, 0);  // ours 4 s against 3 s in both
  EXPECT_EQ(c.only_ours, 1);
  EXPECT_EQ(c.only_reference, 1);
  EXPECT_EQ(c.neither, 1);
  EXPECT_EQ(c.unpaired, std::vector<std::string>{"gone.xml"});

  const json j = SummaryJson(s, {"recorded", 2}).at("comparison");
  EXPECT_EQ(j.at("compared"), 5);
  EXPECT_EQ(j.at("ours_cheaper_wx1_share"), 0.5);
  EXPECT_EQ(j.at("only_human"), 1);
  EXPECT_THAT(SummaryText(s, {"recorded", 2}),
              HasSubstr("vs the reference (human) trajectories: 6 problem(s) with one, 1 "
                        "infeasible at start (not compared)\n  both reach the goal 2: ours cheaper "
                        "(WX1 lower) in 1 = 50%, JB1 lower in 0\n  only ours reaches the goal 1, "
                        "only the human 1, neither 1\n"));
}

}  // namespace
}  // namespace frenetic::apps::commonroad_cli

#include "frenetic/drive/episode.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "drive/drive_test_util.h"
#include "frenetic/drive/record.h"
#include "frenetic/eval/oracle.h"
#include "frenetic/record/plan_json.h"

namespace frenetic::sim {
namespace {

using testing::KeepLanePlanner;

Scenario Quiet() {
  Scenario sc;
  sc.traffic.cars = 0;
  return sc;
}

TEST(Episode, LockstepConsumesOnePointPerExchangeFixedLatencyThree) {
  FRENETIC_REQUIRE_UDACITY(world);
  for (auto mode : {TimingOptions::Mode::kLockstep, TimingOptions::Mode::kFixed}) {
    Scenario sc = Quiet();
    sc.timing.mode = mode;
    sc.timing.l_old = 1;
    sc.timing.l_new = 2;
    auto sim = Simulator::Create(world, sc, 1);
    ASSERT_TRUE(sim.ok());
    Episode ep(std::move(*sim), EpisodeLimits{0, 0, 10, 60});
    KeepLanePlanner planner(world->line, 15);
    int expected = mode == TimingOptions::Mode::kLockstep ? 1 : 3;
    for (int i = 0; i < 20; ++i) {
      const plan::PlanResult& r = planner.Plan(ep.telemetry());
      ASSERT_TRUE(ep.Submit(r.x, r.y).ok());
      // 50 sent; on the first exchange the l_old ticks ran on no path at all.
      const int consumed = i == 0 ? expected - sc.timing.l_old * (expected > 1) : expected;
      EXPECT_EQ(static_cast<int>(ep.telemetry().previous_path_x.size()), 50 - consumed)
          << "exchange " << i;
    }
    EXPECT_NEAR(ep.sim().time(), 20 * expected * 0.02, 1e-9);
  }
}

TEST(Episode, RandomLatencyStaysInItsRanges) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scenario sc = Quiet();
  sc.timing.mode = TimingOptions::Mode::kRandom;
  auto sim = Simulator::Create(world, sc, 4);
  ASSERT_TRUE(sim.ok());
  Episode ep(std::move(*sim), EpisodeLimits{0, 0, 30, 60});
  KeepLanePlanner planner(world->line, 15);
  std::array<int, 5> seen{};
  while (!ep.done()) {
    const plan::PlanResult& r = planner.Plan(ep.telemetry());
    ASSERT_TRUE(ep.Submit(r.x, r.y).ok());
    ASSERT_GE(ep.last_l_old(), 0);
    ASSERT_LE(ep.last_l_old(), 2);
    ASSERT_GE(ep.last_l_new(), 1);
    ASSERT_LE(ep.last_l_new(), 2);
    ++seen[ep.last_l_old() + ep.last_l_new()];
  }
  EXPECT_EQ(seen[0], 0);
  for (int consumed = 1; consumed <= 4; ++consumed) EXPECT_GT(seen[consumed], 10) << consumed;
  EXPECT_EQ(ep.stop_reason(), "time");
}

TEST(Episode, GentleDriveWithoutTrafficHasNoIncidents) {
  FRENETIC_REQUIRE_UDACITY(world);
  KeepLanePlanner planner(world->line, 20);
  auto report = RunEpisode(world, Quiet(), 1, EpisodeLimits{0, 1.0, 0, 60}, planner, {});
  ASSERT_TRUE(report.ok()) << report.message();
  EXPECT_EQ(report->stop_reason, "distance");
  EXPECT_GE(report->miles(), 1.0);
  EXPECT_EQ(report->incidents, 0) << report->ToText();
  EXPECT_LT(report->max_speed_mph, 50);
  EXPECT_GT(report->max_speed_mph, 43);
  EXPECT_LT(report->max_acc, 5);
  EXPECT_NEAR(report->miles_to_first_incident, report->miles(), 1e-9);
  EXPECT_NEAR(report->best_miles_without_incident, report->miles(), 0.01);
  EXPECT_EQ(report->lane_changes, 0);
}

TEST(Episode, StallEndsAnEpisodeWhoseCarDoesNotMove) {
  FRENETIC_REQUIRE_UDACITY(world);
  KeepLanePlanner planner(world->line, 0.0, 0.0);
  auto report = RunEpisode(world, Quiet(), 1, EpisodeLimits{1, 0, 0, 5}, planner, {});
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(report->stop_reason, "stall");
  EXPECT_NEAR(report->sim_seconds, 5, 0.05);
}

std::string RecordBytes(const std::shared_ptr<const World>& world, std::uint64_t seed,
                        const std::string& path) {
  auto writer = RecordWriter::Open(path);
  EXPECT_TRUE(writer.ok()) << writer.message();
  KeepLanePlanner planner(world->line, 18);
  RunOptions options;
  options.record = writer->get();
  options.timing = false;
  options.planner_config = record::YamlToJson("weights: {speed: 1.5, lane: 2}\nname: test\n");
  auto report = RunEpisode(world, Scenario(), seed, EpisodeLimits{0, 0, 20, 60}, planner, options);
  EXPECT_TRUE(report.ok()) << report.message();
  writer->reset();
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Record, SameSeedGivesIdenticalBytesAndTheSchemaHasItsNames) {
  FRENETIC_REQUIRE_UDACITY(world);
  const std::string dir = ::testing::TempDir();
  const std::string a = RecordBytes(world, 9, dir + "/rec_a.jsonl");
  const std::string b = RecordBytes(world, 9, dir + "/rec_b.jsonl");
  const std::string c = RecordBytes(world, 10, dir + "/rec_c.jsonl");
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  std::istringstream lines(a);
  std::string line;
  std::vector<nlohmann::json> rows;
  while (std::getline(lines, line)) rows.push_back(nlohmann::json::parse(line));
  ASSERT_GE(rows.size(), 3u);
  const auto& h = rows.front();
  EXPECT_EQ(h["type"], "header");
  EXPECT_EQ(h["version"], 1);
  EXPECT_EQ(h["lanes"], 3);
  EXPECT_EQ(h["lane_width"], 4);
  EXPECT_EQ(h["seed"], 9);
  EXPECT_EQ(h["config"]["weights"]["lane"], 2);
  EXPECT_GT(h["centerline"].size(), 3000u);  // every ~2 m of a 6946 m loop
  EXPECT_EQ(h["car_length"], 4.6);
  const auto& e = rows[1];
  EXPECT_EQ(e["type"], "exchange");
  EXPECT_EQ(e["i"], 0);
  EXPECT_EQ(e["telemetry"]["sensor_fusion"].size(), 12u);
  EXPECT_EQ(e["telemetry"]["x"], 909.48);
  EXPECT_EQ(e["path"]["x"].size(), 50u);
  for (const char* key : {"status", "ms_total", "candidates_generated", "rejections",
                          "winner_costs", "candidates"}) {
    EXPECT_TRUE(e["plan"].contains(key)) << key;
  }
  for (const char* key : {"speed_mph", "acc", "jerk", "lane", "gap", "headway"}) {
    EXPECT_TRUE(e["metrics"].contains(key)) << key;
  }
  EXPECT_TRUE(e["incidents"].is_array());
  EXPECT_EQ(rows.back()["type"], "footer");
  EXPECT_NEAR(rows.back()["report"]["sim_seconds"].get<double>(), 20, 0.05);
}

TEST(RunEpisodes, ResultsDoNotDependOnTheNumberOfThreads) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto factory = [&]() -> StatusOr<std::unique_ptr<plan::Planner>> {
    return std::unique_ptr<plan::Planner>(new KeepLanePlanner(world->line, 21));
  };
  EpisodeLimits limits{0, 0, 40, 60};
  auto one = RunEpisodes(world, Scenario(), 5, 3, 1, limits, factory, false);
  auto two = RunEpisodes(world, Scenario(), 5, 3, 2, limits, factory, false);
  ASSERT_TRUE(one.ok()) << one.message();
  ASSERT_TRUE(two.ok()) << two.message();
  EXPECT_EQ(one->ToJson().dump(), two->ToJson().dump());
  ASSERT_EQ(one->episodes.size(), 3u);
  EXPECT_EQ(one->episodes[2].seed, 7u);
  EXPECT_GT(one->total_miles, 0.3);
  EXPECT_GE(one->worst, 0);
}

// The report without the judging's fields.
nlohmann::json Unjudged(nlohmann::json j) {
  j.erase("judged");
  for (auto& i : j["incident_log"]) i.erase("judgement");
  return j;
}

TEST(RunEpisode, JudgingReportsEveryIncidentAndNeverChangesTheDrive) {
  FRENETIC_REQUIRE_UDACITY(world);
  KeepLanePlanner planner(world->line, 22);  // keeps its lane into the traffic
  auto [plain, judged] = testing::DriveWithAndWithout(
      world, planner, 3, 90, [](RunOptions& o) { o.judge = JudgeOptions(); });
  ASSERT_TRUE(plain.ok() && judged.ok());
  ASSERT_GT(judged->incidents, 0);
  EXPECT_FALSE(plain->judged);
  EXPECT_FALSE(plain->ToJson().contains("judged"));
  ASSERT_TRUE(judged->judged);
  ASSERT_EQ(judged->judgements.size(), judged->incident_log.size());
  EXPECT_EQ(Unjudged(judged->ToJson()).dump(), plain->ToJson().dump());
  const nlohmann::json j = judged->ToJson();
  int counted = 0;
  for (const char* verdict : {"avoidable", "unavoidable", "undecided", "not_judged"}) {
    counted += j["judged"][verdict].get<int>();
  }
  EXPECT_EQ(counted, judged->incidents);
  const std::string text = judged->ToText();
  EXPECT_NE(text.find("judged          "), std::string::npos) << text;
  for (std::size_t i = 0; i < judged->judgements.size(); ++i) {
    const IncidentJudgement& v = judged->judgements[i];
    EXPECT_EQ(j["incident_log"][i]["judgement"]["verdict"], ToString(v.verdict));
    EXPECT_EQ(j["incident_log"][i]["judgement"]["ms"], 0);  // timing off
    EXPECT_NE(text.find(Describe(v)), std::string::npos) << Describe(v);
    EXPECT_LE(v.until, judged->incident_log[i].t + 2.0 + 1e-9);
  }
}

TEST(RunEpisodes, ProgressIsReportedAndChangesNothing) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto factory = [&]() -> StatusOr<std::unique_ptr<plan::Planner>> {
    return std::unique_ptr<plan::Planner>(new KeepLanePlanner(world->line, 21));
  };
  const EpisodeLimits limits{0, 0, 40, 60};
  auto quiet = RunEpisodes(world, Scenario(), 5, 3, 2, limits, factory, false);
  EpisodesOptions options;
  options.timing = false;
  std::vector<EpisodesProgress> seen;
  options.progress = [&seen](const EpisodesProgress& p) { seen.push_back(p); };
  auto shown = RunEpisodes(world, Scenario(), 5, 3, 2, limits, factory, options);
  ASSERT_TRUE(quiet.ok() && shown.ok());
  EXPECT_EQ(quiet->ToJson().dump(), shown->ToJson().dump());
  int finished = 0, done = 0;
  for (const EpisodesProgress& p : seen) {
    EXPECT_EQ(p.total, 3);
    EXPECT_GE(p.done, done);
    done = p.done;
    finished += p.episode_finished;
  }
  EXPECT_EQ(finished, 3);
  EXPECT_GT(seen.size(), 3u);  // calls while the episodes run as well
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back().done, 3);
  EXPECT_NEAR(seen.back().miles, shown->total_miles, 1e-9);
  EXPECT_EQ(seen.back().incidents, shown->incidents);
  EXPECT_EQ(seen.back().running_miles, 0);
}

TEST(RunEpisodes, JudgedVerdictsAddUp) {
  FRENETIC_REQUIRE_UDACITY(world);
  auto factory = [&]() -> StatusOr<std::unique_ptr<plan::Planner>> {
    return std::unique_ptr<plan::Planner>(new KeepLanePlanner(world->line, 22));
  };
  EpisodesOptions options;
  options.timing = false;
  options.judge = JudgeOptions();
  auto agg = RunEpisodes(world, Scenario(), 3, 2, 2, EpisodeLimits{0, 0, 60, 60}, factory, options);
  ASSERT_TRUE(agg.ok()) << agg.message();
  ASSERT_GT(agg->incidents, 0);
  ASSERT_TRUE(agg->judged);
  int sum = 0;
  for (int n : agg->verdicts) sum += n;
  EXPECT_EQ(sum, agg->incidents);
  const nlohmann::json j = agg->ToJson();
  EXPECT_EQ(j["judged"]["avoidable"], agg->verdicts[0]);
  EXPECT_NE(agg->ToText().find("judged          "), std::string::npos);
  options.judge = JudgeOptions();
  options.judge->budget_blocks = 0;
  EXPECT_FALSE(
      RunEpisodes(world, Scenario(), 3, 2, 2, EpisodeLimits{0, 0, 60, 60}, factory, options).ok());
}

TEST(DriveBreakdown, ADriveReportsItsBreakdown) {
  FRENETIC_REQUIRE_UDACITY(world);
  testing::KeepLanePlanner planner(world->line, 20.0);
  EpisodeLimits limits;
  limits.laps = 0;
  limits.seconds = 60;
  auto report = RunEpisode(world, Scenario(), 3, limits, planner, RunOptions{});
  ASSERT_TRUE(report.ok()) << report.message();
  // The parts are within the whole, and the whole is the drive.
  const LapBreakdown& b = report->breakdown;
  EXPECT_NEAR(b.seconds, report->sim_seconds, 1e-6);
  EXPECT_NEAR(b.distance_m, report->distance_m, 1e-6);
  EXPECT_EQ(b.at_limit_s, 0);  // 20 m/s is 44.7 mph
  EXPECT_LE(b.following_open_s, b.following_s);
  EXPECT_LE(b.following_s, b.seconds);
  ASSERT_EQ(report->laps.size(), 1u);
  const nlohmann::json j = report->ToJson();
  ASSERT_TRUE(j.contains("breakdown"));
  EXPECT_EQ(j["breakdown"]["laps"].size(), 1u);
  EXPECT_NEAR(j["breakdown"]["seconds"].get<double>(), report->sim_seconds, 1e-6);
}

TEST(RunEpisode, TheOracleNeverChangesTheDriveAndIsReported) {
  FRENETIC_REQUIRE_UDACITY(world);
  testing::KeepLanePlanner planner(world->line, 15);
  auto [plain, searched] = testing::DriveWithAndWithout(
      world, planner, 5, 30, [](RunOptions& o) { o.oracle = OracleOptions(); });
  ASSERT_TRUE(plain.ok() && searched.ok());
  EXPECT_FALSE(plain->oracle_run);
  ASSERT_TRUE(searched->oracle_run);
  nlohmann::json j = searched->ToJson();
  ASSERT_TRUE(j.contains("oracle"));
  EXPECT_DOUBLE_EQ(j["oracle"]["mph"].get<double>(), searched->oracle.mph());
  EXPECT_EQ(j["oracle"]["windows"].size(), searched->oracle.windows.size());
  // 15 m/s kept from a standstill: the search is faster than that.
  EXPECT_GT(searched->oracle.mph(), searched->oracle.driven_mph() + 1.0);
  EXPECT_NEAR(searched->oracle.seconds, 30.0, 0.6);
  j.erase("oracle");
  EXPECT_EQ(j.dump(), plain->ToJson().dump());
  EXPECT_NE(searched->ToText().find("oracle          "), std::string::npos);
}

TEST(RunEpisode, TheOracleWithAForesightPlansAheadOnlyThatFarAndSaysSo) {
  FRENETIC_REQUIRE_UDACITY(world);
  testing::KeepLanePlanner planner(world->line, 15);
  const EpisodeLimits limits{0, 0, 30, 60};
  RunOptions options;
  options.timing = false;
  options.oracle = OracleOptions();
  const auto with_whole = RunEpisode(world, Scenario(), 5, limits, planner, options);
  options.oracle->foresight = 2.7;  // searched as 2.5 s: whole 0.5 s stages
  const auto with_ahead = RunEpisode(world, Scenario(), 5, limits, planner, options);
  ASSERT_TRUE(with_whole.ok() && with_ahead.ok());
  const OracleResult& r = with_ahead->oracle;
  EXPECT_DOUBLE_EQ(r.foresight, 2.5);
  EXPECT_DOUBLE_EQ(with_whole->oracle.foresight, 0.0);
  // The same windows, each from the ego as it drove.
  ASSERT_EQ(r.windows.size(), with_whole->oracle.windows.size());
  EXPECT_DOUBLE_EQ(r.driven_m, with_whole->oracle.driven_m);
  const nlohmann::json j = with_ahead->ToJson();
  EXPECT_DOUBLE_EQ(j["oracle"]["foresight_s"].get<double>(), 2.5);
  EXPECT_EQ(j["oracle"]["stuck_windows"].get<int>(), r.stuck_windows);
  ASSERT_EQ(j["oracle"]["windows"].size(), r.windows.size());
  int stuck = 0;
  double through = 0, search = 0;
  for (std::size_t w = 0; w < r.windows.size(); ++w) {
    const OracleWindow& x = r.windows[w];
    EXPECT_EQ(j["oracle"]["windows"][w]["stuck_stage"].get<int>(), x.stuck_stage);
    EXPECT_DOUBLE_EQ(j["oracle"]["windows"][w]["search_m"].get<double>(), x.search_m);
    EXPECT_GE(x.best_m, std::max(x.driven_m, x.search_m));
    const std::size_t stages = with_whole->oracle.windows[w].driven_lanes.size();
    if (x.stuck_stage >= 0) {
      ++stuck;
      EXPECT_EQ(x.lanes.size(), static_cast<std::size_t>(x.stuck_stage));
    } else {
      // A stage taken at each.
      EXPECT_EQ(x.lanes.size(), stages);
      through += 0.5 * stages;
      search += x.search_m;
    }
  }
  EXPECT_EQ(stuck, r.stuck_windows);
  EXPECT_DOUBLE_EQ(r.through_seconds, through);
  EXPECT_DOUBLE_EQ(r.through_search_m, search);
  // 15 m/s kept on a road where it could go faster: the search beats it where it went through.
  ASSERT_GT(through, 0.0);
  EXPECT_GT(r.through_search_mph(), r.through_driven_mph() + 1.0);
  EXPECT_NE(with_ahead->ToText().find("foresight 2.5 s"), std::string::npos)
      << with_ahead->ToText();
}

// Counts the telemetry messages that came with cars' futures, and drives as KeepLanePlanner.
class FutureCounter : public testing::KeepLanePlanner {
 public:
  using KeepLanePlanner::KeepLanePlanner;
  const plan::PlanResult& Plan(const plan::Telemetry& t) override {
    ++messages;
    with_futures += !t.futures.empty();
    for (const plan::CarFuture& f : t.futures) longest = std::max(longest, f.x.size());
    return KeepLanePlanner::Plan(t);
  }
  int messages = 0, with_futures = 0;
  std::size_t longest = 0;
};

TEST(RunEpisode, PerfectPredictionsReachThePlannerOnlyWhenAskedFor) {
  FRENETIC_REQUIRE_UDACITY(world);
  const EpisodeLimits limits{0, 0, 20, 60};
  RunOptions options;
  options.timing = false;
  FutureCounter plain(world->line, 15), foreseeing(world->line, 15);
  ASSERT_TRUE(RunEpisode(world, Scenario(), 5, limits, plain, options).ok());
  options.foresee = 2.0;
  ASSERT_TRUE(RunEpisode(world, Scenario(), 5, limits, foreseeing, options).ok());
  EXPECT_GT(plain.messages, 100);
  EXPECT_EQ(plain.with_futures, 0);
  // Every message once the traffic is on the road; 2 s at 0.1 s: 21 samples.
  EXPECT_GT(foreseeing.with_futures, foreseeing.messages * 9 / 10);
  EXPECT_EQ(foreseeing.longest, 21u);
}

}  // namespace
}  // namespace frenetic::sim

// Closed-loop tuning on the smoke suite (tiny: two scenarios x two seeds, 20 s episodes, eight
// search evaluations). One full run is shared by the tests; the resume test re-runs from its
// truncated log. Everything is seeded, so the assertions are exact.
#include "frenetic/tune/tuner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "frenetic/map/track.h"
#include "frenetic/plan/planner_config.h"

namespace frenetic::tune {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::vector<std::string> ReadLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class TunerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(map::DefaultTrackPath())) {
      skip_ = "the bundled track " + map::DefaultTrackPath() + " is absent";
      return;
    }
    auto suite = LoadSuite(std::string(FRENETIC_SOURCE_DIR "/config/tune/smoke.yaml"));
    ASSERT_TRUE(suite.ok()) << suite.message();
    suite_ = new Suite(*suite);
    dir_ = fs::temp_directory_path() / ("frenetic_tune_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    auto evaluator = Evaluator::Create(*suite_, 2, Cluster::Local());
    ASSERT_TRUE(evaluator.ok()) << evaluator.message();
    TuneOptions options;
    options.log_path = (dir_ / "full.jsonl").string();
    progress_ = new std::vector<Progress>();
    options.progress = [](const Progress& p) { progress_->push_back(p); };
    auto result = Tune(*suite_, options, **evaluator);
    ASSERT_TRUE(result.ok()) << result.message();
    full_ = new TuneResult(*result);
  }
  static void TearDownTestSuite() {
    delete suite_;
    delete full_;
    delete progress_;
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_NE(full_, nullptr) << "the shared tuning run failed";
  }

  static inline std::string skip_;
  static inline fs::path dir_;
  static inline Suite* suite_ = nullptr;
  static inline TuneResult* full_ = nullptr;
  static inline std::vector<Progress>* progress_ = nullptr;
};

TEST_F(TunerTest, ImprovesHeldOutObjectiveFromPoorStart) {
  const TuneResult& r = *full_;
  std::printf("%s", r.ToTable().c_str());
  EXPECT_EQ(r.evaluations, suite_->search.budget);
  EXPECT_LE(r.tuned_train.objective, r.start_train.objective);
  // The point of tuning: seeds the search never saw get better too.
  EXPECT_LT(r.tuned_holdout.objective, r.start_holdout.objective);
  // The start is the dawdling efficiency weight 0.02; tuning must raise it.
  ASSERT_EQ(r.params[0].key, "weights.efficiency");
  EXPECT_DOUBLE_EQ(r.params[0].start, 0.02);
  EXPECT_GT(r.params[0].tuned, r.params[0].start);
  EXPECT_EQ(r.start_holdout.episodes, 4);
  EXPECT_GT(r.tuned_holdout.miles, 0);
}

TEST_F(TunerTest, TunedConfigRoundTripsWithTheTunedValues) {
  auto config = plan::PlannerConfig::Parse(full_->tuned_yaml, "tuned.yaml");
  ASSERT_TRUE(config.ok()) << config.message();
  for (const TunedValue& p : full_->params) {
    EXPECT_NEAR(config->value(p.key), p.tuned, 1e-6 * std::max(1.0, std::abs(p.tuned))) << p.key;
  }
  // Untouched keys keep the start config's values, deadlines included (pinned only while
  // evaluating).
  auto start = plan::PlannerConfig::LoadDefault();
  ASSERT_TRUE(start.ok());
  EXPECT_DOUBLE_EQ(config->value("budget_ms"), start->value("budget_ms"));
  EXPECT_DOUBLE_EQ(config->value("weights.collision"), start->value("weights.collision"));
}

TEST_F(TunerTest, LogsEveryEvaluationAndReportsProgress) {
  const auto lines = ReadLines((dir_ / "full.jsonl").string());
  // start on training seeds, the search, then default and tuned on held-out seeds.
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(1 + suite_->search.budget + 2));
  double best = 1e300;
  int search = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto j = nlohmann::json::parse(lines[i]);
    EXPECT_EQ(j.at("i").get<int>(), static_cast<int>(i));
    EXPECT_TRUE(j.at("params").contains("weights.efficiency"));
    EXPECT_TRUE(j.at("components").contains("avg_speed_mph"));
    if (j.at("phase") == "search") {
      ++search;
      EXPECT_EQ(j.at("x").size(), suite_->params.size());
      best = std::min(best, j.at("objective").get<double>());
    }
  }
  EXPECT_EQ(search, suite_->search.budget);
  EXPECT_DOUBLE_EQ(best, full_->tuned_train.objective);
  EXPECT_EQ(nlohmann::json::parse(lines.front()).at("phase"), "start_train");
  EXPECT_EQ(nlohmann::json::parse(lines.back()).at("phase"), "tuned_holdout");

  ASSERT_EQ(progress_->size(), static_cast<std::size_t>(suite_->search.budget));
  for (std::size_t i = 0; i < progress_->size(); ++i) {
    EXPECT_EQ((*progress_)[i].done, static_cast<int>(i + 1));
    EXPECT_EQ((*progress_)[i].budget, suite_->search.budget);
    if (i > 0) {
      EXPECT_LE((*progress_)[i].best, (*progress_)[i - 1].best);
    }
  }
  EXPECT_DOUBLE_EQ(progress_->back().best, full_->tuned_train.objective);
}

TEST_F(TunerTest, EvaluationDoesNotDependOnThreadCount) {
  // The shared run used two threads; one thread must give the same numbers, bit for bit.
  auto one = Evaluator::Create(*suite_, 1, Cluster::Local());
  ASSERT_TRUE(one.ok()) << one.message();
  auto m = (*one)->Evaluate((*one)->start_values(), SeedSet::kTrain);
  ASSERT_TRUE(m.ok()) << m.message();
  EXPECT_EQ(m->ToJson().dump(), full_->start_train.ToJson().dump());
}

TEST_F(TunerTest, ResumeAfterInterruptionReachesTheSameResult) {
  const auto lines = ReadLines((dir_ / "full.jsonl").string());
  // Interrupted after the start evaluation and six search evaluations, mid-way through the
  // next line.
  const std::string log = (dir_ / "resumed.jsonl").string();
  ASSERT_GT(lines.size(), 8u);
  {
    std::ofstream out(log);
    for (int i = 0; i < 7; ++i) out << lines[i] << "\n";
    out << lines[7].substr(0, lines[7].size() / 2);
  }
  auto evaluator = Evaluator::Create(*suite_, 2, Cluster::Local());
  ASSERT_TRUE(evaluator.ok()) << evaluator.message();
  TuneOptions options;
  options.resume_path = log;
  options.log_path = log;  // continue in the same file
  auto resumed = Tune(*suite_, options, **evaluator);
  ASSERT_TRUE(resumed.ok()) << resumed.message();
  EXPECT_EQ(resumed->replayed, 6);
  EXPECT_EQ(resumed->best_x, full_->best_x);
  EXPECT_EQ(resumed->best_evaluation, full_->best_evaluation);
  nlohmann::json a = resumed->ToJson(), b = full_->ToJson();
  a.erase("replayed");
  b.erase("replayed");
  EXPECT_EQ(a.dump(), b.dump());
  EXPECT_EQ(resumed->tuned_yaml, full_->tuned_yaml);
  // The log is rewritten into exactly the uninterrupted run's log.
  EXPECT_EQ(ReadLines(log), lines);
}

TEST_F(TunerTest, ResumeRejectsALogOfOtherParameters) {
  const std::string log = (dir_ / "other.jsonl").string();
  {
    std::ofstream out(log);
    out << R"({"i":0,"phase":"search","set":"train","keys":["weights.jerk"],"values":[1],)"
        << R"("objective":1,"components":{}})" << "\n"
        << R"({"i":1})" << "\n";
  }
  auto evaluator = Evaluator::Create(*suite_, 1, Cluster::Local());
  ASSERT_TRUE(evaluator.ok()) << evaluator.message();
  TuneOptions options;
  options.resume_path = log;
  auto r = Tune(*suite_, options, **evaluator);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.message(), HasSubstr(log + ":1"));
  EXPECT_THAT(r.message(), HasSubstr("other parameters"));
}

TEST(EvaluatorTest, BadSuiteContentsAreNamed) {
  Suite suite;
  suite.source = "x.yaml";
  suite.scenarios = {"no-such-scenario"};
  suite.train_seeds = {1};
  suite.holdout_seeds = {2};
  suite.params = {{"weights.jerk", 0.1, 5, true}};
  auto e = Evaluator::Create(suite, 1, Cluster::Local());
  ASSERT_FALSE(e.ok());
  EXPECT_THAT(e.message(), HasSubstr("x.yaml"));
  suite.planner = "warp-drive";
  e = Evaluator::Create(suite, 1, Cluster::Local());
  ASSERT_FALSE(e.ok());
  EXPECT_THAT(e.message(), HasSubstr("warp-drive"));
}

}  // namespace
}  // namespace frenetic::tune

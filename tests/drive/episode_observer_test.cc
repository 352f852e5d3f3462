#include "frenetic/drive/episode_observer.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "frenetic/drive/drive_report.h"
#include "frenetic/drive/episode.h"
#include "sim/sim_test_util.h"

namespace frenetic::sim {
namespace {

// Notes every call, and what the episode showed it then.
class Log final : public EpisodeObserver {
 public:
  Log(std::string name, bool ticks, std::vector<std::string>* calls)
      : name_(std::move(name)), ticks_(ticks), calls_(calls) {}
  void OnStart(const Episode& episode) override {
    calls_->push_back(name_ + " start " + std::to_string(episode.exchanges()));
  }
  bool wants_ticks() const override { return ticks_; }
  void OnTick(const Simulator& /*sim*/) override { ++ticks_seen; }
  void OnExchange(const Episode& episode, const Exchange& exchange) override {
    calls_->push_back(name_ + " exchange " + std::to_string(exchange.index));
    EXPECT_EQ(exchange.index + 1, episode.exchanges());
    EXPECT_LE(exchange.t_sent, episode.sim().time());
    EXPECT_LE(exchange.first_incident, episode.sim().monitor().log().size());
    ASSERT_NE(exchange.reply, nullptr);
    EXPECT_EQ(exchange.reply->kind, "test");
    ticks_driven += episode.last_l_old() + episode.last_l_new();
  }
  Status OnEnd(const Episode& /*episode*/, DriveReport* report) override {
    calls_->push_back(name_ + " end " + report->planner);
    report->planner += "+" + name_;
    return name_ == "b" ? Status::Error("b failed") : Status::Ok();
  }
  long ticks_seen = 0, ticks_driven = 0;

 private:
  std::string name_;
  bool ticks_;
  std::vector<std::string>* calls_;
};

TEST(EpisodeObserver, SeesStartExchangesTicksAndEndInAttachOrder) {
  FRENETIC_REQUIRE_UDACITY(world);
  Scenario sc;
  sc.traffic.cars = 0;
  auto sim = Simulator::Create(world, sc, 1);
  ASSERT_TRUE(sim.ok());
  Episode ep(std::move(*sim), EpisodeLimits{0, 0, 1, 60});
  std::vector<std::string> calls;
  Log a("a", /*ticks=*/true, &calls), b("b", /*ticks=*/false, &calls);
  ep.Attach(&a);
  ep.Attach(&b);
  testing::KeepLanePlanner planner(world->line, 15);
  ExchangeReply reply;
  reply.kind = "test";
  int exchanges = 0;
  while (!ep.done()) {
    const plan::PlanResult& r = planner.Plan(ep.telemetry());
    ASSERT_TRUE(ep.Submit(r.x, r.y, reply).ok());
    ++exchanges;
  }
  DriveReport report = MakeReport(ep, "p", {}, 0);
  const Status s = ep.Finish(&report);
  EXPECT_FALSE(s.ok());  // b's failure, after every observer ran
  EXPECT_EQ(s.message(), "b failed");
  EXPECT_EQ(report.planner, "p+a+b");
  std::vector<std::string> expected = {"a start 0", "b start 0"};
  for (int i = 0; i < exchanges; ++i) {
    expected.push_back("a exchange " + std::to_string(i));
    expected.push_back("b exchange " + std::to_string(i));
  }
  expected.push_back("a end p");
  expected.push_back("b end p+a");
  EXPECT_EQ(calls, expected);
  // Only the observer that asked sees the ticks, every one of them.
  EXPECT_GT(a.ticks_seen, 0);
  EXPECT_EQ(a.ticks_seen, a.ticks_driven);
  EXPECT_EQ(b.ticks_seen, 0);
  EXPECT_EQ(b.ticks_driven, a.ticks_driven);
}

}  // namespace
}  // namespace frenetic::sim

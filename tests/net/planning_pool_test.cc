// The planning pool on its own: which queued work runs next, on which thread, and what Stop()
// drops. Work is held on gates, so every order below is decided by the pool, not by timing;
// the usages are set far apart (and decay alike), so their order holds however long a test runs.
#include "net/planning_pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace frenetic::net {
namespace {

// A latch the test opens; work waits on it.
class Gate {
 public:
  void Open() {
    {
      std::lock_guard lock(mutex_);
      open_ = true;
    }
    cv_.notify_all();
  }
  void Wait() {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [&] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
};

// What ran, in order, and on which thread; Await(n) blocks until n works have run.
class Log {
 public:
  void Add(const std::string& name) {
    {
      std::lock_guard lock(mutex_);
      names_.push_back(name);
      threads_.push_back(std::this_thread::get_id());
    }
    cv_.notify_all();
  }
  void Await(std::size_t n) {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [&] { return names_.size() >= n; });
  }
  std::vector<std::string> names() {
    std::lock_guard lock(mutex_);
    return names_;
  }
  std::thread::id thread(std::size_t i) {
    std::lock_guard lock(mutex_);
    return threads_.at(i);
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<std::string> names_;
  std::vector<std::thread::id> threads_;
};

// A usage of `seconds` recent work (now).
Usage UsageOf(double seconds) {
  Usage u;
  u.seconds = seconds;
  u.at = Clock::now();
  return u;
}

// Well under kHeavyUsage (light) and far over it (heavy, for longer than any test runs).
constexpr double kLight = 1e-6;
constexpr double kHeavy = 1e6;

PlanningPool::Release Ignore() {
  return [](std::shared_ptr<void>) {};
}

// Everything a work touches is declared before the pool, which stops (joining its threads)
// first on the way out.

TEST(PlanningPoolTest, RunsTheLeastUsedSessionFirstAndTiesInQueueOrder) {
  Gate gate;
  Log log;
  // All light; their order stays as it is while they decay (alike).
  Usage blocker = UsageOf(0), busy = UsageOf(0.05), middle = UsageOf(0.02), idle = UsageOf(0),
        idle_too = UsageOf(0);
  PlanningPool pool;
  pool.Start(1, Ignore());
  pool.Submit(&blocker, false, nullptr, [&] {
    log.Add("blocker");
    gate.Wait();
  });
  log.Await(1);  // the only thread is taken: the rest queue up
  pool.Submit(&busy, false, nullptr, [&] { log.Add("busy"); });
  pool.Submit(&idle, false, nullptr, [&] { log.Add("idle"); });
  pool.Submit(&middle, false, nullptr, [&] { log.Add("middle"); });
  pool.Submit(&idle_too, false, nullptr, [&] { log.Add("idle too"); });
  gate.Open();
  log.Await(5);
  EXPECT_EQ(log.names(),
            (std::vector<std::string>{"blocker", "idle", "idle too", "middle", "busy"}));
}

TEST(PlanningPoolTest, ASingleThreadAlsoRunsHeavyWork) {
  Log log;
  Usage heavy = UsageOf(kHeavy);
  PlanningPool pool;
  pool.Start(1, Ignore());
  pool.Submit(&heavy, true, nullptr, [&] { log.Add("asked heavy"); });
  pool.Submit(&heavy, false, nullptr, [&] { log.Add("heavy by usage"); });
  pool.SubmitHeavy([&] { log.Add("the pool's own"); });
  log.Await(3);
  EXPECT_EQ(log.names().size(), 3u);
}

// With two threads or more the first is kept for light work: heavy work (asked, or by usage)
// waits for another thread, while light work still runs.
TEST(PlanningPoolTest, HeavyWorkNeverTakesTheLightThread) {
  Gate gate;
  Log log;
  // The queued heavy work is less used than the light work: the light thread would take it
  // first if it took heavy work.
  Usage first = UsageOf(kLight), asked = UsageOf(0), by_usage = UsageOf(kHeavy),
        light = UsageOf(kLight);
  PlanningPool pool;
  pool.Start(2, Ignore());
  pool.Submit(&first, true, nullptr, [&] {  // takes the only thread heavy work may use
    log.Add("heavy");
    gate.Wait();
  });
  log.Await(1);
  pool.Submit(&asked, true, nullptr, [&] { log.Add("asked heavy"); });
  pool.SubmitHeavy([&] { log.Add("the pool's own"); });
  pool.Submit(&by_usage, false, nullptr, [&] { log.Add("heavy by usage"); });
  pool.Submit(&light, false, nullptr, [&] { log.Add("light"); });
  log.Await(2);
  EXPECT_EQ(log.names(), (std::vector<std::string>{"heavy", "light"}));
  EXPECT_NE(log.thread(0), log.thread(1));
  gate.Open();
  log.Await(5);
  for (std::size_t i = 2; i < 5; ++i) EXPECT_EQ(log.thread(i), log.thread(0)) << i;
}

// Light work goes to another thread while the light thread is busy, and only then: a
// well-paced session waits for at most the one light work in hand.
TEST(PlanningPoolTest, LightWorkOverflowsToTheOtherThreadsOnlyWhileTheLightOneIsBusy) {
  Gate gate;
  Log log, released;
  Usage heavy = UsageOf(kHeavy), a = UsageOf(kLight), b = UsageOf(kLight), c = UsageOf(kLight);
  PlanningPool pool;
  pool.Start(2, [&](std::shared_ptr<void>) { released.Add("released"); });
  pool.Submit(&heavy, true, nullptr, [&] { log.Add("heavy"); });
  log.Await(1);  // log.thread(0) is the other thread
  pool.Submit(&a, false, std::make_shared<int>(0), [&] { log.Add("a"); });
  released.Await(1);  // the light thread is idle again (released after it is marked so)
  EXPECT_NE(log.thread(1), log.thread(0)) << "light work on the other thread, the light one idle";
  pool.Submit(&b, false, nullptr, [&] {
    log.Add("b");
    gate.Wait();
  });
  log.Await(3);
  pool.Submit(&c, false, nullptr, [&] { log.Add("c"); });
  log.Await(4);  // runs while b is held
  EXPECT_EQ(log.thread(2), log.thread(1));
  EXPECT_EQ(log.thread(3), log.thread(0));
  gate.Open();
}

TEST(PlanningPoolTest, AddsTheWorksTimeToItsSessionsUsage) {
  Log log;
  Usage usage = UsageOf(0);
  const Clock::time_point before = usage.at;
  PlanningPool pool;
  pool.Start(1, Ignore());
  pool.Submit(&usage, false, nullptr, [&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    log.Add("work");
  });
  log.Await(1);
  pool.Stop();  // joins: the usage was written under the pool's lock before
  // The work's time, added to the (zero) usage it had.
  EXPECT_GE(usage.seconds, 0.002);
  EXPECT_GT(usage.at, before);
}

TEST(PlanningPoolTest, HandsEachKeptReferenceToReleaseAfterItsWork) {
  Log log;
  Usage usage = UsageOf(kLight);
  PlanningPool pool;
  pool.Start(2, [&](std::shared_ptr<void> keep) {
    log.Add("release " + *std::static_pointer_cast<std::string>(keep));
  });
  pool.Submit(&usage, false, std::make_shared<std::string>("session"), [&] { log.Add("work"); });
  pool.SubmitHeavy([&] { log.Add("nothing to release"); });
  log.Await(3);
  pool.Stop();
  std::vector<std::string> names = log.names();
  names.erase(std::find(names.begin(), names.end(), "nothing to release"));
  EXPECT_EQ(names, (std::vector<std::string>{"work", "release session"}));
}

TEST(PlanningPoolTest, StopFinishesTheWorkInHandAndDropsTheQueue) {
  Gate gate;
  Log log;
  std::atomic<int> released = 0;
  Usage usage = UsageOf(0);
  PlanningPool pool;
  pool.Start(1, [&](std::shared_ptr<void>) { ++released; });
  pool.Submit(&usage, false, std::make_shared<int>(1), [&] {
    log.Add("in hand");
    gate.Wait();
  });
  log.Await(1);
  auto queued = std::make_shared<int>(2);
  const std::weak_ptr<int> queued_alive = queued;
  pool.Submit(&usage, false, std::move(queued), [&] { log.Add("queued"); });
  std::thread stopper([&] { pool.Stop(); });
  // Stop() drops the queue (and the reference it held) before it waits for the work in hand.
  while (!queued_alive.expired()) std::this_thread::yield();
  gate.Open();
  stopper.join();
  EXPECT_EQ(log.names(), (std::vector<std::string>{"in hand"}));
  EXPECT_EQ(released, 1);
  pool.Submit(&usage, false, nullptr, [&] { log.Add("after stop"); });
  pool.Stop();  // idempotent
  EXPECT_EQ(log.names().size(), 1u);
}

}  // namespace
}  // namespace frenetic::net

#include "net/planning_pool.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace frenetic::net {
namespace {

// The niceness of the threads that run heavy work.
constexpr int kHeavyNice = 5;

}  // namespace

double Usage::Now(Clock::time_point now) const {
  const double age = std::chrono::duration<double>(now - at).count();
  return seconds * std::exp(-std::max(0.0, age) / kUsageTau);
}

void PlanningPool::Start(int threads, Release release) {
  release_ = std::move(release);
  has_light_thread_ = threads > 1;
  for (int i = 0; i < threads; ++i) {
    threads_.emplace_back([this, light = has_light_thread_ && i == 0] { Loop(light); });
  }
}

void PlanningPool::Stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    queue_.clear();
  }
  cv_.notify_all();
  for (std::thread& t : threads_) t.join();
  threads_.clear();
}

void PlanningPool::Submit(Usage* usage, bool heavy, std::shared_ptr<void> keep, Work work) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    // Classified once, when queued: a class that changed while the work waits (the usage
    // decays) could leave it to a thread that is not looking.
    heavy = heavy || usage->Now(Clock::now()) > kHeavyUsage;
    queue_.push_back({usage, heavy, std::move(keep), std::move(work)});
  }
  cv_.notify_all();  // not every thread takes every work
}

// The queued item a thread runs next (queue_.end() when none is for it now). The light thread
// takes only light work; the others take any, light work only while the light thread is busy.
std::deque<PlanningPool::Item>::iterator PlanningPool::Pick(Clock::time_point now,
                                                            bool light_thread) {
  auto best = queue_.end();
  double best_usage = 0;
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if (light_thread ? it->heavy : !it->heavy && has_light_thread_ && !light_busy_) continue;
    const double u = it->usage->Now(now);
    if (best == queue_.end() || u < best_usage) {
      best = it;
      best_usage = u;
    }
  }
  return best;
}

void PlanningPool::Loop(bool light_thread) {
  // Heavy work runs at a lower priority than the light thread and the I/O thread: when the
  // machine is short of cores, floods and churn wait, not the simulators (nice is per thread
  // on Linux; failing to set it is harmless).
  if (has_light_thread_ && !light_thread) {
    // Also when the server runs under a real-time policy (chrt -f, to keep a busy machine's
    // other work from delaying the simulator's replies): heavy work then stays out of it.
    const sched_param normal{};
    (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kHeavyNice);
  }
  for (;;) {
    Item item;
    {
      std::unique_lock lock(mutex_);
      auto next = queue_.end();
      cv_.wait(lock, [&] {
        if (stopping_) return true;
        next = Pick(Clock::now(), light_thread);
        return next != queue_.end();
      });
      if (stopping_) return;
      item = std::move(*next);
      queue_.erase(next);
      if (light_thread) light_busy_ = true;
    }
    const Clock::time_point start = Clock::now();
    item.work();
    const Clock::time_point end = Clock::now();
    {
      std::lock_guard lock(mutex_);
      item.usage->seconds =
          item.usage->Now(end) + std::chrono::duration<double>(end - start).count();
      item.usage->at = end;
      if (light_thread) light_busy_ = false;
    }
    if (light_thread) cv_.notify_all();  // light work left to the others goes back to it
    if (item.keep) release_(std::move(item.keep));
  }
}

}  // namespace frenetic::net

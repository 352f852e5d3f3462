// The server's planning threads (internal to net). Work is queued per session and taken by the
// session with the least recent planning time, so a session that keeps the pool busy cannot push
// a well-paced one behind a queue of its own work.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace frenetic::net {

using Clock = std::chrono::steady_clock;

// The time constant of a session's planning usage (pool priority), s.
inline constexpr double kUsageTau = 1.0;
// Usage (s of work over ~kUsageTau) beyond which a session's work is heavy: a tenth of a core.
// A simulator at 50 frames/s of ~1 ms each uses ~0.05. At a quarter, 7 flooding connections
// sharing the heavy thread (1/7 of a core each) fell back under it and took turns on the light
// thread, where a simulator's frame waited behind their plans (flood p99 12 ms).
inline constexpr double kHeavyUsage = 0.1;

// A session's recent planning time, for the pool's choice: seconds of work, decayed with
// kUsageTau. Read and written under the pool's lock only (once the session's work is queued).
struct Usage {
  double seconds = 0;
  Clock::time_point at = Clock::now();

  // The usage at `now`: `seconds` decayed since `at`.
  double Now(Clock::time_point now) const;
};

// Runs queued work on a few threads. It takes the waiting work of the session with the least
// recent planning time (ties: the first queued). Heavy work (a session that has used more than
// kHeavyUsage lately, building a planner, a session's first plans, giving memory back) never
// runs on the first thread, kept for light work, and runs at a lower priority: a well-paced
// session's frame waits for at most one light frame to finish, however many connections flood
// or churn. With one thread, that thread takes every work, by usage.
//
// After a work ran, its time is added to its usage, and its `keep` reference is handed to the
// Release function on the planning thread that ran it.
class PlanningPool {
 public:
  using Work = std::function<void()>;
  // Drops a session's reference once its work ran; the server drops it on the I/O thread, so
  // that a session is never destroyed on a planning thread.
  using Release = std::function<void(std::shared_ptr<void>)>;

  PlanningPool() = default;
  PlanningPool(const PlanningPool&) = delete;
  PlanningPool& operator=(const PlanningPool&) = delete;
  ~PlanningPool() { Stop(); }

  // Starts `threads` (>= 1) threads; call once. The first is kept for light work when there
  // are two or more.
  void Start(int threads, Release release);
  // Stops the threads after the work in hand; queued work is dropped (its `keep` with it, on
  // the calling thread) and later Submits are ignored. Idempotent.
  void Stop();

  // Queues `work` for the session whose usage is *usage (owned by the session; `keep` holds it
  // alive until the work ran); `heavy` when the work is known to be long (a planner to build).
  // The work is classified once, here: heavy as asked or when the usage is over kHeavyUsage.
  void Submit(Usage* usage, bool heavy, std::shared_ptr<void> keep, Work work);
  // Heavy work of no session (its usage is the pool's own).
  void SubmitHeavy(Work work) { Submit(&own_usage_, true, nullptr, std::move(work)); }

 private:
  struct Item {
    Usage* usage;
    bool heavy;
    std::shared_ptr<void> keep;
    Work work;
  };

  std::deque<Item>::iterator Pick(Clock::time_point now, bool light_thread);
  void Loop(bool light_thread);

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Item> queue_;
  bool stopping_ = false;
  bool has_light_thread_ = false;  // set before the threads start
  bool light_busy_ = false;
  Usage own_usage_;
  Release release_;
  std::vector<std::thread> threads_;
};

}  // namespace frenetic::net

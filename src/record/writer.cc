#include "frenetic/record/writer.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include "record/file_sink.h"

namespace frenetic::record {
namespace {

// Lines queued for the writer's thread at most (~5-30 kB each); a producer that finds the queue
// full waits until it is half empty, so that the planning thread then runs many cycles in a row
// instead of trading the core (and its caches) with the writer at every exchange.
constexpr std::size_t kMaxQueuedLines = 512;
// The writer's thread wakes up for this many queued lines (or a flush, the last line, the end):
// lines are written in bursts, not one wake-up per exchange.
constexpr std::size_t kBatchLines = 64;

}  // namespace

StatusOr<std::unique_ptr<Writer>> Writer::Open(const std::string& path) {
  auto sink = FileSink::Open(path);
  if (!sink.ok()) return sink.status();
  return std::unique_ptr<Writer>(new Writer(std::move(sink).value()));
}

Writer::Writer(std::unique_ptr<FileSink> sink) : sink_(std::move(sink)) {
  thread_ = std::thread([this] { Loop(); });
}

Writer::~Writer() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  thread_.join();
  sink_->Finish();
}

const std::string& Writer::path() const { return sink_->path(); }

void Writer::Loop() {
  // The record is no reason to take a core from the planner: the writer runs as a batch job at
  // low priority (also when the drive runs under a real-time policy, which a thread may always
  // leave), so it yields to the planning thread. Policy and nice are per thread on Linux;
  // failing to lower them is harmless.
  const sched_param batch{};
  (void)pthread_setschedparam(pthread_self(), SCHED_BATCH, &batch);
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  std::string line;
  std::unique_lock lock(mutex_);
  for (;;) {
    work_.wait(lock,
               [this] { return stop_ || last_ || drain_ > 0 || queue_.size() >= kBatchLines; });
    if (queue_.empty()) {
      if (stop_) return;  // everything written
      room_.notify_all();
      if (last_ || drain_ > 0) {
        // Nothing to do until more lines come: wait for them, not for the predicate above.
        work_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      }
      continue;
    }
    Line next = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    const bool last = last_ && queue_.empty();
    if (queue_.size() <= kMaxQueuedLines / 2) room_.notify_all();
    lock.unlock();
    line.clear();
    next(&line);
    line.push_back('\n');
    sink_->Write(line);
    if (last) sink_->Finish();
    lock.lock();
    busy_ = false;
    if (queue_.empty()) room_.notify_all();
  }
}

void Writer::Write(Line format, bool last) {
  if (finished_) return;  // nothing follows the last line
  finished_ = last;
  std::unique_lock lock(mutex_);
  if (queue_.size() >= kMaxQueuedLines) {
    room_.wait(lock, [this] { return queue_.size() <= kMaxQueuedLines / 2; });
  }
  queue_.push_back(std::move(format));
  last_ = last;
  if (last || queue_.size() >= kBatchLines) work_.notify_one();
}

void Writer::WriteText(std::string text, bool last) {
  Write([text = std::move(text)](std::string* line) { *line += text; }, last);
}

Status Writer::status() {
  std::unique_lock lock(mutex_);
  ++drain_;
  work_.notify_one();
  room_.wait(lock, [this] { return queue_.empty() && !busy_; });
  --drain_;
  // Only this thread queues lines: the writer's thread stays idle while the file is flushed.
  sink_->Flush();
  if (!sink_->error().empty()) return Status::Error(sink_->path() + ": " + sink_->error());
  return Status::Ok();
}

}  // namespace frenetic::record

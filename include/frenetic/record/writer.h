// Writes a record (schema.h): JSON lines to a file, gzip-compressed when its name ends in ".gz"
// (zlib; `zcat` shows the text; ~11 MB for a lap of a drive instead of ~95 MB).
//
// Writing costs the caller's thread a copy of the line's values: the lines are formatted,
// compressed and written by a thread of the writer's own, at low priority, in order, and a
// bounded queue between them keeps a slow disk from holding the whole record in memory (the
// caller then waits between lines, never inside one). status() waits for everything queued to
// be written.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "frenetic/status.h"

namespace frenetic::record {

class FileSink;  // src/record/file_sink.h

class Writer {
 public:
  // Formats one line, one JSON object without its newline, appending it to *line.
  using Line = std::function<void(std::string* line)>;

  // Opens (truncates) the file, gzip-compressed when `path` ends in ".gz"; an error names it.
  static StatusOr<std::unique_ptr<Writer>> Open(const std::string& path);
  // Writes what is queued, ends the stream and closes the file.
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Queues a line that `format` writes on the writer's thread (so it holds copies, not
  // references to what the caller changes next). `last`: the stream is ended after it and
  // later lines are ignored (the footer). Waits while the queue is full.
  void Write(Line format, bool last = false);
  // Queues a line formatted already.
  void WriteText(std::string text, bool last = false);
  // Waits until everything queued is in the file; Ok unless a write failed (the message names
  // the file and why). Call from the thread that queues the lines.
  Status status();
  const std::string& path() const;

 private:
  explicit Writer(std::unique_ptr<FileSink> sink);
  void Loop();

  std::unique_ptr<FileSink> sink_;
  bool finished_ = false;  // the last line was queued (producer side)

  std::mutex mutex_;
  std::condition_variable work_;  // for the writer's thread: lines to write, or stop
  std::condition_variable room_;  // for producers: room in the queue, or all written
  std::deque<Line> queue_;        // guarded by mutex_
  bool busy_ = false;             // a line is being written (guarded)
  bool last_ = false;             // the last line is queued: end the stream after it (guarded)
  bool stop_ = false;             // guarded
  int drain_ = 0;                 // status() calls waiting for everything to be written
  std::thread thread_;
};

}  // namespace frenetic::record

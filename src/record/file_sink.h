// The file a record is written to (internal to record): plain text, or one gzip stream (zlib,
// deterministic: no name, time 0). Used by one thread at a time (record::Writer's).
#pragma once

#include <zlib.h>

#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include "frenetic/status.h"

namespace frenetic::record {

class FileSink {
 public:
  // Opens (truncates) `path`, gzip-compressed when it ends in ".gz"; an error names the path.
  static StatusOr<std::unique_ptr<FileSink>> Open(const std::string& path);
  ~FileSink();  // Finish(), then closes the file
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;

  void Write(std::string_view data);
  // Everything written so far is in the file (readable, for gzip up to a flush point).
  void Flush();
  // Ends the stream (the gzip trailer) and flushes; later writes are dropped.
  void Finish();
  // The first write error ("write failed: ..."), empty while all is well.
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }

 private:
  FileSink(std::FILE* file, std::string path);
  void Deflate(std::string_view data, int flush);
  void Fail(int err);

  std::FILE* file_;
  std::string path_;
  std::unique_ptr<z_stream> zs_;  // null: plain text
  std::string out_;
  std::size_t since_flush_ = 0;
  bool finished_ = false;
  std::string error_;
};

}  // namespace frenetic::record

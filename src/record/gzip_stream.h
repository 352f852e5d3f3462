// The text of a gzip-compressed record (`drive --record run.jsonl.gz`), inflated as it is read
// (internal to record).
#pragma once

#include <zlib.h>

#include <istream>
#include <streambuf>
#include <string>
#include <vector>

namespace frenetic::record {

// A read-only streambuf over the inflated bytes of `in` (gzip, or zlib, detected by the
// header). Concatenated gzip members read as one text. Data that ends early or is corrupt ends
// the text there; error() then says why (empty while all is well).
class GzipStreambuf : public std::streambuf {
 public:
  explicit GzipStreambuf(std::istream& in);
  ~GzipStreambuf() override;
  GzipStreambuf(const GzipStreambuf&) = delete;
  GzipStreambuf& operator=(const GzipStreambuf&) = delete;

  const std::string& error() const { return error_; }

 protected:
  int_type underflow() override;

 private:
  std::istream& in_;
  std::vector<char> in_buf_, out_buf_;
  z_stream zs_{};
  bool member_ended_ = false, done_ = false;
  std::string error_;
};

}  // namespace frenetic::record

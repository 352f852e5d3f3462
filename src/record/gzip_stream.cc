#include "record/gzip_stream.h"

namespace frenetic::record {

GzipStreambuf::GzipStreambuf(std::istream& in) : in_(in), in_buf_(256 << 10), out_buf_(256 << 10) {
  // 15 window bits + 32: a gzip (or zlib) header, detected.
  if (inflateInit2(&zs_, 15 + 32) != Z_OK) {
    error_ = "cannot start inflating";
    done_ = true;
  }
}

GzipStreambuf::~GzipStreambuf() { inflateEnd(&zs_); }

GzipStreambuf::int_type GzipStreambuf::underflow() {
  if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
  while (!done_) {
    if (zs_.avail_in == 0) {
      in_.read(in_buf_.data(), static_cast<std::streamsize>(in_buf_.size()));
      const auto n = static_cast<uInt>(in_.gcount());
      if (n == 0) {
        if (!member_ended_) error_ = "the compressed data ends early (the drive was cut short?)";
        done_ = true;
        break;
      }
      zs_.next_in = reinterpret_cast<Bytef*>(in_buf_.data());
      zs_.avail_in = n;
    }
    if (member_ended_) {  // another gzip member follows
      inflateReset(&zs_);
      member_ended_ = false;
    }
    zs_.next_out = reinterpret_cast<Bytef*>(out_buf_.data());
    zs_.avail_out = static_cast<uInt>(out_buf_.size());
    const int rc = inflate(&zs_, Z_NO_FLUSH);
    const std::size_t produced = out_buf_.size() - zs_.avail_out;
    if (rc == Z_STREAM_END) {
      member_ended_ = true;
    } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
      error_ = std::string("corrupt compressed data (") + (zs_.msg ? zs_.msg : "zlib error") + ")";
      done_ = true;
    }
    if (produced > 0) {
      setg(out_buf_.data(), out_buf_.data(), out_buf_.data() + produced);
      return traits_type::to_int_type(*gptr());
    }
  }
  return traits_type::eof();
}

}  // namespace frenetic::record

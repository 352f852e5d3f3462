#include "record/file_sink.h"

#include <cerrno>
#include <cstring>

namespace frenetic::record {
namespace {

// The gzip stream is flushed to a byte boundary this often (raw bytes), so a run that dies
// still leaves a record that reads up to about there.
constexpr std::size_t kSyncFlushBytes = 4 << 20;
constexpr int kGzipLevel = 6;

}  // namespace

StatusOr<std::unique_ptr<FileSink>> FileSink::Open(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    return Status::Error(path + ": cannot write record: " + std::strerror(errno));
  }
  auto sink = std::unique_ptr<FileSink>(new FileSink(f, path));
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  if (gzip) {
    sink->zs_ = std::make_unique<z_stream>();
    *sink->zs_ = z_stream{};
    // 15 window bits + 16: a gzip header and trailer around the deflate stream.
    if (deflateInit2(sink->zs_.get(), kGzipLevel, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) !=
        Z_OK) {
      sink->zs_.reset();
      return Status::Error(path + ": cannot start the gzip stream");
    }
    sink->out_.resize(256 << 10);
  }
  return sink;
}

FileSink::FileSink(std::FILE* file, std::string path) : file_(file), path_(std::move(path)) {
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
}

FileSink::~FileSink() {
  Finish();
  if (zs_) deflateEnd(zs_.get());
  std::fclose(file_);
}

void FileSink::Write(std::string_view data) {
  if (!error_.empty() || finished_) return;
  if (!zs_) {
    if (std::fwrite(data.data(), 1, data.size(), file_) != data.size()) Fail(errno);
    return;
  }
  Deflate(data, Z_NO_FLUSH);
  since_flush_ += data.size();
  if (since_flush_ >= kSyncFlushBytes) Deflate({}, Z_SYNC_FLUSH);
}

void FileSink::Flush() {
  if (!error_.empty()) return;
  if (zs_ && !finished_) Deflate({}, Z_SYNC_FLUSH);
  if (std::fflush(file_) != 0) Fail(errno);
}

void FileSink::Finish() {
  if (finished_) return;
  if (zs_ && error_.empty()) Deflate({}, Z_FINISH);
  finished_ = true;
  if (error_.empty() && std::fflush(file_) != 0) Fail(errno);
}

void FileSink::Deflate(std::string_view data, int flush) {
  zs_->next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  zs_->avail_in = static_cast<uInt>(data.size());
  int rc = Z_OK;
  do {
    zs_->next_out = reinterpret_cast<Bytef*>(out_.data());
    zs_->avail_out = static_cast<uInt>(out_.size());
    rc = deflate(zs_.get(), flush);
    if (rc == Z_STREAM_ERROR) {
      error_ = "gzip stream error";
      return;
    }
    const std::size_t n = out_.size() - zs_->avail_out;
    if (n > 0 && std::fwrite(out_.data(), 1, n, file_) != n) {
      Fail(errno);
      return;
    }
  } while (zs_->avail_out == 0 || (flush == Z_FINISH && rc != Z_STREAM_END));
  if (flush != Z_NO_FLUSH) since_flush_ = 0;
}

void FileSink::Fail(int err) {
  if (error_.empty()) error_ = std::string("write failed: ") + std::strerror(err);
}

}  // namespace frenetic::record

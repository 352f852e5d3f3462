// The bytes on the wire, without a WebSocket library in between: a plain POSIX TCP socket whose
// every read is bounded by poll(), the RFC 6455 upgrade done by hand, and a frame reader that
// reports each frame's header bits as sent. For tests that check how messages are framed.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/beast/websocket/detail/hybi13.hpp>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace frenetic::net::testing {

class RawSocket {
 public:
  explicit RawSocket(int fd = -1) : fd_(fd) {}
  RawSocket(RawSocket&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  RawSocket& operator=(RawSocket&& o) noexcept {
    std::swap(fd_, o.fd_);
    return *this;
  }
  ~RawSocket() { Close(); }
  bool ok() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  void Close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  static RawSocket Connect(int port) {
    RawSocket s(::socket(AF_INET, SOCK_STREAM, 0));
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (!s.ok() || ::connect(s.fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      s.Close();
    }
    return s;
  }

  // Makes writes return at once when the socket's buffers are full (WriteSome).
  bool SetNonBlocking() { return ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK) == 0; }
  // Writes what fits now (non-blocking socket); the count written, or -1 on an error other
  // than full buffers.
  std::int64_t WriteSome(std::string_view data) {
    const ssize_t n = ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL);
    if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK ? 0 : -1;
    return n;
  }

  bool WriteAll(std::string_view data) {
    while (!data.empty()) {
      const ssize_t n = ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL);
      if (n <= 0) return false;
      data.remove_prefix(static_cast<std::size_t>(n));
    }
    return true;
  }

  // Appends exactly n bytes to *out; false on error, end of stream or after `timeout` s.
  bool ReadExactly(std::size_t n, std::string* out, double timeout = 5.0) {
    const auto deadline = Deadline(timeout);
    while (n > 0) {
      if (!WaitReadable(deadline)) return false;
      char buf[65536];
      const ssize_t got = ::recv(fd_, buf, std::min(n, sizeof buf), 0);
      if (got <= 0) return false;
      out->append(buf, static_cast<std::size_t>(got));
      n -= static_cast<std::size_t>(got);
    }
    return true;
  }

  // Reads byte by byte up to and including `delimiter` (for the HTTP upgrade).
  bool ReadUntil(std::string_view delimiter, std::string* out, double timeout = 5.0) {
    while (out->size() < delimiter.size() ||
           out->compare(out->size() - delimiter.size(), delimiter.size(), delimiter) != 0) {
      if (out->size() > 65536 || !ReadExactly(1, out, timeout)) return false;
    }
    return true;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static Clock::time_point Deadline(double timeout) {
    return Clock::now() + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(timeout));
  }
  bool WaitReadable(Clock::time_point deadline) const {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd_, POLLIN, 0};
    return ::poll(&p, 1, static_cast<int>(left.count())) == 1;
  }

  int fd_;
};

// A listening socket on 127.0.0.1 with an ephemeral port.
class RawListener {
 public:
  RawListener() : socket_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = 0;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof addr;
    if (!socket_.ok() || ::bind(socket_.fd(), reinterpret_cast<sockaddr*>(&addr), len) != 0 ||
        ::listen(socket_.fd(), 4) != 0 ||
        ::getsockname(socket_.fd(), reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
      socket_.Close();
      return;
    }
    port_ = ntohs(addr.sin_port);
  }
  int port() const { return port_; }
  RawSocket Accept(double timeout = 5.0) {
    pollfd p{socket_.fd(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout * 1000)) != 1) return RawSocket();
    return RawSocket(::accept(socket_.fd(), nullptr, nullptr));
  }

 private:
  RawSocket socket_;
  int port_ = 0;
};

// One frame as it arrived: the header bits and the (unmasked) payload.
struct RawFrame {
  bool fin = false;
  int opcode = -1;  // 0 continuation, 1 text, 2 binary, 8 close, 9 ping, 10 pong
  bool masked = false;
  std::string payload;
};

inline constexpr int kOpContinuation = 0x0, kOpText = 0x1, kOpClose = 0x8;

// Reads one frame (RFC 6455 §5.2); nullopt on error or timeout.
inline std::optional<RawFrame> ReadRawFrame(RawSocket& s, double timeout = 5.0) {
  std::string h;
  if (!s.ReadExactly(2, &h, timeout)) return std::nullopt;
  RawFrame f;
  const auto b0 = static_cast<unsigned char>(h[0]), b1 = static_cast<unsigned char>(h[1]);
  f.fin = (b0 & 0x80) != 0;
  f.opcode = b0 & 0x0F;
  f.masked = (b1 & 0x80) != 0;
  std::uint64_t len = b1 & 0x7F;
  const int extra = len == 126 ? 2 : len == 127 ? 8 : 0;
  if (extra > 0) {
    std::string ext;
    if (!s.ReadExactly(static_cast<std::size_t>(extra), &ext, timeout)) return std::nullopt;
    len = 0;
    for (char c : ext) len = (len << 8) | static_cast<unsigned char>(c);
  }
  if (len > (64u << 20)) return std::nullopt;
  std::string key;
  if (f.masked && !s.ReadExactly(4, &key, timeout)) return std::nullopt;
  if (!s.ReadExactly(static_cast<std::size_t>(len), &f.payload, timeout)) return std::nullopt;
  if (f.masked) {
    for (std::size_t i = 0; i < f.payload.size(); ++i) f.payload[i] ^= key[i % 4];
  }
  return f;
}

// One whole frame with FIN set; masked (as a client must) with a fixed key when `mask`.
inline std::string EncodeRawFrame(int opcode, std::string_view payload, bool mask) {
  std::string out;
  out.push_back(static_cast<char>(0x80 | opcode));
  const char mask_bit = mask ? static_cast<char>(0x80) : 0;
  const std::uint64_t n = payload.size();
  if (n < 126) {
    out.push_back(static_cast<char>(mask_bit | static_cast<char>(n)));
  } else if (n <= 0xFFFF) {
    out.push_back(static_cast<char>(mask_bit | 126));
    out.push_back(static_cast<char>(n >> 8));
    out.push_back(static_cast<char>(n & 0xFF));
  } else {
    out.push_back(static_cast<char>(mask_bit | 127));
    for (int i = 7; i >= 0; --i) out.push_back(static_cast<char>((n >> (8 * i)) & 0xFF));
  }
  const char key[4] = {0x12, 0x34, 0x56, 0x78};
  if (mask) out.append(key, 4);
  for (std::size_t i = 0; i < payload.size(); ++i) {
    out.push_back(mask ? static_cast<char>(payload[i] ^ key[i % 4]) : payload[i]);
  }
  return out;
}

// The server's side of the upgrade: reads the client's request into *request and answers 101
// with the Sec-WebSocket-Accept the client expects.
inline bool AcceptUpgradeByHand(RawSocket& s, std::string* request) {
  if (!s.ReadUntil("\r\n\r\n", request)) return false;
  const std::string_view name = "sec-websocket-key:";
  std::string lower = *request;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::size_t at = lower.find(name);
  if (at == std::string::npos) return false;
  std::size_t begin = at + name.size();
  while (begin < request->size() && (*request)[begin] == ' ') ++begin;
  const std::size_t end = request->find("\r\n", begin);
  boost::beast::websocket::detail::sec_ws_accept_type accept;
  const std::string key = request->substr(begin, end - begin);
  boost::beast::websocket::detail::make_sec_ws_accept(
      accept, boost::beast::string_view(key.data(), key.size()));
  return s.WriteAll(
      "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Accept: " +
      std::string(accept.data(), accept.size()) + "\r\n\r\n");
}

// The client's side of the upgrade (RFC 6455 §1.3's sample key); *response gets the answer.
inline bool UpgradeByHand(RawSocket& s, int port, std::string* response) {
  const std::string request =
      "GET /socket.io/?EIO=4&transport=websocket HTTP/1.1\r\nHost: 127.0.0.1:" +
      std::to_string(port) +
      "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  return s.WriteAll(request) && s.ReadUntil("\r\n\r\n", response);
}
inline constexpr std::string_view kSampleAccept = "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=";

// A connected, upgraded raw client (not ok() when the server did not answer 101); *response gets
// the server's answer.
inline RawSocket ConnectUpgraded(int port, std::string* response = nullptr) {
  std::string local;
  std::string& r = response != nullptr ? *response : local;
  RawSocket s = RawSocket::Connect(port);
  if (!s.ok() || !UpgradeByHand(s, port, &r) || r.rfind("HTTP/1.1 101", 0) != 0) s.Close();
  return s;
}

// The status code of a close frame's payload (0 when it has none).
inline int CloseCode(const RawFrame& f) {
  if (f.payload.size() < 2) return 0;
  return (static_cast<unsigned char>(f.payload[0]) << 8) | static_cast<unsigned char>(f.payload[1]);
}

// A close frame with `code` and `reason`, masked as a client sends it (or not, from a server).
inline std::string EncodeCloseFrame(int code, std::string_view reason, bool mask) {
  std::string payload;
  payload.push_back(static_cast<char>((code >> 8) & 0xFF));
  payload.push_back(static_cast<char>(code & 0xFF));
  payload += reason;
  return EncodeRawFrame(kOpClose, payload, mask);
}

}  // namespace frenetic::net::testing

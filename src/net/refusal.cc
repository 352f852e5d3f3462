#include "net/refusal.h"

#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <memory>

namespace frenetic::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

// How long an over-capacity connection may take to send its upgrade request before the 503.
constexpr auto kRefusalTimeout = std::chrono::seconds(2);

class Refusal : public std::enable_shared_from_this<Refusal> {
 public:
  Refusal(tcp::socket socket, int* in_progress)
      : in_progress_(in_progress), stream_(std::move(socket)) {
    ++*in_progress_;
    parser_.header_limit(8 << 10);
    parser_.body_limit(0);
  }
  ~Refusal() { --*in_progress_; }

  void Start(std::string reason) {
    reason_ = std::move(reason);
    stream_.expires_after(kRefusalTimeout);
    http::async_read(
        stream_, buffer_, parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->OnRequest(ec); });
  }

 private:
  void OnRequest(beast::error_code ec) {
    if (ec) return;  // no request in time: closed without an answer
    response_ =
        "HTTP/1.1 503 Service Unavailable\r\nServer: frenetic\r\nRetry-After: 1\r\n"
        "Content-Type: text/plain\r\nConnection: close\r\nContent-Length: " +
        std::to_string(reason_.size() + 1) + "\r\n\r\n" + reason_ + "\n";
    asio::async_write(stream_.socket(), asio::buffer(response_),
                      [self = shared_from_this()](beast::error_code, std::size_t) {
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                        self->stream_.close();
                      });
  }

  int* in_progress_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request_parser<http::empty_body> parser_;
  std::string reason_, response_;
};

}  // namespace

void StartRefusal(tcp::socket socket, std::string reason, int* in_progress) {
  std::make_shared<Refusal>(std::move(socket), in_progress)->Start(std::move(reason));
}

}  // namespace frenetic::net

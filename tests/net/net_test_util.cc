// TestClient's Beast stream (net_test_util.h), compiled once for the net tests.
#include "net/net_test_util.h"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <optional>
#include <string>

namespace frenetic::net::testing {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;

struct TestClient::Impl {
  explicit Impl(double timeout) : timeout(timeout), ws(io) {}

  template <typename Start>
  beast::error_code Await(Start start) {
    std::optional<beast::error_code> result;
    start([&result](beast::error_code ec) { result = ec; });
    io.restart();
    io.run_for(std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(timeout)));
    if (result) return *result;
    Abort();
    io.restart();
    io.run();
    return asio::error::timed_out;
  }
  void Abort() {
    beast::error_code ec;
    beast::get_lowest_layer(ws).socket().close(ec);
  }

  double timeout;
  asio::io_context io;
  websocket::stream<beast::tcp_stream> ws;
};

TestClient::TestClient(double timeout) : impl_(std::make_unique<Impl>(timeout)) {}
TestClient::~TestClient() = default;

bool TestClient::Connect(int port, const std::string& target) {
  const asio::ip::tcp::endpoint ep(asio::ip::make_address("127.0.0.1"),
                                   static_cast<unsigned short>(port));
  auto& ws = impl_->ws;
  auto ec = impl_->Await([&](auto h) {
    beast::get_lowest_layer(ws).async_connect(ep, [h](beast::error_code e) mutable { h(e); });
  });
  if (ec) return false;
  ec = impl_->Await([&](auto h) {
    ws.async_handshake("127.0.0.1:" + std::to_string(port), target,
                       [h](beast::error_code e) mutable { h(e); });
  });
  return !ec;
}

boost::system::error_code TestClient::Send(std::string_view frame, bool binary) {
  auto& ws = impl_->ws;
  ws.binary(binary);
  return impl_->Await([&](auto h) {
    ws.async_write(asio::buffer(frame.data(), frame.size()),
                   [h](beast::error_code e, std::size_t) mutable { h(e); });
  });
}

std::optional<std::string> TestClient::Receive() {
  auto& ws = impl_->ws;
  beast::flat_buffer buffer;
  auto ec = impl_->Await([&](auto h) {
    ws.async_read(buffer, [h](beast::error_code e, std::size_t) mutable { h(e); });
  });
  if (ec) return std::nullopt;
  return beast::buffers_to_string(buffer.data());
}

void TestClient::Close() {
  auto& ws = impl_->ws;
  impl_->Await([&](auto h) {
    ws.async_close(websocket::close_code::normal, [h](beast::error_code e) mutable { h(e); });
  });
}

void TestClient::Abort() { impl_->Abort(); }

}  // namespace frenetic::net::testing

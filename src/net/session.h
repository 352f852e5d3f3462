// One upgraded (or upgrading) WebSocket connection of the server (internal to net). It reads a
// frame, has it handled (42 frames on the planning pool, engine.io packets at once), writes the
// reply and only then reads the next frame: it has at most one frame in hand, so its planner is
// never used by two threads at once, and a client that floods or stops reading delays only
// itself. Its planner is built at its first telemetry and freed when it ends.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "frenetic/plan/planner.h"
#include "frenetic/wire/protocol.h"
#include "net/planning_pool.h"
#include "net/server_impl.h"

namespace frenetic::net {

class Session : public std::enable_shared_from_this<Session> {
 public:
  // Counts against max_connections from here (I/O thread). Its place is given up in End() (or
  // when the upgrade fails), on the I/O thread: the last reference may go anywhere.
  Session(Server::Impl* server, int id, boost::asio::ip::tcp::socket socket);

  // Registers the session with the server, sets the socket up and starts the upgrade.
  void Start();
  // Closes the socket: pending operations end, and the session with them.
  void Close();

 private:
  void OnAccept(boost::beast::error_code ec);
  void ReadNext();
  void DoRead();
  void OnRead(boost::beast::error_code ec);
  // Whether this session has yet to build its planner or to plan kYoungPlans frames. Read on
  // the I/O thread between frames (the pool hands the session back through a post).
  bool Young() const;
  void Waiting(int change);
  void Done(bool answer);
  std::string_view Frame() const;
  void FrameDone();
  void Finish(bool answer);
  void OnCloseFrame();
  bool Handle(const wire::ParsedFrame& parsed);
  bool EnsurePlanner();
  bool Plan(const plan::Telemetry& telemetry);
  void Problem(const std::string& what);
  void Forget();
  void End(boost::beast::error_code ec);

  Server::Impl* server_;
  int id_;
  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  boost::asio::steady_timer write_timer_;
  boost::asio::steady_timer read_timer_;
  double read_tokens_;  // bytes that may be read now (negative: owed)
  Clock::time_point read_refill_;
  std::unique_ptr<plan::Planner> planner_;
  boost::beast::flat_buffer buffer_;
  std::string reply_;
  std::string peer_;
  Usage usage_;  // pool priority (the pool's lock guards it)
  std::int64_t frames_ = 0;
  std::int64_t plans_ = 0;  // Plan() calls (planning thread; read between frames)
  int problems_ = 0;
  bool upgraded_ = false;
  bool closing_ = false;
  bool ended_ = false;
  bool stalled_ = false;
  bool close_connection_ = false;
};

}  // namespace frenetic::net

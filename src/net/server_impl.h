// The server's shared state (internal to net): options, counters, the I/O context, the live
// sessions and the planning pool. The I/O thread owns the fields marked so; `mutex` guards the
// counters, which planning threads update too.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "frenetic/net/server.h"
#include "net/planning_pool.h"

namespace frenetic::net {

class Session;

// Planning times and the last ego state of the current status interval.
struct Interval {
  std::vector<double> plan_ms;
  double speed = 0, d = 0;
  bool have_ego = false;
  std::int64_t cycles_at_start = 0;
};

struct Server::Impl {
  Impl(const ServerOptions& o, PlannerFactory f) : options(o), factory(std::move(f)) {}

  void Accept();
  // Answers a connection over max_connections with a 503 (or closes it when too many are being
  // answered already), counted and logged.
  void Refuse(boost::asio::ip::tcp::socket socket, int id);
  void ScheduleStatus();
  // Gives memory back to the system once connections have stopped closing for a while.
  void ScheduleTrim();
  void LogStatus();
  std::string StatusLine();
  void DoStop();

  ServerOptions options;
  PlannerFactory factory;
  int bound_port = 0;
  int next_session_id = 1;
  bool stopping = false;  // I/O thread only
  int live_sessions = 0;  // upgrading or upgraded; I/O thread only
  int refusing = 0;       // 503 answers in progress; I/O thread only

  mutable std::mutex mutex;  // guards stats, interval and logged_refusals
  ServerStats stats;
  Interval interval;
  int logged_refusals = 0;

  // Live sessions, for closing them on Stop(). Declared before io so that handlers destroyed
  // with io (which own sessions) can still unregister.
  std::map<int, std::weak_ptr<Session>> sessions;

  boost::asio::io_context io{1};
  boost::asio::ip::tcp::acceptor acceptor{io};
  boost::asio::steady_timer status_timer{io};
  boost::asio::steady_timer trim_timer{io};
  boost::asio::signal_set signals{io};
  // Declared after io: its threads post to io, and the sessions it holds close their sockets.
  PlanningPool pool;
};

}  // namespace frenetic::net

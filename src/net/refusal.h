// The answer to a connection over ServerOptions::max_connections (internal to net).
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <string>

namespace frenetic::net {

// Reads the connection's upgrade request (so that closing does not reset the connection before
// the client reads the answer), writes `HTTP/1.1 503 Service Unavailable` with `reason` as its
// one-line body, and closes; a request that does not come within 2 s is closed without an
// answer. *in_progress counts the refusals under way (incremented here, decremented when this
// one is done); I/O thread only, and it must outlive the socket's handlers.
void StartRefusal(boost::asio::ip::tcp::socket socket, std::string reason, int* in_progress);

}  // namespace frenetic::net

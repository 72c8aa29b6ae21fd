// How contactd runs cpp-httplib: the connection gate (connection_gate.hpp) accepts connections and reads request
// heads; when one is whole, an HTTP thread runs httplib's request processing (routing, handlers, responses) on it
// through ConnStream, and hands the connection back to the gate for its next request. httplib's own accept loop
// and thread-per-connection keep-alive are not used: with them, every slow or idle client held a thread.
//
// Two thread pools serve requests: `threads` for the API, and two for GET /healthz and /readyz only, so that probes
// are answered even when every API thread is busy (long downloads, progress streams).
#pragma once

#include "transport/connection_gate.hpp"

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace contactd {

struct TransportSettings {
  GateSettings gate;
  std::size_t threads = 96;                       // API threads
  std::size_t keep_alive_max = 100;               // requests per connection
  std::chrono::milliseconds read_timeout{10000};  // per read of a body
  std::chrono::milliseconds write_timeout{5000};  // per write of a response
  std::chrono::milliseconds body_timeout{60000};  // a whole request body (slow uploads are cut off)
};

// What the HTTP thread serving a request knows about its exchange (thread-local; null outside a request).
struct Exchange {
  bool body_timed_out = false;  // a body read ran past body_timeout: the handler should answer 408
  std::string bad_framing;      // a chunked body's framing is broken (chunk_framing.hpp): the handler answers 400
  bool close_after = false;     // close the connection after this response
};
Exchange* current_exchange();

// httplib::Server with its protected request processing made available to the transport.
class HttplibCore : public httplib::Server {
 public:
  bool process(httplib::Stream& stream, bool close_connection, bool& connection_closed,
               const std::function<void(httplib::Request&)>& setup) {
    return process_request(stream, close_connection, connection_closed, setup);
  }
  // httplib's content providers stop when the server socket is invalid: keep it set while serving.
  void set_serving(int listen_fd) { svr_sock_ = listen_fd; }
};

class Transport {
 public:
  // `setup` runs for every request after its head is parsed and before routing.
  Transport(TransportSettings settings, HttplibCore& core, std::function<void(httplib::Request&)> setup,
            ConnectionGate::Refused refused);
  ~Transport();

  int bind(const std::string& host, int port, std::string& error);
  // Serves until stop(); blocks the calling thread (the gate's loop).
  void run();
  // Stops accepting; connections held by the gate close; the HTTP threads finish their requests and exit.
  void stop();
  std::size_t open_connections() const { return gate_.open_connections(); }

 private:
  class Pool;
  void serve(std::unique_ptr<Connection> connection);

  const TransportSettings settings_;
  HttplibCore& core_;
  std::function<void(httplib::Request&)> setup_;
  ConnectionGate gate_;
  std::unique_ptr<Pool> api_pool_;
  std::unique_ptr<Pool> probe_pool_;
  std::atomic<bool> stopping_{false};
};

}  // namespace contactd

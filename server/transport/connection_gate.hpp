// The front door of contactd: one thread that owns the listening socket and every connection that is not being
// served (accepting, waiting for a request head, idle between keep-alive requests, or closing), multiplexed with
// epoll. An HTTP thread only ever gets a connection whose request head has arrived whole and passed check_head(),
// so slow or idle clients (slowloris) cost a file descriptor and a small buffer, never a thread:
//   - the request head must arrive within `head_timeout` (408 otherwise), and an idle keep-alive connection
//     must start its next request within `idle_timeout` (closed otherwise);
//   - limits on the head's size, request line and field count (431 / 414), and the character checks of
//     check_head() (400);
//   - at most `max_connections` connections in total and `max_connections_per_client` per remote address: at a
//     cap, the connection (of that address, for the per-address cap) that has waited longest for its request head
//     (more than a second) is closed to make room, so that a client sending whole requests always gets in; if
//     there is none, the new connection gets 503 + Retry-After;
//   - a listen backlog of `backlog` (the kernel caps it at net.core.somaxconn).
// Refusals are RFC 9457 problem documents written by the gate itself; the connection is then shut down for
// writing and drained for a moment, so the client reads the answer rather than a reset.
#pragma once

#include "transport/request_head.hpp"

#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace contactd {

struct GateSettings {
  HeadLimits head;
  int backlog = 1024;
  std::size_t max_connections = 1024;
  std::size_t max_connections_per_client = 512;  // 0 = no per-address cap
  std::chrono::milliseconds head_timeout{10000};
  std::chrono::milliseconds idle_timeout{5000};
};

class ConnectionTracker;

// The address and port of a socket address (IPv4 or IPv6), as text.
void address_of(const struct sockaddr_storage& address, std::string& ip, int& port);

// One accepted TCP connection (non-blocking socket). Destroying it closes the socket and frees its place in the
// connection caps.
class Connection {
 public:
  Connection(int fd, std::string peer_ip, int peer_port, std::shared_ptr<ConnectionTracker> tracker);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  int fd() const { return fd_; }
  const std::string& peer_ip() const { return peer_ip_; }
  int peer_port() const { return peer_port_; }

  std::string buffer;          // bytes received and not yet consumed: the request head first
  std::size_t head_bytes = 0;  // the current request's head length at the start of `buffer` (set by the gate)
  bool probe = false;          // the current request is GET /healthz or /readyz
  int requests = 0;            // requests served on this connection so far

 private:
  int fd_;
  std::string peer_ip_;
  int peer_port_;
  std::shared_ptr<ConnectionTracker> tracker_;
};

class ConnectionGate {
 public:
  // Called on the gate's thread with each connection whose request head is complete; it must not block.
  using Dispatch = std::function<void(std::unique_ptr<Connection>)>;
  // Called for every answer the gate writes itself (its status), e.g. for metrics.
  using Refused = std::function<void(int status)>;

  ConnectionGate(GateSettings settings, Dispatch dispatch, Refused refused);
  ~ConnectionGate();
  ConnectionGate(const ConnectionGate&) = delete;
  ConnectionGate& operator=(const ConnectionGate&) = delete;

  // Creates the listening socket (SO_REUSEADDR, never SO_REUSEPORT: a second server cannot share the port).
  // Returns the port (the one chosen when `port` is 0), or -1 with `error` set.
  int bind(const std::string& host, int port, std::string& error);
  int listening_fd() const { return listen_fd_; }
  // Runs the loop on the calling thread until stop().
  void run();
  // Stops the loop: the listening socket and every connection the gate holds are closed. Thread-safe.
  void stop();

  // A served connection comes back: with `keep_alive` it waits for its next request (what is already in its
  // buffer counts); otherwise it is shut down gracefully and closed. Thread-safe; after stop() it is closed.
  void give_back(std::unique_ptr<Connection> connection, bool keep_alive);

  std::size_t open_connections() const;

 private:
  enum class Mode { head, idle, closing };
  struct Entry {
    std::unique_ptr<Connection> connection;
    Mode mode = Mode::head;
    std::chrono::steady_clock::time_point since;     // when the wait began (eviction picks the oldest)
    std::chrono::steady_clock::time_point deadline;  // head or idle timeout, or the end of draining
  };

  void accept_all();
  void admit(int fd, const std::string& ip, int port);
  void on_readable(int fd);
  void examine(int fd);  // after new bytes: dispatch, refuse or keep waiting
  void expire(std::chrono::steady_clock::time_point now);
  void take_returned();
  void hold(std::unique_ptr<Connection> connection, Mode mode);
  void refuse(Entry& entry, int status, const std::string& detail, bool retry_after = false);
  void close_entry(int fd);
  // Closes the connection (of `ip`, if not empty) that has waited longest (over a second) for a request head.
  bool evict_oldest_waiting(std::chrono::steady_clock::time_point now, const std::string& ip);
  void wake();

  const GateSettings settings_;
  Dispatch dispatch_;
  Refused refused_;
  std::shared_ptr<ConnectionTracker> tracker_;
  int listen_fd_ = -1;
  int epoll_fd_ = -1;
  int wake_fd_ = -1;
  std::atomic<bool> stopping_{false};
  std::map<int, Entry> entries_;  // gate thread only
  std::mutex returned_mutex_;
  std::vector<std::pair<std::unique_ptr<Connection>, bool>> returned_;
};

}  // namespace contactd

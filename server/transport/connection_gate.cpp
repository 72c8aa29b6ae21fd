#include "transport/connection_gate.hpp"

#include "common/log.hpp"
#include "http/problem_document.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <unordered_map>

namespace contactd {

using Clock = std::chrono::steady_clock;

// Counts open connections, in total and per remote address, across the gate and the HTTP threads.
class ConnectionTracker {
 public:
  ConnectionTracker(std::size_t max_total, std::size_t max_per_client)
      : max_total_(max_total), max_per_client_(max_per_client) {}

  enum class Admission { admitted, total_full, client_full };
  Admission admit(const std::string& ip) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (total_ >= max_total_) return Admission::total_full;
    auto& mine = per_client_[ip];
    if (max_per_client_ > 0 && mine >= max_per_client_) {
      if (mine == 0) per_client_.erase(ip);
      return Admission::client_full;
    }
    ++mine;
    ++total_;
    return Admission::admitted;
  }
  void release(const std::string& ip) {
    std::lock_guard<std::mutex> lock(mutex_);
    --total_;
    const auto it = per_client_.find(ip);
    if (it != per_client_.end() && --it->second == 0) per_client_.erase(it);
  }
  std::size_t total() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return total_;
  }

 private:
  const std::size_t max_total_, max_per_client_;
  mutable std::mutex mutex_;
  std::size_t total_ = 0;
  std::unordered_map<std::string, std::size_t> per_client_;
};

Connection::Connection(int fd, std::string peer_ip, int peer_port, std::shared_ptr<ConnectionTracker> tracker)
    : fd_(fd), peer_ip_(std::move(peer_ip)), peer_port_(peer_port), tracker_(std::move(tracker)) {}

Connection::~Connection() {
  ::close(fd_);
  if (tracker_) tracker_->release(peer_ip_);
}

void address_of(const sockaddr_storage& address, std::string& ip, int& port) {
  char text[INET6_ADDRSTRLEN] = "";
  if (address.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&address);
    ::inet_ntop(AF_INET, &a->sin_addr, text, sizeof text);
    port = ntohs(a->sin_port);
  } else if (address.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&address);
    ::inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof text);
    port = ntohs(a->sin6_port);
  }
  ip = text;
}

namespace {

constexpr auto kDrain = std::chrono::milliseconds(1000);  // how long a refused or closing connection is drained
constexpr std::size_t kMaxUntracked = 256;                // refusals drained beyond the caps, at most

// The answer the gate writes itself: a problem document, then the connection closes.
std::string canned_response(int status, const std::string& detail, bool retry_after) {
  const std::string body = problem_document(status, "", detail, "");
  std::string out = "HTTP/1.1 " + std::to_string(status) + " " + reason_phrase(status) +
                    "\r\nContent-Type: application/problem+json\r\nContent-Length: " + std::to_string(body.size()) +
                    "\r\nConnection: close\r\n";
  if (retry_after) out += "Retry-After: 5\r\n";
  return out + "\r\n" + body;
}

std::string seconds_text(std::chrono::milliseconds d) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", static_cast<double>(d.count()) / 1000.0);
  return text;
}

// A fresh socket's send buffer always takes a few hundred bytes: one non-blocking send, no waiting.
void send_now(int fd, const std::string& data) {
  const ssize_t n = ::send(fd, data.data(), data.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  (void)n;
}

}  // namespace

ConnectionGate::ConnectionGate(GateSettings settings, Dispatch dispatch, Refused refused)
    : settings_(settings),
      dispatch_(std::move(dispatch)),
      refused_(std::move(refused)),
      tracker_(std::make_shared<ConnectionTracker>(settings.max_connections, settings.max_connections_per_client)) {
  epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (epoll_fd_ < 0 || wake_fd_ < 0) throw std::runtime_error(std::string("epoll: ") + std::strerror(errno));
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = wake_fd_;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, wake_fd_, &ev);
}

ConnectionGate::~ConnectionGate() {
  entries_.clear();
  returned_.clear();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  ::close(wake_fd_);
  ::close(epoll_fd_);
}

int ConnectionGate::bind(const std::string& host, int port, std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    error = std::string("cannot resolve '") + host + "': " + ::gai_strerror(rc);
    return -1;
  }
  error = "no address";
  for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int on = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);  // restart while old connections linger
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 || ::listen(fd, settings_.backlog) != 0) {
      error = std::strerror(errno);
      ::close(fd);
      continue;
    }
    sockaddr_storage bound{};
    socklen_t length = sizeof bound;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &length);
    std::string ip;
    int actual = -1;
    address_of(bound, ip, actual);
    ::freeaddrinfo(found);
    listen_fd_ = fd;
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = listen_fd_;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, listen_fd_, &ev);
    return actual;
  }
  ::freeaddrinfo(found);
  return -1;
}

void ConnectionGate::run() {
  std::vector<epoll_event> events(256);
  auto last_sweep = Clock::now();
  while (!stopping_.load()) {
    const int n = ::epoll_wait(epoll_fd_, events.data(), static_cast<int>(events.size()), 50);
    for (int k = 0; k < n; ++k) {
      const int fd = events[static_cast<std::size_t>(k)].data.fd;
      if (fd == listen_fd_) {
        accept_all();
      } else if (fd == wake_fd_) {
        std::uint64_t count = 0;
        while (::read(wake_fd_, &count, sizeof count) > 0) {
        }
        take_returned();
      } else {
        on_readable(fd);
      }
    }
    const auto now = Clock::now();
    if (now - last_sweep >= std::chrono::milliseconds(50)) {
      expire(now);
      last_sweep = now;
    }
  }
  entries_.clear();  // closes every connection the gate holds
  std::lock_guard<std::mutex> lock(returned_mutex_);
  returned_.clear();
}

void ConnectionGate::stop() {
  stopping_ = true;
  wake();
}

void ConnectionGate::wake() {
  const std::uint64_t one = 1;
  const ssize_t n = ::write(wake_fd_, &one, sizeof one);
  (void)n;
}

std::size_t ConnectionGate::open_connections() const { return tracker_->total(); }

void ConnectionGate::give_back(std::unique_ptr<Connection> connection, bool keep_alive) {
  {
    std::lock_guard<std::mutex> lock(returned_mutex_);
    if (stopping_) return;  // closed here
    returned_.emplace_back(std::move(connection), keep_alive);
  }
  wake();
}

void ConnectionGate::take_returned() {
  std::vector<std::pair<std::unique_ptr<Connection>, bool>> returned;
  {
    std::lock_guard<std::mutex> lock(returned_mutex_);
    returned.swap(returned_);
  }
  for (auto& [connection, keep_alive] : returned) {
    const int fd = connection->fd();
    if (!keep_alive) {
      ::shutdown(fd, SHUT_WR);
      hold(std::move(connection), Mode::closing);
      continue;
    }
    const bool pipelined = !connection->buffer.empty();
    hold(std::move(connection), Mode::idle);
    if (pipelined) examine(fd);  // the next request may already be whole
  }
}

void ConnectionGate::hold(std::unique_ptr<Connection> connection, Mode mode) {
  const int fd = connection->fd();
  const auto now = Clock::now();
  Entry entry;
  entry.connection = std::move(connection);
  entry.mode = mode;
  entry.since = now;
  entry.deadline = now + (mode == Mode::head   ? settings_.head_timeout
                          : mode == Mode::idle ? settings_.idle_timeout
                                               : std::chrono::duration_cast<std::chrono::milliseconds>(kDrain));
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = fd;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &ev);
  entries_[fd] = std::move(entry);
}

void ConnectionGate::close_entry(int fd) {
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  entries_.erase(fd);  // the Connection closes its socket
}

void ConnectionGate::accept_all() {
  while (true) {
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;
      if (errno == EMFILE || errno == ENFILE) {
        // The pending connections stay in the backlog; a pause keeps this loop from spinning on them.
        static auto last_note = Clock::time_point{};
        if (Clock::now() - last_note > std::chrono::seconds(10)) {
          last_note = Clock::now();
          log_line("gate: out of file descriptors; accepting again as connections close");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      return;  // EAGAIN: none left
    }
    std::string ip;
    int port = 0;
    address_of(address, ip, port);
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    admit(fd, ip, port);
  }
}

void ConnectionGate::admit(int fd, const std::string& ip, int port) {
  auto admission = tracker_->admit(ip);
  // At a cap: make room by closing the connection (of this address, at the per-address cap) that has waited
  // longest for its request.
  if (admission != ConnectionTracker::Admission::admitted &&
      evict_oldest_waiting(Clock::now(), admission == ConnectionTracker::Admission::client_full ? ip : ""))
    admission = tracker_->admit(ip);
  if (admission == ConnectionTracker::Admission::admitted) {
    hold(std::make_unique<Connection>(fd, ip, port, tracker_), Mode::head);
    return;
  }
  const bool total = admission == ConnectionTracker::Admission::total_full;
  const std::string detail = total ? "the server has its maximum of " + std::to_string(settings_.max_connections) +
                                         " open connections; retry later"
                                   : "this address has its maximum of " +
                                         std::to_string(settings_.max_connections_per_client) +
                                         " open connections; retry later";
  if (refused_) refused_(503);
  send_now(fd, canned_response(503, detail, true));
  // Drained briefly (so that the client reads the answer, not a reset), outside the caps but bounded in number.
  if (entries_.size() < settings_.max_connections + kMaxUntracked) {
    ::shutdown(fd, SHUT_WR);
    hold(std::make_unique<Connection>(fd, ip, port, nullptr), Mode::closing);
  } else {
    ::close(fd);
  }
}

bool ConnectionGate::evict_oldest_waiting(Clock::time_point now, const std::string& ip) {
  // A connection that has waited more than a second for its head (or its next request) is the likeliest to be
  // a slow or idle client; closing it keeps the server reachable for a client that sends a whole request.
  auto oldest = entries_.end();
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    if (it->second.mode == Mode::closing || !it->second.connection) continue;
    if (!ip.empty() && it->second.connection->peer_ip() != ip) continue;
    if (now - it->second.since < std::chrono::seconds(1)) continue;
    if (oldest == entries_.end() || it->second.since < oldest->second.since) oldest = it;
  }
  if (oldest == entries_.end()) return false;
  if (oldest->second.mode == Mode::head) {
    if (refused_) refused_(408);
    send_now(oldest->first, canned_response(408,
                                            "the request head took too long while the server is at its "
                                            "connection limit",
                                            false));
  }
  close_entry(oldest->first);  // at once: its place in the caps is what the new connection needs
  return true;
}

void ConnectionGate::on_readable(int fd) {
  const auto it = entries_.find(fd);
  if (it == entries_.end()) return;
  Entry& entry = it->second;
  Connection& c = *entry.connection;
  char chunk[16384];
  bool ended = false;
  while (true) {
    std::size_t want = sizeof chunk;
    if (entry.mode != Mode::closing) {
      // Never hold more than one head (plus a little of the body after it) per connection.
      const std::size_t room = settings_.head.max_head_bytes + 1024;
      if (c.buffer.size() >= room) break;
      want = std::min(want, room - c.buffer.size());
    }
    const ssize_t n = ::recv(fd, chunk, want, 0);
    if (n > 0) {
      if (entry.mode != Mode::closing) c.buffer.append(chunk, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    ended = true;  // end of stream (a client may send its request and shut down its side) or an error
    break;
  }
  if (entry.mode == Mode::closing || (ended && c.buffer.empty())) {
    if (ended) close_entry(fd);
    return;
  }
  if (entry.mode == Mode::idle && !c.buffer.empty()) {
    entry.mode = Mode::head;  // the next request has begun: it now has the head deadline
    entry.since = Clock::now();
    entry.deadline = entry.since + settings_.head_timeout;
  }
  examine(fd);
  if (ended && entries_.count(fd) && entries_[fd].mode != Mode::closing) close_entry(fd);  // no whole head came
}

void ConnectionGate::examine(int fd) {
  const auto it = entries_.find(fd);
  if (it == entries_.end()) return;
  Entry& entry = it->second;
  Connection& c = *entry.connection;
  const HeadCheck check = check_head(c.buffer, settings_.head);
  switch (check.verdict) {
    case HeadCheck::Verdict::incomplete:
      return;
    case HeadCheck::Verdict::refused:
      refuse(entry, check.status, check.detail);
      return;
    case HeadCheck::Verdict::complete:
      break;
  }
  c.buffer.erase(0, check.skip);
  c.head_bytes = shorten_range_positions(c.buffer, check.head_end - check.skip);
  c.probe = check.probe;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  std::unique_ptr<Connection> ready = std::move(entry.connection);
  entries_.erase(it);
  dispatch_(std::move(ready));
}

void ConnectionGate::refuse(Entry& entry, int status, const std::string& detail, bool retry_after) {
  if (refused_) refused_(status);
  const int fd = entry.connection->fd();
  send_now(fd, canned_response(status, detail, retry_after));
  ::shutdown(fd, SHUT_WR);
  entry.connection->buffer.clear();
  entry.connection->buffer.shrink_to_fit();
  entry.mode = Mode::closing;
  entry.deadline = Clock::now() + kDrain;
}

void ConnectionGate::expire(Clock::time_point now) {
  std::vector<int> done;
  for (auto& [fd, entry] : entries_) {
    if (now < entry.deadline) continue;
    switch (entry.mode) {
      case Mode::head:
        refuse(entry, 408, "the request head did not arrive within " + seconds_text(settings_.head_timeout));
        break;
      case Mode::idle:
      case Mode::closing:
        done.push_back(fd);
        break;
    }
  }
  for (int fd : done) close_entry(fd);
}

}  // namespace contactd

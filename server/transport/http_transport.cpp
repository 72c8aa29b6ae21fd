#include "transport/http_transport.hpp"

#include <poll.h>
#include <sys/select.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cctype>
#include <cstring>
#include <string_view>

#include "transport/chunk_framing.hpp"

namespace contactd {

using Clock = std::chrono::steady_clock;

namespace {

thread_local Exchange* t_exchange = nullptr;

int poll_for(int fd, short events, std::chrono::milliseconds timeout) {
  pollfd p{fd, events, 0};
  while (true) {
    const int rc = ::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(0, timeout.count())));
    if (rc < 0 && errno == EINTR) continue;
    return rc;
  }
}

// One request's view of its connection for httplib: the bytes the gate already read (the head, perhaps the start
// of the body) come first, then the socket, with a deadline for the whole body. Reads ahead into the
// connection's buffer, so that what follows this request (pipelining) stays for the next one.
class ConnStream final : public httplib::Stream {
 public:
  ConnStream(Connection& c, const TransportSettings& s, Exchange& exchange)
      : c_(c),
        s_(s),
        exchange_(exchange),
        body_deadline_(Clock::now() + s.body_timeout),
        head_left_(c.head_bytes),
        chunked_(is_chunked(std::string_view(c.buffer).substr(0, std::min(c.head_bytes, c.buffer.size())))) {}

  // Removes what this request consumed from the connection's buffer.
  void finish() { c_.buffer.erase(0, std::min(consumed_, c_.buffer.size())); }

  bool is_readable() const override {
    return consumed_ < c_.buffer.size() || poll_for(c_.fd(), POLLIN, s_.read_timeout) > 0;
  }

  bool is_writable() const override {
    if (poll_for(c_.fd(), POLLOUT, s_.write_timeout) <= 0) return false;
    // Still connected? (A readable socket with nothing to read has been closed by the client.)
    char byte;
    if (poll_for(c_.fd(), POLLIN, std::chrono::milliseconds(0)) <= 0) return true;
    return ::recv(c_.fd(), &byte, 1, MSG_PEEK | MSG_DONTWAIT) > 0;
  }

  ssize_t read(char* ptr, size_t size) override {
    if (consumed_ >= c_.buffer.size() && !fill()) return -1;
    if (consumed_ >= c_.buffer.size()) return 0;  // end of stream
    const std::size_t n = std::min(size, c_.buffer.size() - consumed_);
    // The body's bytes (past the head) of a chunked request go through its framing check first.
    const std::size_t head = std::min(n, head_left_);
    head_left_ -= head;
    if (chunked_ && n > head && !framing_.feed(c_.buffer.data() + consumed_ + head, n - head)) {
      exchange_.bad_framing = framing_.error();
      return -1;
    }
    std::memcpy(ptr, c_.buffer.data() + consumed_, n);
    consumed_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    while (true) {
      if (poll_for(c_.fd(), POLLOUT, s_.write_timeout) <= 0) return -1;
      const ssize_t n = ::send(c_.fd(), ptr, size, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
      return n;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = c_.peer_ip();
    port = c_.peer_port();
  }

  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    ip.clear();
    port = 0;
    if (::getsockname(c_.fd(), reinterpret_cast<sockaddr*>(&address), &length) == 0) address_of(address, ip, port);
  }

  // httplib's only use of the descriptor is a guard for its select()-based socket stream (descriptors from
  // FD_SETSIZE up answer 500). This stream polls, so it has no such limit and hides large descriptors.
  socket_t socket() const override { return c_.fd() < FD_SETSIZE ? c_.fd() : INVALID_SOCKET; }

 private:
  // Reads more into the buffer (up to 64 KiB at a time). False on timeout or error; true with nothing added at
  // the end of the stream.
  bool fill() {
    if (consumed_ > 0 && consumed_ >= c_.buffer.size()) {
      c_.buffer.clear();
      consumed_ = 0;
    }
    while (true) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(body_deadline_ - Clock::now());
      if (left.count() <= 0) {
        exchange_.body_timed_out = true;
        return false;
      }
      const int ready = poll_for(c_.fd(), POLLIN, std::min(left, s_.read_timeout));
      if (ready == 0 && left <= s_.read_timeout) {
        exchange_.body_timed_out = true;
        return false;
      }
      if (ready <= 0) return false;
      char chunk[65536];
      const ssize_t n = ::recv(c_.fd(), chunk, sizeof chunk, MSG_DONTWAIT);
      if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
      if (n < 0) return false;
      c_.buffer.append(chunk, static_cast<std::size_t>(n));
      return true;
    }
  }

  // Whether the head (its field lines, case-insensitive) says Transfer-Encoding: chunked. request_guard's
  // check_framing refuses any other coding before a body is read.
  static bool is_chunked(std::string_view head) {
    std::string lowered(head);
    for (char& ch : lowered) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    for (std::size_t at = lowered.find("\r\ntransfer-encoding:"); at != std::string::npos;
         at = lowered.find("\r\ntransfer-encoding:", at + 2)) {
      const std::size_t end = lowered.find("\r\n", at + 2);
      if (lowered.substr(at, end - at).find("chunked") != std::string::npos) return true;
    }
    return false;
  }

  Connection& c_;
  const TransportSettings& s_;
  Exchange& exchange_;
  const Clock::time_point body_deadline_;
  std::size_t consumed_ = 0;
  std::size_t head_left_;  // bytes of the head not yet read (fill() may empty the buffer once they are)
  const bool chunked_;
  ChunkFraming framing_;
};

}  // namespace

Exchange* current_exchange() { return t_exchange; }

// A fixed number of threads taking connections from a queue.
class Transport::Pool {
 public:
  Pool(std::size_t threads, std::function<void(std::unique_ptr<Connection>)> serve) : serve_(std::move(serve)) {
    for (std::size_t k = 0; k < threads; ++k) threads_.emplace_back([this] { loop(); });
  }
  ~Pool() { stop(); }

  void submit(std::unique_ptr<Connection> connection) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return;  // closed
      queue_.push_back(std::move(connection));
    }
    ready_.notify_one();
  }

  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      queue_.clear();
    }
    ready_.notify_all();
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }

 private:
  void loop() {
    while (true) {
      std::unique_ptr<Connection> connection;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
        if (stopping_) return;
        connection = std::move(queue_.front());
        queue_.pop_front();
      }
      serve_(std::move(connection));
    }
  }

  std::function<void(std::unique_ptr<Connection>)> serve_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::unique_ptr<Connection>> queue_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

Transport::Transport(TransportSettings settings, HttplibCore& core, std::function<void(httplib::Request&)> setup,
                     ConnectionGate::Refused refused)
    : settings_(std::move(settings)),
      core_(core),
      setup_(std::move(setup)),
      gate_(
          settings_.gate,
          [this](std::unique_ptr<Connection> c) { (c->probe ? probe_pool_ : api_pool_)->submit(std::move(c)); },
          std::move(refused)) {
  api_pool_ = std::make_unique<Pool>(settings_.threads, [this](std::unique_ptr<Connection> c) { serve(std::move(c)); });
  probe_pool_ = std::make_unique<Pool>(2, [this](std::unique_ptr<Connection> c) { serve(std::move(c)); });
}

Transport::~Transport() { stop(); }

int Transport::bind(const std::string& host, int port, std::string& error) {
  const int bound = gate_.bind(host, port, error);
  if (bound >= 0) core_.set_serving(gate_.listening_fd());
  return bound;
}

void Transport::run() { gate_.run(); }

void Transport::stop() {
  if (stopping_.exchange(true)) return;
  core_.set_serving(INVALID_SOCKET);  // content providers (downloads, streams) stop at their next chunk
  gate_.stop();
  api_pool_->stop();
  probe_pool_->stop();
}

void Transport::serve(std::unique_ptr<Connection> connection) {
  Exchange exchange;
  t_exchange = &exchange;
  ConnStream stream(*connection, settings_, exchange);
  const bool last = stopping_.load() || connection->requests + 1 >= static_cast<int>(settings_.keep_alive_max);
  bool closed = false;
  const bool ok = core_.process(stream, last, closed, setup_);
  t_exchange = nullptr;
  stream.finish();
  ++connection->requests;
  const bool keep_alive =
      ok && !closed && !last && !exchange.close_after && !exchange.body_timed_out && !stopping_.load();
  gate_.give_back(std::move(connection), keep_alive);
}

}  // namespace contactd

// The HTTP face of contactd: one class owns the transport (connection gate, HTTP threads, httplib's request
// processing: http_transport.hpp) and the rules every request passes first; the routes are modules of free
// functions registered on a Router (routes.hpp: jobs, streams, service, web), which see a RouteContext, not this
// class.
// Cross-cutting rules live in the pre-routing handler (framing, Host allow-list, cross-site rules, bearer token,
// Content-Encoding and media type, body size, "not ready"), the error handler (JSON problem documents for every
// 4xx/5xx, 405 with Allow) and the exception handler (500). The API is specified in api/openapi.yaml and explained
// in docs/server.md.
#pragma once

// The solver's headers (Eigen) before httplib's: <resolv.h>, which httplib includes, defines a macro `_res`
// that Eigen uses as a parameter name.
#include "http/routes.hpp"

#include "transport/http_transport.hpp"
#include "transport/request_guard.hpp"

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <vector>

namespace contactd {

class HttpServer {
 public:
  // `budget` bounds the job bodies read and validated at once; the queue's workers share its validation slots.
  HttpServer(HttpSettings settings, JobQueue& queue, JobStore& store, Metrics& metrics, BodyBudget& budget);
  ~HttpServer();

  // Binds the listening socket. Returns the port, or -1 if it cannot bind (`error` says why).
  int bind(std::string& error);
  // Serves until stop(); blocks the calling thread.
  void listen();

  // Start-up done: /readyz answers 200 and /v1 routes are served (before, they answer 503).
  void set_ready() { state_.ready = true; }
  // Shutdown, first step: /readyz answers 503 and submissions are refused; other requests are still served.
  void begin_shutdown() { state_.stopping = true; }
  // Second step: open streams send what is left and close (within about a second).
  void close_streams() { state_.closing_streams = true; }
  // Waits (at most `timeout`) until every stream has sent its last bytes and closed.
  void wait_for_streams(std::chrono::milliseconds timeout);
  // Last step: stops listening and waits for the connections to finish.
  void stop() { transport_->stop(); }

 private:
  httplib::Server::HandlerResponse pre_route(const Request& req, Response& res);
  int expect_continue(const Request& req, Response& res);
  // 413: the request's size (when known), the limit and the setting that raises it.
  void send_too_large(Response& res, const std::string& path, std::optional<std::uint64_t> bytes) const;
  httplib::Server::HandlerResponse on_error(const Request& req, Response& res);
  void on_exception(const Request& req, Response& res, std::exception_ptr error);
  void on_response(const Request& req, const Response& res);
  void method_not_allowed_or_not_found(const Request& req, Response& res);

  HttpSettings settings_;
  GuardSettings guard_;
  Metrics& metrics_;
  HttplibCore core_;
  std::unique_ptr<Transport> transport_;
  ServerState state_;
  RouteContext context_;
  Router router_{core_};
};

}  // namespace contactd

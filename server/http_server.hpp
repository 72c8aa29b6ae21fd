// The HTTP face of contactd: one class owns the transport (connection gate, HTTP threads, httplib's request
// processing: http_transport.hpp); the routes are registered in one place (register_routes) and each handler is
// short: parse the request, call the JobQueue, map the outcome to a response (http_jobs.cpp, http_streams.cpp;
// the service endpoints in http_service.cpp; the web page and the examples in http_web.cpp).
// Cross-cutting rules live in the pre-routing handler (framing, Host allow-list, cross-site rules, bearer token,
// Content-Encoding and media type, body size, "not ready"), the error handler (JSON problem documents for every
// 4xx/5xx, 405 with Allow) and the exception handler (500). The API is specified in api/openapi.yaml and explained
// in docs/server.md.
#pragma once

// The solver's headers (Eigen) before httplib's: <resolv.h>, which httplib includes, defines a macro `_res`
// that Eigen uses as a parameter name.
#include "job_queue.hpp"
#include "job_store.hpp"
#include "metrics.hpp"

#include "body_budget.hpp"
#include "http_transport.hpp"
#include "request_guard.hpp"

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

struct HttpSettings {
  std::string host = "127.0.0.1";
  int port = 8080;                           // 0: any free port (bind() returns it)
  std::size_t max_request_bytes = 8u << 20;  // larger bodies get 413
  std::string token;                         // "" = no authentication
  int heartbeat_seconds = 15;                // SSE comment / NDJSON empty line at least this often
  int max_streams = 64;                      // concurrent progress streams; more get 503
  int http_threads = 0;                      // 0 = max_streams + 32
  bool access_log = false;                   // one stderr line per request
  std::vector<std::string> allowed_hosts;    // Host header allow-list; empty = loopback names and `host`
  // Connections (connection_gate.hpp).
  std::size_t max_connections = 1024;
  std::size_t max_connections_per_client = 512;
  int listen_backlog = 1024;
  double head_timeout_seconds = 10.0;
  double idle_timeout_seconds = 5.0;
  double body_timeout_seconds = 60.0;
  std::size_t max_header_bytes = 16 * 1024;
  std::size_t max_header_fields = 64;
  // Job bodies (body_budget.hpp).
  std::size_t max_large_bodies = 4;  // bodies over 256 KiB read at once
  std::size_t max_validations = 0;   // jobs parsed and validated at once; 0 = the number of cores (at least 2)
};

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
  void set_ready() { ready_ = true; }
  // Shutdown, first step: /readyz answers 503 and submissions are refused; other requests are still served.
  void begin_shutdown() { stopping_ = true; }
  // Second step: open streams send what is left and close (within about a second).
  void close_streams() { closing_streams_ = true; }
  // Waits (at most `timeout`) until every stream has sent its last bytes and closed.
  void wait_for_streams(std::chrono::milliseconds timeout);
  // Last step: stops listening and waits for the connections to finish.
  void stop() { transport_->stop(); }

 private:
  using Request = httplib::Request;
  using Response = httplib::Response;
  using ContentReader = httplib::ContentReader;
  struct Route {
    std::string method;
    std::regex pattern;
  };
  struct Stream;

  void register_routes();
  void add_route(const std::string& method, const std::string& pattern);

  httplib::Server::HandlerResponse pre_route(const Request& req, Response& res);
  int expect_continue(const Request& req, Response& res);
  // 413: the request's size (when known), the limit and the setting that raises it.
  void send_too_large(Response& res, const std::string& path, std::optional<std::uint64_t> bytes) const;
  httplib::Server::HandlerResponse on_error(const Request& req, Response& res);
  void on_exception(const Request& req, Response& res, std::exception_ptr error);
  void on_response(const Request& req, const Response& res);

  void handle_root(const Request& req, Response& res);
  void handle_web_file(const Request& req, Response& res);
  void handle_examples(const Request& req, Response& res);
  void handle_example(const Request& req, Response& res);
  void handle_healthz(const Request& req, Response& res);
  void handle_readyz(const Request& req, Response& res);
  void handle_metrics(const Request& req, Response& res);
  void handle_problem_type(const Request& req, Response& res);
  void handle_submit(const Request& req, Response& res, const ContentReader& reader);
  void handle_validate(const Request& req, Response& res, const ContentReader& reader);
  void handle_list(const Request& req, Response& res);
  void handle_get(const Request& req, Response& res);
  void handle_delete(const Request& req, Response& res);
  void handle_cancel(const Request& req, Response& res);
  void handle_events(const Request& req, Response& res);
  void handle_result(const Request& req, Response& res, bool sidecar);
  void handle_schema(const Request& req, Response& res);
  void handle_openapi(const Request& req, Response& res);

  // Helpers.
  bool authorized(const Request& req) const;
  // Reads a JSON job body within the body budget; on failure the response is set and the result is false.
  bool read_json_body(const Request& req, Response& res, const ContentReader& reader, std::string& body,
                      BodyBudget::Slot& slot);
  std::shared_ptr<Job> find_job(const Request& req, Response& res);
  nlohmann::json job_resource(const JobRecord& record, int queue_position) const;
  bool pump_stream(Stream& stream, httplib::DataSink& sink);
  void method_not_allowed_or_not_found(const Request& req, Response& res);

  HttpSettings settings_;
  GuardSettings guard_;
  JobQueue& queue_;
  JobStore& store_;
  Metrics& metrics_;
  BodyBudget& budget_;
  HttplibCore core_;
  std::unique_ptr<Transport> transport_;
  std::vector<Route> routes_;
  std::atomic<bool> ready_{false};
  std::atomic<bool> stopping_{false};
  std::atomic<bool> closing_streams_{false};
  std::atomic<int> streams_{0};
  std::regex cancel_route_;
  const std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

}  // namespace contactd

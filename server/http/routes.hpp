// The routes of contactd's HTTP API, registered by modules on a Router: jobs (http_jobs.cpp: submit, validate,
// list, get, cancel, delete), streams (http_streams.cpp: progress events, result files), service
// (http_service.cpp: probes, metrics, problem types, schema, OpenAPI) and web (http_web.cpp: the page, the
// examples). Each handler is a free function of a RouteContext: what a route may touch (the job queue, the store,
// metrics, the body budget, the server's state and settings), never the transport. The HttpServer
// (http_server.hpp) owns the transport and the rules every request passes first, and asks the Router which
// routes exist (404 / 405 before a body is read). Dependencies point one way: routes -> jobs -> solver; the
// problem documents (problem_document.hpp) are a leaf both the transport and the routes use.
#pragma once

// The solver's headers (Eigen) before httplib's: <resolv.h>, which httplib includes, defines a macro `_res`
// that Eigen uses as a parameter name.
#include "jobs/job_queue.hpp"
#include "metrics/metrics.hpp"
#include "store/job_store.hpp"

#include "http/http_settings.hpp"
#include "jobs/body_budget.hpp"

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <vector>

namespace contactd {

using Request = httplib::Request;
using Response = httplib::Response;
using ContentReader = httplib::ContentReader;

// What the server's lifecycle says, read by the routes (set by HttpServer).
struct ServerState {
  std::atomic<bool> ready{false};            // start-up done: /readyz 200, /v1 served
  std::atomic<bool> stopping{false};         // shutdown begun: submissions refused
  std::atomic<bool> closing_streams{false};  // open streams send what is left and close
  std::atomic<int> streams{0};               // progress streams open now
  const std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
};

// The routes known to the server, registered on httplib's router and remembered to answer 404 / 405 early.
class Router {
 public:
  using Handler = std::function<void(const Request&, Response&)>;
  using BodyHandler = std::function<void(const Request&, Response&, const ContentReader&)>;
  explicit Router(httplib::Server& core) : core_(core) {}
  void get(const std::string& pattern, Handler handler);            // HEAD too
  void post(const std::string& pattern, Handler handler);           // the body is read by httplib (or absent)
  void post_body(const std::string& pattern, BodyHandler handler);  // the handler reads the body itself
  void del(const std::string& pattern, Handler handler);
  bool known(const std::string& method, const std::string& path) const;
  // The methods of the routes matching `path` (empty: no such resource).
  std::vector<std::string> allowed(const std::string& path) const;

 private:
  struct Route {
    std::string method;
    std::regex pattern;
  };
  httplib::Server& core_;
  std::vector<Route> routes_;
};

struct RouteContext {
  const HttpSettings& settings;
  JobQueue& queue;
  JobStore& store;
  Metrics& metrics;
  BodyBudget& budget;
  ServerState& state;
  std::function<std::size_t()> open_connections;  // the transport's count, for /metrics
  // 413: the request's size (when known), the limit and the setting that raises it.
  std::function<void(Response&, const std::string&, std::optional<std::uint64_t>)> send_too_large;

  bool authorized(const Request& req) const;  // the bearer token, if the server has one
  // Reads a JSON job body within the body budget; on failure the response is set and the result is false.
  bool read_json_body(const Request& req, Response& res, const ContentReader& reader, std::string& body,
                      BodyBudget::Slot& slot) const;
  // The job the path names, or null with the answer set: 404 (a malformed id is no job either), or 500 corrupt-job
  // when its files are damaged.
  std::shared_ptr<Job> find_job(const Request& req, Response& res) const;
  // The job as JSON; `listed`: as the job list carries it (its progress a bounded digest, progress_digest).
  nlohmann::json job_resource(const JobRecord& record, int queue_position, bool listed = false) const;
};

void register_job_routes(Router& router, RouteContext& context);
void register_stream_routes(Router& router, RouteContext& context);
void register_service_routes(Router& router, RouteContext& context);
void register_web_routes(Router& router, RouteContext& context);

// A body-less POST .../cancel (curl -X POST) is answered by the pre-routing rules, before httplib would wait for
// a body: whether a path is that route, and its handler.
bool is_cancel_path(const std::string& path);
void handle_cancel(RouteContext& context, const Request& req, Response& res);

}  // namespace contactd

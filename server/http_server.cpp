#include "http_server.hpp"

#include "events.hpp"
#include "util.hpp"

#include "solve.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <thread>

namespace contactd {

namespace assets {
std::string_view job_schema();
std::string_view openapi_yaml();
}  // namespace assets

namespace {

using Handled = httplib::Server::HandlerResponse;

// The problem types this API defines (RFC 9457 "type"): relative URIs that GET /problems/<slug> explains.
// Plain HTTP errors whose status says everything use "about:blank".
struct ProblemType {
  const char* slug;
  const char* title;
  const char* description;
};
const ProblemType kProblemTypes[] = {
    {"invalid-job", "The job is invalid",
     "The body is not a valid contact job. `errors` lists every problem found, each with the JSON pointer "
     "(RFC 6901) of the offending value; the pointer \"\" means the document as a whole (for example text that is "
     "not JSON)."},
    {"invalid-request", "The request is malformed",
     "A query parameter or header has a value the API does not accept; `detail` names it."},
    {"queue-full", "The queue is full",
     "The server already holds its maximum number of queued jobs. Retry after the number of seconds in the "
     "Retry-After header."},
    {"not-ready", "The server is not ready",
     "The server is starting (reading its job store back) or shutting down. Retry after Retry-After seconds."},
    {"too-many-streams", "Too many progress streams",
     "The server already serves its maximum number of concurrent progress streams."},
    {"idempotency-key-reused", "The Idempotency-Key was used with another body",
     "A job was already submitted with this Idempotency-Key and a different body. Use a new key for a new job."},
    {"job-not-finished", "The job has not finished",
     "The operation needs a finished job (SUCCEEDED, FAILED or CANCELLED); `state` is the job's current state."},
    {"job-finished", "The job has already finished", "A finished job cannot be cancelled; `state` is its state."},
    {"no-result", "The job has no result file",
     "The job finished without a solution to store (it failed before the first iteration, or was cancelled "
     "before it started)."},
    {"store-error", "The job store failed",
     "The server could not read or write its data directory; `detail` says why."},
};

// The reason phrase of a status (RFC 9110), the title of an about:blank problem.
const char* reason_phrase(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 403:
      return "Forbidden";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 406:
      return "Not Acceptable";
    case 408:
      return "Request Timeout";
    case 409:
      return "Conflict";
    case 411:
      return "Length Required";
    case 413:
      return "Content Too Large";
    case 414:
      return "URI Too Long";
    case 415:
      return "Unsupported Media Type";
    case 416:
      return "Range Not Satisfiable";
    case 417:
      return "Expectation Failed";
    case 422:
      return "Unprocessable Content";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 501:
      return "Not Implemented";
    case 503:
      return "Service Unavailable";
    default:
      return status >= 500 ? "Server Error" : "Client Error";
  }
}

const char* problem_title(const std::string& slug) {
  for (const auto& t : kProblemTypes)
    if (slug == t.slug) return t.title;
  return "";
}

std::string dump(const nlohmann::json& j) {
  // Replaces invalid UTF-8 (a hostile path echoed in `instance`) instead of throwing.
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void send_json(httplib::Response& res, int status, const nlohmann::json& j) {
  res.status = status;
  // With the parameter, httplib does not compress the response: it would use brotli at its slowest quality for
  // any client that accepts "br" (a long job list would cost a second of CPU).
  res.set_content(dump(j) + "\n", "application/json; charset=utf-8");
}

// An RFC 9457 problem document. `slug` names one of kProblemTypes, or is "" for about:blank.
void send_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                  const std::string& instance, nlohmann::json extra = nlohmann::json::object()) {
  nlohmann::json problem = extra.is_object() ? std::move(extra) : nlohmann::json::object();
  problem["type"] = slug.empty() ? std::string("about:blank") : "/problems/" + slug;
  problem["title"] = slug.empty() ? std::string(reason_phrase(status)) : std::string(problem_title(slug));
  problem["status"] = status;
  problem["detail"] = detail;
  if (!instance.empty()) problem["instance"] = instance;
  res.status = status;
  res.set_content(dump(problem) + "\n", "application/problem+json");
}

bool has_body(const httplib::Request& req) {
  return req.has_header("Transfer-Encoding") ||
         (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0");
}

// A decimal integer in [0, max]; false for anything else (signs, spaces, overflow, empty).
bool parse_count(const std::string& text, std::uint64_t max, std::uint64_t& value) {
  if (text.empty() || text.size() > 19) return false;
  value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<std::uint64_t>(c - '0');
  }
  return value <= max;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// The media type of a Content-Type value, lower case, without parameters.
std::string media_type(const std::string& content_type) {
  return lower(trim(content_type.substr(0, content_type.find(';'))));
}

std::string job_link(const std::string& id) { return "/v1/jobs/" + id; }

std::string encode_cursor(const JobQueue::Cursor& c) {
  return base64url_encode(std::to_string(c.created_us) + ":" + c.id);
}

bool decode_cursor(const std::string& token, JobQueue::Cursor& cursor) {
  std::string raw;
  if (token.size() > 200 || !base64url_decode(token, raw)) return false;
  const auto colon = raw.find(':');
  if (colon == std::string::npos) return false;
  std::uint64_t created = 0;
  if (!parse_count(raw.substr(0, colon), static_cast<std::uint64_t>(INT64_MAX), created)) return false;
  cursor.created_us = static_cast<std::int64_t>(created);
  cursor.id = raw.substr(colon + 1);
  return is_job_id(cursor.id);
}

std::string format_sse(const Event& e) {
  return "id: " + std::to_string(e.seq) + "\nevent: " + e.type + "\ndata: " + e.json + "\n\n";
}

}  // namespace

// One progress stream's position. Owned by the content provider (shared with its releaser).
struct HttpServer::Stream {
  std::shared_ptr<Job> job;
  std::int64_t cursor = 0;  // the last seq sent
  bool ndjson = false;
  std::chrono::steady_clock::time_point last_write;
};

HttpServer::HttpServer(HttpSettings settings, JobQueue& queue, JobStore& store, Metrics& metrics)
    : settings_(std::move(settings)), queue_(queue), store_(store), metrics_(metrics) {
  const std::size_t threads =
      static_cast<std::size_t>(settings_.http_threads > 0 ? settings_.http_threads : settings_.max_streams + 32);
  // httplib's default pool has 8 threads and every open stream holds one: size it so that the capped number of
  // streams never starves /healthz and the API.
  server_.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  server_.set_tcp_nodelay(true);  // responses and stream chunks go out at once (no Nagle / delayed-ACK stalls)
  server_.set_keep_alive_max_count(100);
  server_.set_keep_alive_timeout(2);  // an idle keep-alive connection holds a pool thread (and delays stop())
  server_.set_read_timeout(10, 0);
  server_.set_write_timeout(5, 0);  // a client that stops reading loses its stream after this long
  server_.set_payload_max_length(settings_.max_request_bytes);  // Content-Length bodies: read and dropped, 413
  server_.set_pre_routing_handler([this](const Request& req, Response& res) { return pre_route(req, res); });
  server_.set_expect_100_continue_handler(
      [this](const Request& req, Response& res) { return expect_continue(req, res); });
  server_.set_error_handler(
      httplib::Server::HandlerWithResponse([this](const Request& req, Response& res) { return on_error(req, res); }));
  server_.set_exception_handler(
      [this](const Request& req, Response& res, std::exception_ptr error) { on_exception(req, res, error); });
  server_.set_logger([this](const Request& req, const Response& res) { on_response(req, res); });
  register_routes();
}

// ------------------------------------------------------------------------------------------------ routes
void HttpServer::add_route(const std::string& method, const std::string& pattern) {
  routes_.push_back({method, std::regex(pattern)});
}

void HttpServer::register_routes() {
  const std::string job = R"(/v1/jobs/([^/]+))";
  auto get = [this](const std::string& pattern, void (HttpServer::*handler)(const Request&, Response&)) {
    add_route("GET", pattern);
    server_.Get(pattern, [this, handler](const Request& req, Response& res) { (this->*handler)(req, res); });
  };
  get("/", &HttpServer::handle_root);
  get("/healthz", &HttpServer::handle_healthz);
  get("/readyz", &HttpServer::handle_readyz);
  get("/metrics", &HttpServer::handle_metrics);
  get(R"(/problems/([a-z-]+))", &HttpServer::handle_problem_type);
  get("/v1/schema", &HttpServer::handle_schema);
  get(R"(/v1/job\.schema\.json)", &HttpServer::handle_schema);  // so that openapi.yaml's "./job.schema.json" resolves
  get(R"(/v1/openapi\.yaml)", &HttpServer::handle_openapi);
  get("/v1/jobs", &HttpServer::handle_list);
  get(job, &HttpServer::handle_get);
  get(job + "/events", &HttpServer::handle_events);
  add_route("GET", job + "/result");
  server_.Get(job + "/result", [this](const Request& req, Response& res) { handle_result(req, res, false); });
  add_route("GET", job + R"(/result\.xmf)");
  server_.Get(job + R"(/result\.xmf)", [this](const Request& req, Response& res) { handle_result(req, res, true); });

  add_route("POST", "/v1/jobs");
  server_.Post("/v1/jobs", [this](const Request& req, Response& res, const ContentReader& reader) {
    handle_submit(req, res, reader);
  });
  add_route("POST", "/v1/validate");
  server_.Post("/v1/validate", [this](const Request& req, Response& res, const ContentReader& reader) {
    handle_validate(req, res, reader);
  });
  add_route("POST", job + "/cancel");
  cancel_route_ = std::regex(job + "/cancel");
  server_.Post(job + "/cancel", [this](const Request& req, Response& res) { handle_cancel(req, res); });
  add_route("DELETE", job);
  server_.Delete(job, [this](const Request& req, Response& res) { handle_delete(req, res); });
}

int HttpServer::bind() {
  if (settings_.port == 0) return server_.bind_to_any_port(settings_.host);
  return server_.bind_to_port(settings_.host, settings_.port) ? settings_.port : -1;
}

void HttpServer::listen() { server_.listen_after_bind(); }

void HttpServer::wait_for_streams(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (streams_.load() > 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

// ------------------------------------------------------------------------------------------------ middleware
bool HttpServer::authorized(const Request& req) const {
  if (settings_.token.empty()) return true;
  const std::string header = req.get_header_value("Authorization");
  static const std::string scheme = "bearer ";
  if (header.size() <= scheme.size() || lower(header.substr(0, scheme.size())) != scheme) return false;
  return constant_time_equal(trim(header.substr(scheme.size())), settings_.token);
}

Handled HttpServer::pre_route(const Request& req, Response& res) {
  const bool api = req.path == "/v1" || req.path.rfind("/v1/", 0) == 0;
  // A request refused here has not had its body read: close the connection after answering, so that the
  // unread bytes are never taken for the next request.
  auto refuse = [&](int status, const std::string& slug, const std::string& detail) {
    send_problem(res, status, slug, detail, req.path);
    if (has_body(req)) res.set_header("Connection", "close");
    return Handled::Handled;
  };
  if (api && !authorized(req)) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"contactd\"");
    return refuse(401, "",
                  req.has_header("Authorization") ? "the bearer token is not valid"
                                                  : "this server requires 'Authorization: Bearer <token>'");
  }
  if (req.has_header("Content-Encoding") && lower(trim(req.get_header_value("Content-Encoding"))) != "identity")
    return refuse(415, "",
                  "Content-Encoding '" + req.get_header_value("Content-Encoding") +
                      "' is not accepted: send the body uncompressed");
  if (req.has_header("Content-Length")) {
    std::uint64_t length = 0;
    if (!parse_count(req.get_header_value("Content-Length"), UINT64_MAX / 2, length))
      return refuse(400, "invalid-request", "the Content-Length header is not a number");
    // Up to a few times the limit the body is read and dropped by httplib (set_payload_max_length), which keeps
    // the connection usable and lets every client read the 413; far beyond, it is refused unread.
    if (length > 4 * static_cast<std::uint64_t>(settings_.max_request_bytes) + (1u << 20))
      return refuse(413, "",
                    "the body has " + std::to_string(length) + " bytes; the limit is " +
                        std::to_string(settings_.max_request_bytes));
  }
  if (api && !ready_) return (res.set_header("Retry-After", "1"), refuse(503, "not-ready", "the server is starting"));
  // Unknown paths (404) and methods (405) are answered here, before httplib reads a body for them.
  const std::string method = req.method == "HEAD" ? std::string("GET") : req.method;
  if (std::none_of(routes_.begin(), routes_.end(), [&](const Route& route) {
        return route.method == method && std::regex_match(req.path, route.pattern);
      })) {
    method_not_allowed_or_not_found(req, res);
    if (has_body(req)) res.set_header("Connection", "close");
    return Handled::Handled;
  }
  // A POST without Content-Length or chunked encoding: httplib would read until the client closes. A body-less
  // cancel is fine (curl -X POST); routes that need a body say so (411).
  if (req.method == "POST" && !req.has_header("Content-Length") && !req.has_header("Transfer-Encoding")) {
    if (std::regex_match(req.path, cancel_route_)) {
      handle_cancel(req, res);
      return Handled::Handled;
    }
    return refuse(411, "", "send the job with a Content-Length (or chunked transfer encoding)");
  }
  return Handled::Unhandled;
}

int HttpServer::expect_continue(const Request& req, Response& res) {
  // "Expect: 100-continue" (curl sends it for large bodies): refuse before the body is sent.
  const bool api = req.path == "/v1" || req.path.rfind("/v1/", 0) == 0;
  if (api && !authorized(req)) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"contactd\"");
    send_problem(res, 401, "", "this server requires 'Authorization: Bearer <token>'", req.path);
    return 401;
  }
  std::uint64_t length = 0;
  if (req.has_header("Content-Length") && parse_count(req.get_header_value("Content-Length"), UINT64_MAX / 2, length) &&
      length > settings_.max_request_bytes) {
    send_problem(res, 413, "",
                 "the body has " + std::to_string(length) + " bytes; the limit is " +
                     std::to_string(settings_.max_request_bytes),
                 req.path);
    return 413;
  }
  return 100;
}

void HttpServer::method_not_allowed_or_not_found(const Request& req, Response& res) {
  std::vector<std::string> allowed;
  for (const auto& route : routes_)
    if (std::regex_match(req.path, route.pattern) &&
        std::find(allowed.begin(), allowed.end(), route.method) == allowed.end())
      allowed.push_back(route.method);
  if (allowed.empty()) {
    send_problem(res, 404, "", "no such resource: " + req.path, req.path);
    return;
  }
  std::string allow;
  for (const auto& m : allowed) allow += (allow.empty() ? "" : ", ") + m + (m == "GET" ? ", HEAD" : "");
  res.set_header("Allow", allow);
  send_problem(res, 405, "", "method " + req.method + " is not allowed here; allowed: " + allow, req.path);
}

Handled HttpServer::on_error(const Request& req, Response& res) {
  if (!res.body.empty()) return Handled::Unhandled;  // a handler's own problem document
  switch (res.status) {
    case 404:
      method_not_allowed_or_not_found(req, res);
      break;
    case 413:
      send_problem(res, 413, "",
                   "the body is larger than the limit of " + std::to_string(settings_.max_request_bytes) + " bytes",
                   req.path);
      break;
    case 400:
      send_problem(res, 400, "", "the request could not be read (malformed HTTP, body or encoding)", req.path);
      break;
    default:
      send_problem(res, res.status, "", reason_phrase(res.status), req.path);
  }
  return Handled::Handled;
}

void HttpServer::on_exception(const Request& req, Response& res, std::exception_ptr error) {
  std::string what = "unknown exception";
  try {
    if (error) std::rethrow_exception(error);
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
  }
  log_line("internal error in " + req.method + " " + req.path + ": " + what);
  send_problem(res, 500, "", "internal error; the server's log has the details", req.path);
}

void HttpServer::on_response(const Request& req, const Response& res) {
  metrics_.http_response(res.status);
  if (settings_.access_log)
    log_line(req.remote_addr + " " + req.method + " " + req.path + " " + std::to_string(res.status));
}

// ------------------------------------------------------------------------------------------------ helpers
bool HttpServer::read_json_body(const Request& req, Response& res, const ContentReader& reader, std::string& body) {
  bool too_large = false;
  const bool read = reader([&](const char* data, std::size_t length) {
    if (body.size() + length > settings_.max_request_bytes) {  // chunked bodies have no Content-Length to check
      too_large = true;
      return false;
    }
    body.append(data, length);
    return true;
  });
  if (too_large || res.status == 413) {
    if (too_large) res.set_header("Connection", "close");  // the rest of the chunked body is still unread
    send_problem(res, 413, "",
                 "the body is larger than the limit of " + std::to_string(settings_.max_request_bytes) + " bytes",
                 req.path);
    return false;
  }
  if (!read) {
    res.set_header("Connection", "close");
    send_problem(res, 400, "", "the request body could not be read", req.path);
    return false;
  }
  const std::string type = media_type(req.get_header_value("Content-Type"));
  if (type != "application/json") {
    send_problem(res, 415, "",
                 "the body must be a job as JSON with 'Content-Type: application/json'" +
                     (type.empty() ? std::string(" (none given)") : " (got '" + type + "')"),
                 req.path);
    return false;
  }
  return true;
}

std::shared_ptr<Job> HttpServer::find_job(const Request& req, Response& res) {
  const std::string id = req.matches.size() > 1 ? std::string(req.matches[1]) : std::string();
  std::shared_ptr<Job> job = is_job_id(id) ? queue_.find(id) : nullptr;  // anything else never reaches the disk
  if (!job) send_problem(res, 404, "", "no job with id '" + id + "'", req.path);
  return job;
}

nlohmann::json HttpServer::job_resource(const JobRecord& r, int queue_position) const {
  const std::int64_t now = now_unix_us();
  auto time_or_null = [](std::int64_t us) { return us > 0 ? nlohmann::json(iso8601_us(us)) : nlohmann::json(nullptr); };
  const std::int64_t queued_until = r.started_us > 0 ? r.started_us : (r.finished_us > 0 ? r.finished_us : now);
  nlohmann::json timings = {
      {"queued_seconds", static_cast<double>(queued_until - r.created_us) * 1e-6},
      {"run_seconds",
       r.started_us > 0 ? static_cast<double>((r.finished_us > 0 ? r.finished_us : now) - r.started_us) * 1e-6 : 0.0},
      {"solve_seconds", r.solve_seconds}};
  const std::string self = job_link(r.id);
  nlohmann::json links = {{"self", self}, {"events", self + "/events"}, {"cancel", self + "/cancel"}};
  if (r.result_available) {
    links["result"] = self + "/result";
    links["result_xmf"] = self + "/result.xmf";
  }
  const bool done = is_terminal(r.state);
  nlohmann::json j = {{"id", r.id},
                      {"name", r.name},
                      {"state", to_string(r.state)},
                      {"done", done},
                      {"created", iso8601_us(r.created_us)},
                      {"started", time_or_null(r.started_us)},
                      {"finished", time_or_null(r.finished_us)},
                      {"attempts", r.attempts},
                      {"iterations", r.iterations},
                      {"progress", r.progress},
                      {"timings", timings},
                      {"result_available", r.result_available},
                      {"links", links}};
  j["queue_position"] =
      r.state == JobState::queued && queue_position > 0 ? nlohmann::json(queue_position) : nlohmann::json(nullptr);
  j["stop_reason"] = done ? nlohmann::json(r.stop_reason) : nlohmann::json(nullptr);
  j["converged"] =
      done && r.converged ? nlohmann::json(*r.converged) : (done ? nlohmann::json(false) : nlohmann::json(nullptr));
  j["message"] = r.message.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.message);
  j["error"] = r.state == JobState::failed ? nlohmann::json({{"reason", r.stop_reason}, {"message", r.message}})
                                           : nlohmann::json(nullptr);
  j["idempotency_key"] = r.idempotency_key.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.idempotency_key);
  return j;
}

// ------------------------------------------------------------------------------------------------ handlers
void HttpServer::handle_root(const Request&, Response& res) {
  send_json(res, 200,
            {{"service", "contactd"},
             {"version", contact::solver_version()},
             {"links",
              {{"jobs", "/v1/jobs"},
               {"validate", "/v1/validate"},
               {"schema", "/v1/schema"},
               {"openapi", "/v1/openapi.yaml"},
               {"health", "/healthz"},
               {"ready", "/readyz"},
               {"metrics", "/metrics"}}}});
}

void HttpServer::handle_healthz(const Request&, Response& res) {
  const double uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  send_json(res, 200, {{"status", "ok"}, {"uptime_seconds", uptime}});
}

void HttpServer::handle_readyz(const Request&, Response& res) {
  const bool writable = store_.writable();
  const int alive = queue_.workers_alive();
  const bool ready = ready_ && !stopping_ && writable && alive == queue_.workers();
  std::string status = ready ? "ready" : (!ready_ ? "starting" : (stopping_ ? "stopping" : "degraded"));
  nlohmann::json body = {
      {"status", status}, {"data_dir_writable", writable}, {"workers", queue_.workers()}, {"workers_alive", alive}};
  if (!ready) res.set_header("Retry-After", "1");
  send_json(res, ready ? 200 : 503, body);
}

void HttpServer::handle_metrics(const Request&, Response& res) {
  res.status = 200;
  res.set_content(metrics_.render(queue_.counts(), queue_.workers_busy(), queue_.workers()),
                  "text/plain; version=0.0.4; charset=utf-8");
}

void HttpServer::handle_problem_type(const Request& req, Response& res) {
  const std::string slug = req.matches[1];
  for (const auto& t : kProblemTypes)
    if (slug == t.slug) {
      res.status = 200;
      res.set_content(std::string(t.title) + "\n\n" + t.description + "\n", "text/plain; charset=utf-8");
      return;
    }
  send_problem(res, 404, "", "no problem type '" + slug + "'", req.path);
}

void HttpServer::handle_schema(const Request&, Response& res) {
  res.status = 200;
  res.set_content(std::string(assets::job_schema()), "application/schema+json");
}

void HttpServer::handle_openapi(const Request&, Response& res) {
  res.status = 200;
  res.set_content(std::string(assets::openapi_yaml()), "application/yaml");
}

void HttpServer::handle_submit(const Request& req, Response& res, const ContentReader& reader) {
  std::string body;
  if (!read_json_body(req, res, reader, body)) return;
  const std::string key = req.get_header_value("Idempotency-Key");
  if (req.has_header("Idempotency-Key") &&
      (key.empty() || key.size() > 255 ||
       !std::all_of(key.begin(), key.end(), [](unsigned char c) { return c >= 0x20 && c < 0x7f; }))) {
    send_problem(res, 400, "invalid-request", "Idempotency-Key must be 1 to 255 printable ASCII characters", req.path);
    return;
  }
  if (stopping_) {
    res.set_header("Retry-After", "5");
    send_problem(res, 503, "not-ready", "the server is shutting down and accepts no new jobs", req.path);
    return;
  }
  using Outcome = JobQueue::Submission::Outcome;
  const auto s = queue_.submit(body, key);
  switch (s.outcome) {
    case Outcome::accepted:
    case Outcome::replayed: {
      int position = 0;
      const JobRecord record = queue_.snapshot(*s.job, &position);
      res.set_header("Location", job_link(record.id));
      if (s.outcome == Outcome::replayed) res.set_header("Idempotent-Replayed", "true");
      send_json(res, 202, job_resource(record, position));
      return;
    }
    case Outcome::invalid: {
      nlohmann::json errors = nlohmann::json::array();
      for (const auto& e : s.errors) errors.push_back({{"pointer", e.pointer}, {"message", e.message}});
      send_problem(res, 400, "invalid-job",
                   std::to_string(s.errors.size()) + (s.errors.size() == 1 ? " error" : " errors") +
                       " in the job; each is listed with its JSON pointer",
                   req.path, {{"errors", errors}});
      return;
    }
    case Outcome::key_conflict:
      send_problem(res, 422, "idempotency-key-reused",
                   "Idempotency-Key '" + key + "' was used for job " + s.job->record.id + " with a different body",
                   req.path, {{"job", job_link(s.job->record.id)}});
      return;
    case Outcome::queue_full:
      res.set_header("Retry-After", "5");
      send_problem(res, 503, "queue-full", "the queue is full; retry later", req.path);
      return;
    case Outcome::unavailable:
      res.set_header("Retry-After", "5");
      send_problem(res, 503, "not-ready", "the server is shutting down and accepts no new jobs", req.path);
      return;
    case Outcome::store_error:
      send_problem(res, 500, "store-error", s.detail, req.path);
      return;
  }
}

void HttpServer::handle_validate(const Request& req, Response& res, const ContentReader& reader) {
  std::string body;
  if (!read_json_body(req, res, reader, body)) return;
  const auto parsed = queue_.validate(body);
  if (!parsed.ok()) {
    nlohmann::json errors = nlohmann::json::array();
    for (const auto& e : parsed.errors) errors.push_back({{"pointer", e.pointer}, {"message", e.message}});
    send_problem(res, 400, "invalid-job",
                 std::to_string(parsed.errors.size()) + (parsed.errors.size() == 1 ? " error" : " errors") +
                     " in the job; each is listed with its JSON pointer",
                 req.path, {{"errors", errors}});
    return;
  }
  const contact::Problem& p = *parsed.problem;
  long dofs = 0;
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& b : p.bodies) {
    dofs += 2L * b.mesh.num_nodes();
    bodies.push_back({{"name", b.name}, {"elements", b.mesh.num_cells()}, {"nodes", b.mesh.num_nodes()}});
  }
  send_json(res, 200,
            {{"valid", true},
             {"name", p.name},
             {"bodies", bodies},
             {"contacts", p.contacts.size()},
             {"dofs", dofs},
             {"normalized", p.normalized}});
}

void HttpServer::handle_list(const Request& req, Response& res) {
  std::optional<JobState> state;
  if (req.has_param("state")) {
    state = job_state_from_string(req.get_param_value("state"));
    if (!state) {
      send_problem(res, 400, "invalid-request", "state must be one of QUEUED, RUNNING, SUCCEEDED, FAILED, CANCELLED",
                   req.path);
      return;
    }
  }
  std::uint64_t page_size = 50;
  if (req.has_param("page_size")) {
    if (!parse_count(req.get_param_value("page_size"), UINT32_MAX, page_size) || page_size == 0) {
      send_problem(res, 400, "invalid-request", "page_size must be a positive integer (at most 500 are returned)",
                   req.path);
      return;
    }
    page_size = std::min<std::uint64_t>(page_size, 500);  // AIP-158: larger values are coerced to the maximum
  }
  std::optional<JobQueue::Cursor> after;
  if (req.has_param("page_token") && !req.get_param_value("page_token").empty()) {
    JobQueue::Cursor cursor;
    if (!decode_cursor(req.get_param_value("page_token"), cursor)) {
      send_problem(res, 400, "invalid-request", "page_token is not a token this server issued", req.path);
      return;
    }
    after = cursor;
  }
  const auto page = queue_.list(state, static_cast<std::size_t>(page_size), after);
  nlohmann::json jobs = nlohmann::json::array();
  for (const auto& record : page.jobs) jobs.push_back(job_resource(record, 0));
  send_json(res, 200, {{"jobs", jobs}, {"next_page_token", page.next ? encode_cursor(*page.next) : std::string()}});
}

void HttpServer::handle_get(const Request& req, Response& res) {
  const auto job = find_job(req, res);
  if (!job) return;
  int position = 0;
  const JobRecord record = queue_.snapshot(*job, &position);
  send_json(res, 200, job_resource(record, position));
}

void HttpServer::handle_delete(const Request& req, Response& res) {
  const auto job = find_job(req, res);
  if (!job) return;
  std::string detail;
  switch (queue_.remove(job->record.id, detail)) {
    case JobQueue::RemoveOutcome::removed:
      res.status = 204;
      return;
    case JobQueue::RemoveOutcome::not_found:
      send_problem(res, 404, "", "no job with id '" + job->record.id + "'", req.path);
      return;
    case JobQueue::RemoveOutcome::not_done: {
      const JobRecord record = queue_.snapshot(*job);
      send_problem(res, 409, "job-not-finished", "cancel the job first, then delete it when it has ended", req.path,
                   {{"state", to_string(record.state)}});
      return;
    }
    case JobQueue::RemoveOutcome::store_error:
      send_problem(res, 500, "store-error", detail, req.path);
      return;
  }
}

void HttpServer::handle_cancel(const Request& req, Response& res) {
  std::smatch match;
  // Called from the pre-routing handler too (a POST without a body), where req.matches is not set.
  std::string id;
  if (std::regex_match(req.path, match, cancel_route_)) id = match[1];
  std::shared_ptr<Job> job = is_job_id(id) ? queue_.find(id) : nullptr;
  if (!job) {
    send_problem(res, 404, "", "no job with id '" + id + "'", req.path);
    return;
  }
  const auto outcome = queue_.cancel(id);
  int position = 0;
  const JobRecord record = queue_.snapshot(*job, &position);
  switch (outcome) {
    case JobQueue::CancelOutcome::cancelled:
    case JobQueue::CancelOutcome::cancelling:
    case JobQueue::CancelOutcome::already_cancelled:
      res.set_header("Location", job_link(id));
      send_json(res, 202, job_resource(record, position));
      return;
    case JobQueue::CancelOutcome::already_done:
      send_problem(res, 409, "job-finished", "the job has already finished", req.path,
                   {{"state", to_string(record.state)}});
      return;
    case JobQueue::CancelOutcome::not_found:
      send_problem(res, 404, "", "no job with id '" + id + "'", req.path);
      return;
  }
}

void HttpServer::handle_result(const Request& req, Response& res, bool sidecar) {
  const auto job = find_job(req, res);
  if (!job) return;
  const JobRecord record = queue_.snapshot(*job);
  if (!is_terminal(record.state)) {
    send_problem(res, 409, "job-not-finished",
                 "the job is " + std::string(to_string(record.state)) + "; the result exists once it has ended",
                 req.path, {{"state", to_string(record.state)}});
    return;
  }
  if (!record.result_available) {
    send_problem(
        res, 404, "no-result",
        "the job ended " + std::string(to_string(record.state)) + " (" + record.stop_reason + ") without a result file",
        req.path, {{"state", to_string(record.state)}});
    return;
  }
  const std::string path = sidecar ? store_.xmf_path(record.id) : store_.result_path(record.id);
  // The descriptor keeps the file readable even if the job is deleted while it is being sent.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0) {
    if (fd >= 0) ::close(fd);
    send_problem(res, 404, "no-result", "the result file is gone", req.path);
    return;
  }
  char etag[96];
  std::snprintf(etag, sizeof etag, "\"%s-%llx-%llx\"", record.id.substr(0, 8).c_str(),
                static_cast<unsigned long long>(st.st_size),
                static_cast<unsigned long long>(st.st_mtim.tv_sec) * 1000000000ull +
                    static_cast<unsigned long long>(st.st_mtim.tv_nsec));
  res.set_header("ETag", etag);
  res.set_header("Cache-Control", "private, max-age=0, must-revalidate");
  res.set_header("Content-Disposition",
                 sidecar ? "attachment; filename=\"result.xmf\"" : "attachment; filename=\"result.hdf\"");
  const std::string if_none_match = req.get_header_value("If-None-Match");
  if (!if_none_match.empty() && (if_none_match == etag || if_none_match == "*")) {
    ::close(fd);
    res.status = 304;
    return;
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  auto descriptor = std::make_shared<int>(fd);
  res.status = 200;
  res.set_content_provider(
      size, sidecar ? "application/xml; charset=utf-8" : "application/x-hdf5",
      [descriptor](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        char buffer[1 << 16];
        const std::size_t want = std::min(length, sizeof buffer);
        ssize_t n;
        do {
          n = ::pread(*descriptor, buffer, want, static_cast<off_t>(offset));
        } while (n < 0 && errno == EINTR);
        if (n <= 0) return false;
        return sink.write(buffer, static_cast<std::size_t>(n));
      },
      [descriptor](bool) { ::close(*descriptor); });
}

void HttpServer::handle_events(const Request& req, Response& res) {
  const auto job = find_job(req, res);
  if (!job) return;
  std::string resume = req.get_header_value("Last-Event-ID");
  if (resume.empty() && req.has_param("last_event_id")) resume = req.get_param_value("last_event_id");
  std::uint64_t after = 0;
  if (!resume.empty() && !parse_count(trim(resume), 1ull << 53, after)) {
    send_problem(res, 400, "invalid-request", "Last-Event-ID must be an event's seq (a non-negative integer)",
                 req.path);
    return;
  }
  if (streams_.fetch_add(1) >= settings_.max_streams) {
    --streams_;
    res.set_header("Retry-After", "5");
    send_problem(res, 503, "too-many-streams",
                 "the server already serves " + std::to_string(settings_.max_streams) + " progress streams", req.path);
    return;
  }
  metrics_.stream_opened();
  auto stream = std::make_shared<Stream>();
  stream->job = job;
  // An id beyond the last event (from a log cut short by a crash) resumes at the end.
  stream->cursor = std::min<std::int64_t>(static_cast<std::int64_t>(after), job->events.last_seq());
  stream->ndjson = req.get_header_value("Accept").find("application/x-ndjson") != std::string::npos;
  stream->last_write = std::chrono::steady_clock::now();
  res.status = 200;
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");  // proxies: do not buffer the stream
  res.set_chunked_content_provider(
      stream->ndjson ? "application/x-ndjson" : "text/event-stream",
      [this, stream](std::size_t, httplib::DataSink& sink) { return pump_stream(*stream, sink); },
      [this](bool) {
        --streams_;
        metrics_.stream_closed();
      });
}

// Called by httplib again and again on the connection's thread until it returns false (client gone) or calls
// sink.done(). Sends what is new; otherwise waits for the job's next event for at most a second, so that
// shutdown and heartbeats are never late; never blocks the worker appending events.
bool HttpServer::pump_stream(Stream& stream, httplib::DataSink& sink) {
  const auto events = stream.job->events.read_after(stream.cursor, 256);
  if (!events.empty()) {
    std::string out;
    bool ended = false;
    for (const auto& e : events) {
      out += stream.ndjson ? e.json + "\n" : format_sse(e);
      stream.cursor = e.seq;
      if (e.type == "end") {
        ended = true;
        break;
      }
    }
    if (!sink.write(out.data(), out.size())) return false;
    stream.last_write = std::chrono::steady_clock::now();
    if (ended) sink.done();
    return true;
  }
  // Nothing new. Finished (a log without `end` after a crash is repaired at start-up), deleted, or shutting down:
  // close the stream.
  if (stream.job->events.discarded() ||
      (stream.job->settled.load() && stream.cursor >= stream.job->events.last_seq())) {
    sink.done();
    return true;
  }
  if (closing_streams_) {
    if (!stream.ndjson) {
      static const std::string bye = ": the server is shutting down; reconnect with Last-Event-ID to resume\n\n";
      sink.write(bye.data(), bye.size());
    }
    sink.done();
    return true;
  }
  const auto now = std::chrono::steady_clock::now();
  const auto heartbeat = std::chrono::seconds(settings_.heartbeat_seconds);
  if (now - stream.last_write >= heartbeat) {
    // Also how a vanished client is noticed: the write fails.
    static const std::string sse_beat = ": heartbeat\n\n", ndjson_beat = "\n";
    const std::string& beat = stream.ndjson ? ndjson_beat : sse_beat;
    if (!sink.write(beat.data(), beat.size())) return false;
    stream.last_write = now;
    return true;
  }
  const auto until_beat = std::chrono::duration_cast<std::chrono::milliseconds>(heartbeat - (now - stream.last_write));
  stream.job->events.wait_after(stream.cursor,
                                std::min(until_beat, std::chrono::milliseconds(1000)) + std::chrono::milliseconds(1));
  return true;
}

}  // namespace contactd

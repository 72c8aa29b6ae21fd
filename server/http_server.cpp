#include "http_server.hpp"

#include "common/encoding.hpp"
#include "common/log.hpp"
#include "http/problem_document.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <thread>

namespace contactd {

namespace {

using Handled = httplib::Server::HandlerResponse;

// "8 MiB", "12.5 MiB": a byte count for people.
std::string format_mib(std::uint64_t bytes) {
  std::ostringstream os;
  os << std::setprecision(4) << static_cast<double>(bytes) / 1048576.0 << " MiB";
  return os.str();
}

std::chrono::milliseconds millis(double seconds) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(seconds * 1000.0));
}

TransportSettings transport_settings(const HttpSettings& s) {
  TransportSettings t;
  t.gate.head.max_head_bytes = s.max_header_bytes;
  t.gate.head.max_header_fields = s.max_header_fields;
  t.gate.backlog = s.listen_backlog;
  t.gate.max_connections = s.max_connections;
  t.gate.max_connections_per_client = s.max_connections_per_client;
  t.gate.head_timeout = millis(s.head_timeout_seconds);
  t.gate.idle_timeout = millis(s.idle_timeout_seconds);
  // Every open stream holds a thread: sized so that the capped number of streams never starves the API.
  t.threads = static_cast<std::size_t>(s.http_threads > 0 ? s.http_threads : s.max_streams + 32);
  t.body_timeout = millis(s.body_timeout_seconds);
  return t;
}

GuardSettings guard_settings(const HttpSettings& s) {
  GuardSettings g;
  if (!s.allowed_hosts.empty()) {
    g.allowed_hosts = s.allowed_hosts;
  } else if (s.host != "0.0.0.0" && s.host != "::" && s.host != "") {
    // The address listened on is a name clients use too (unless it is a wildcard).
    const std::string host = s.host.find(':') != std::string::npos ? "[" + s.host + "]" : s.host;
    if (std::find(g.allowed_hosts.begin(), g.allowed_hosts.end(), lower(host)) == g.allowed_hosts.end())
      g.allowed_hosts.push_back(lower(host));
  }
  g.token_required = !s.token.empty();
  return g;
}

}  // namespace

HttpServer::HttpServer(HttpSettings settings, JobQueue& queue, JobStore& store, Metrics& metrics, BodyBudget& budget)
    : settings_(std::move(settings)),
      guard_(guard_settings(settings_)),
      metrics_(metrics),
      context_{settings_,
               queue,
               store,
               metrics,
               budget,
               state_,
               [this] { return transport_->open_connections(); },
               [this](Response& res, const std::string& path, std::optional<std::uint64_t> bytes) {
                 send_too_large(res, path, bytes);
               }} {
  // Every answer says its Content-Type is to be believed (a JSON error document or a result file is never to be
  // sniffed into something a browser would run).
  core_.set_default_headers({{"X-Content-Type-Options", "nosniff"}});
  core_.set_tcp_nodelay(true);
  core_.set_keep_alive_max_count(100);
  core_.set_keep_alive_timeout(static_cast<time_t>(std::max(1.0, settings_.idle_timeout_seconds)));
  core_.set_payload_max_length(settings_.max_request_bytes);  // Content-Length bodies: read and dropped, 413
  core_.set_pre_routing_handler([this](const Request& req, Response& res) { return pre_route(req, res); });
  core_.set_expect_100_continue_handler(
      [this](const Request& req, Response& res) { return expect_continue(req, res); });
  core_.set_error_handler(
      httplib::Server::HandlerWithResponse([this](const Request& req, Response& res) { return on_error(req, res); }));
  core_.set_exception_handler(
      [this](const Request& req, Response& res, std::exception_ptr error) { on_exception(req, res, error); });
  core_.set_logger([this](const Request& req, const Response& res) { on_response(req, res); });
  // Just before a response goes out: a response to a request whose body may be unread (an error) closes the
  // connection, so that those bytes are never taken for the next request.
  core_.set_post_routing_handler([](const Request& req, Response& res) {
    Exchange* exchange = current_exchange();
    if (!exchange) return;
    if (res.get_header_value("Connection") == "close" || (has_body(req) && res.status >= 400)) {
      exchange->close_after = true;
      res.headers.erase("Connection");
      res.headers.erase("Keep-Alive");
      res.set_header("Connection", "close");
    }
  });
  transport_ = std::make_unique<Transport>(
      transport_settings(settings_), core_,
      // Range requests are served by handle_result itself (httplib's own handling answers 200 to bytes=0-0 and
      // overflows on a range past the end).
      [](Request& req) { req.ranges.clear(); }, [this](int status) { metrics_.http_response(status); });
  register_web_routes(router_, context_);
  register_service_routes(router_, context_);
  register_job_routes(router_, context_);
  register_stream_routes(router_, context_);
}

HttpServer::~HttpServer() { transport_->stop(); }

int HttpServer::bind(std::string& error) { return transport_->bind(settings_.host, settings_.port, error); }

void HttpServer::listen() { transport_->run(); }

void HttpServer::wait_for_streams(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (state_.streams.load() > 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

// ------------------------------------------------------------------------------------------------ middleware
bool RouteContext::authorized(const Request& req) const {
  if (settings.token.empty()) return true;
  const std::string header = req.get_header_value("Authorization");
  static const std::string scheme = "bearer ";
  if (header.size() <= scheme.size() || lower(header.substr(0, scheme.size())) != scheme) return false;
  // A control character (a NUL and garbage after the token) is never part of a valid header value.
  if (std::any_of(header.begin(), header.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; })) return false;
  return constant_time_equal(trim(header.substr(scheme.size())), settings.token);
}

Handled HttpServer::pre_route(const Request& req, Response& res) {
  const bool api = req.path == "/v1" || req.path.rfind("/v1/", 0) == 0;
  // A request refused here has not had its body read: the connection closes after the answer (the post-routing
  // handler sees to it), so that the unread bytes are never taken for the next request.
  auto refuse = [&](int status, const std::string& slug, const std::string& detail) {
    send_problem(res, status, slug, detail, req.path);
    if (has_body(req)) res.set_header("Connection", "close");
    return Handled::Handled;
  };
  if (auto r = check_framing(req)) return refuse(r->status, r->slug, r->detail);
  // Probes are exempt from the Host allow-list: an orchestrator probes by address (a pod's IP), and they tell a
  // page of another site nothing it could use.
  const bool probe = req.path == "/healthz" || req.path == "/readyz";
  if (!probe)
    if (auto r = check_host(req, guard_)) return refuse(r->status, r->slug, r->detail);
  if (api && !context_.authorized(req)) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"contactd\"");
    return refuse(401, "",
                  req.has_header("Authorization") ? "the bearer token is not valid"
                                                  : "this server requires 'Authorization: Bearer <token>'");
  }
  if (auto r = check_cross_site(req, guard_)) return refuse(r->status, r->slug, r->detail);
  if (req.has_header("Content-Encoding") && lower(trim(req.get_header_value("Content-Encoding"))) != "identity")
    return refuse(415, "",
                  "Content-Encoding '" + clip(req.get_header_value("Content-Encoding"), 64) +
                      "' is not accepted: send the body uncompressed");
  if (req.has_header("Content-Length")) {
    std::uint64_t length = 0;
    parse_count(trim(req.get_header_value("Content-Length")), UINT64_MAX / 2, length);  // checked by check_framing
    // Up to a few times the limit the body is read and dropped by httplib (set_payload_max_length), which keeps
    // the connection usable and lets every client read the 413; far beyond, it is refused unread.
    if (length > 4 * static_cast<std::uint64_t>(settings_.max_request_bytes) + (1u << 20))
      return (send_too_large(res, req.path, length), res.set_header("Connection", "close"), Handled::Handled);
  }
  if (api && !state_.ready)
    return (res.set_header("Retry-After", "1"), refuse(503, "not-ready", "the server is starting"));
  // Unknown paths (404) and methods (405) are answered here, before httplib reads a body for them.
  const std::string method = req.method == "HEAD" ? std::string("GET") : req.method;
  if (!router_.known(method, req.path)) {
    method_not_allowed_or_not_found(req, res);
    if (has_body(req)) res.set_header("Connection", "close");
    return Handled::Handled;
  }
  // Every body this API reads is JSON: anything else (multipart/form-data included) is 415 before httplib parses it.
  if (req.method == "POST" && has_body(req)) {
    const std::string type = media_type(req.get_header_value("Content-Type"));
    if (type != "application/json")
      return refuse(415, "",
                    "the body must be JSON with 'Content-Type: application/json'" +
                        (type.empty() ? std::string(" (none given)") : " (got '" + clip(type, 64) + "')"));
  }
  // A POST without Content-Length or chunked encoding: httplib would read until the client closes. A body-less
  // cancel is fine (curl -X POST); routes that need a body say so (411).
  if (req.method == "POST" && !req.has_header("Content-Length") && !req.has_header("Transfer-Encoding")) {
    if (is_cancel_path(req.path)) {
      handle_cancel(context_, req, res);
      return Handled::Handled;
    }
    return refuse(411, "", "send the job with a Content-Length (or chunked transfer encoding)");
  }
  return Handled::Unhandled;
}

int HttpServer::expect_continue(const Request& req, Response& res) {
  // "Expect: 100-continue" (curl sends it for large bodies): refuse before the body is sent.
  const bool api = req.path == "/v1" || req.path.rfind("/v1/", 0) == 0;
  if (api && !context_.authorized(req)) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"contactd\"");
    send_problem(res, 401, "", "this server requires 'Authorization: Bearer <token>'", req.path);
    return 401;
  }
  std::uint64_t length = 0;
  if (req.has_header("Content-Length") && parse_count(req.get_header_value("Content-Length"), UINT64_MAX / 2, length) &&
      length > settings_.max_request_bytes) {
    send_too_large(res, req.path, length);
    return 413;
  }
  return 100;
}

void HttpServer::send_too_large(Response& res, const std::string& path, std::optional<std::uint64_t> bytes) const {
  const std::uint64_t limit = settings_.max_request_bytes;
  const std::string size = bytes ? "has " + std::to_string(*bytes) + " bytes, more than" : "is larger than";
  nlohmann::json extra = {{"limit_bytes", limit}, {"setting", "--max-request-bytes"}};
  if (bytes) extra["request_bytes"] = *bytes;
  send_problem(res, 413, "",
               "the request body " + size + " the limit of " + std::to_string(limit) + " bytes (" + format_mib(limit) +
                   ") that contactd's --max-request-bytes (CONTACTD_MAX_REQUEST_BYTES) sets; a job "
                   "whose bodies come from one Gmsh file can give its text once, in the job's \"meshes\" table, "
                   "instead of once per body (docs/job-format.md)",
               path, std::move(extra));
}

void HttpServer::method_not_allowed_or_not_found(const Request& req, Response& res) {
  const std::vector<std::string> allowed = router_.allowed(req.path);
  if (allowed.empty()) {
    send_problem(res, 404, "", "no such resource: " + clip(req.path), req.path);
    return;
  }
  std::string allow;
  for (const auto& m : allowed) allow += (allow.empty() ? "" : ", ") + m + (m == "GET" ? ", HEAD" : "");
  res.set_header("Allow", allow);
  send_problem(res, 405, "", "method " + clip(req.method, 32) + " is not allowed here; allowed: " + allow, req.path);
}

Handled HttpServer::on_error(const Request& req, Response& res) {
  if (!res.body.empty()) return Handled::Unhandled;  // a handler's own problem document
  switch (res.status) {
    case 404:
      method_not_allowed_or_not_found(req, res);
      break;
    case 413: {
      std::uint64_t length = 0;
      const bool known = parse_count(trim(req.get_header_value("Content-Length")), UINT64_MAX / 2, length);
      send_too_large(res, req.path, known ? std::optional<std::uint64_t>(length) : std::nullopt);
      break;
    }
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
  log_line("internal error in " + req.method + " " + clip(req.path) + ": " + what);
  send_problem(res, 500, "", "internal error; the server's log has the details", req.path);
}

void HttpServer::on_response(const Request& req, const Response& res) {
  metrics_.http_response(res.status);
  if (settings_.access_log)
    log_line(req.remote_addr + " " + clip(req.method, 32) + " " + clip(req.path) + " " + std::to_string(res.status));
}

}  // namespace contactd

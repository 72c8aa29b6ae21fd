// The job routes (routes.hpp): submit, validate, list, get, cancel, delete.
#include "http/routes.hpp"

#include "transport/http_transport.hpp"
#include "transport/request_guard.hpp"

#include "common/encoding.hpp"
#include "common/job_id.hpp"
#include "contact/warning.hpp"
#include "http/problem_document.hpp"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <regex>
#include <string_view>

namespace contactd {

namespace {

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

void send_invalid_job(httplib::Response& res, const std::vector<contact::job::ValidationError>& list,
                      const std::string& instance) {
  // The parser bounds the list (200 errors of at most 1 KiB each): the answer stays small whatever the body.
  nlohmann::json errors = nlohmann::json::array();
  for (const auto& e : list) errors.push_back({{"pointer", e.pointer}, {"message", e.message}});
  send_problem(res, 400, "invalid-job",
               std::to_string(list.size()) + (list.size() == 1 ? " error" : " errors") +
                   " in the job; each is listed with its JSON pointer",
               instance, {{"errors", errors}});
}

// The one answer for a job id that names no job (a malformed id is shown clipped: it never reaches the disk).
void send_no_job(httplib::Response& res, const std::string& id, const std::string& instance) {
  send_problem(res, 404, "", "no job with id '" + clip(id, 64) + "'", instance);
}

// The job `id` names, or null with the answer set: 404 when it names none (a malformed id never reaches the disk),
// 500 corrupt-job when its files are damaged. GET, the streams (find_job) and cancel answer alike.
std::shared_ptr<Job> job_or_problem(const JobQueue& queue, const std::string& id, httplib::Response& res,
                                    const std::string& instance) {
  std::shared_ptr<Job> job = is_job_id(id) ? queue.find(id) : nullptr;
  if (!job) {
    if (auto problem = is_job_id(id) ? queue.damage(id) : std::nullopt)
      send_problem(res, 500, "corrupt-job", "job " + id + ": " + *problem, instance);
    else
      send_no_job(res, id, instance);
  }
  return job;
}

void send_busy(httplib::Response& res, const std::string& what, const std::string& instance) {
  res.set_header("Retry-After", "5");
  send_problem(res, 503, "busy", "the server is at its limit of " + what + "; retry later", instance);
}

}  // namespace

bool RouteContext::read_json_body(const Request& req, Response& res, const ContentReader& reader, std::string& body,
                                  BodyBudget::Slot& slot) const {
  std::uint64_t announced = 0;
  parse_count(trim(req.get_header_value("Content-Length")), UINT64_MAX / 2, announced);
  bool granted = false;
  slot = budget.for_body(req.has_header("Transfer-Encoding"), announced, granted);
  if (!granted) {
    res.set_header("Connection", "close");  // the body is not read
    send_busy(res, "large request bodies being read at once", req.path);
    return false;
  }
  if (announced <= settings.max_request_bytes) body.reserve(static_cast<std::size_t>(announced));
  bool too_large = false;
  const bool read = reader([&](const char* data, std::size_t length) {
    if (body.size() + length > settings.max_request_bytes) {  // chunked bodies have no Content-Length to check
      too_large = true;
      return false;
    }
    body.append(data, length);
    return true;
  });
  if (too_large || res.status == 413) {
    if (too_large) res.set_header("Connection", "close");  // the rest of the chunked body is still unread
    send_too_large(res, req.path, !too_large && announced > 0 ? std::optional<std::uint64_t>(announced) : std::nullopt);
    return false;
  }
  if (!read) {
    res.set_header("Connection", "close");
    const Exchange* exchange = current_exchange();
    if (exchange && exchange->body_timed_out)
      send_problem(
          res, 408, "",
          "the body did not arrive within " + std::to_string(static_cast<int>(settings.body_timeout_seconds)) + " s",
          req.path);
    else if (exchange && !exchange->bad_framing.empty())
      send_problem(res, 400, "invalid-request", "the chunked body is malformed: " + exchange->bad_framing, req.path);
    else
      send_problem(res, 400, "", "the request body could not be read", req.path);
    return false;
  }
  return true;
}

std::shared_ptr<Job> RouteContext::find_job(const Request& req, Response& res) const {
  const std::string id = req.matches.size() > 1 ? std::string(req.matches[1]) : std::string();
  return job_or_problem(queue, id, res, req.path);
}

namespace {

const std::string kJobPath = R"(/v1/jobs/([^/]+))";
const std::regex kCancelRoute(kJobPath + "/cancel");

void handle_submit(RouteContext& ctx, const Request& req, Response& res, const ContentReader& reader) {
  const std::string key = req.get_header_value("Idempotency-Key");
  if (req.has_header("Idempotency-Key") &&
      (key.empty() || key.size() > 255 ||
       !std::all_of(key.begin(), key.end(), [](unsigned char c) { return c >= 0x20 && c < 0x7f; }))) {
    res.set_header("Connection", "close");  // the body is not read
    send_problem(res, 400, "invalid-request", "Idempotency-Key must be 1 to 255 printable ASCII characters", req.path);
    return;
  }
  if (ctx.state.stopping) {
    res.set_header("Retry-After", "5");
    res.set_header("Connection", "close");
    send_problem(res, 503, "not-ready", "the server is shutting down and accepts no new jobs", req.path);
    return;
  }
  std::string body;
  BodyBudget::Slot body_slot;
  if (!ctx.read_json_body(req, res, reader, body, body_slot)) return;
  BodyBudget::Slot validation = ctx.budget.for_validation(body.size());
  if (!validation) return send_busy(res, "jobs being validated at once", req.path);
  auto parsed = ctx.queue.validate(body);
  using Outcome = JobQueue::Submission::Outcome;
  const auto s = ctx.queue.submit(body, std::move(parsed), key);
  switch (s.outcome) {
    case Outcome::accepted:
    case Outcome::replayed: {
      int position = 0;
      const JobRecord record = ctx.queue.snapshot(*s.job, &position);
      res.set_header("Location", job_link(record.id));
      if (s.outcome == Outcome::replayed) res.set_header("Idempotent-Replayed", "true");
      send_json(res, 202, ctx.job_resource(record, position));
      return;
    }
    case Outcome::invalid:
      send_invalid_job(res, s.errors, req.path);
      return;
    case Outcome::key_conflict:
      send_problem(res, 422, "idempotency-key-reused",
                   "Idempotency-Key '" + key + "' was used for job " + s.job->record.id + " with a different body",
                   req.path, {{"job", job_link(s.job->record.id)}});
      return;
    case Outcome::key_damaged:
      send_problem(res, 500, "corrupt-job",
                   "Idempotency-Key '" + key + "' was used for job " + s.detail +
                       ", whose files are damaged; it is not submitted again",
                   req.path, {{"job", job_link(s.detail)}});
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

void handle_validate(RouteContext& ctx, const Request& req, Response& res, const ContentReader& reader) {
  std::string body;
  BodyBudget::Slot body_slot;
  if (!ctx.read_json_body(req, res, reader, body, body_slot)) return;
  BodyBudget::Slot validation = ctx.budget.for_validation(body.size());
  if (!validation) return send_busy(res, "jobs being validated at once", req.path);
  const auto parsed = ctx.queue.validate(body);
  if (!parsed.ok()) return send_invalid_job(res, parsed.errors, req.path);
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
             {"warnings", contact::warnings_json(parsed.warnings)},
             {"normalized", p.normalized}});
}

// If-None-Match (RFC 9110, 13.1.2): "*" or a list of entity tags, compared weakly (W/ is ignored on both sides).
bool if_none_match_matches(const std::string& header, const std::string& etag) {
  const auto opaque = [](std::string_view tag) {
    while (!tag.empty() && (tag.front() == ' ' || tag.front() == '\t')) tag.remove_prefix(1);
    while (!tag.empty() && (tag.back() == ' ' || tag.back() == '\t')) tag.remove_suffix(1);
    if (tag.substr(0, 2) == "W/") tag.remove_prefix(2);
    return tag;
  };
  const std::string_view mine = opaque(etag);
  std::string_view rest = header;
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view tag = opaque(rest.substr(0, comma));
    if (tag == "*" || (!tag.empty() && tag == mine)) return true;
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  return false;
}

void handle_list(RouteContext& ctx, const Request& req, Response& res) {
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
  auto page = ctx.queue.list(state, static_cast<std::size_t>(page_size), after);
  // Bounded by bytes as well as by count: past kListBytes the page ends early (at least one job), and the token
  // continues after its last job.
  constexpr std::size_t kListBytes = 1 << 20;
  nlohmann::json jobs = nlohmann::json::array();
  std::size_t bytes = 0;
  for (std::size_t i = 0; i < page.jobs.size(); ++i) {
    nlohmann::json job = ctx.job_resource(page.jobs[i], 0, true);
    bytes += job.dump().size();
    jobs.push_back(std::move(job));
    if (bytes > kListBytes && i + 1 < page.jobs.size()) {
      page.next = JobQueue::Cursor{page.jobs[i].created_us, page.jobs[i].id};
      break;
    }
  }
  // A poller (the web page, every 2 s) that sends the page's ETag back gets 304 and no body while nothing in it
  // changed: a page of 50 walls is some 50 kB. The ETag is weak (RFC 9110, 8.8.1): it follows the jobs, their states
  // and outcomes, not the figures of a running or queued job (its iterations, progress and timings change with
  // every iteration and every second, and a strong tag never gave a poller a 304 while any job ran). A poller that
  // shows those figures live reads the job or its events, or asks without If-None-Match (the web page does while a
  // job runs).
  const nlohmann::json answer = {{"jobs", jobs},
                                 {"next_page_token", page.next ? encode_cursor(*page.next) : std::string()}};
  nlohmann::json significant = answer;
  for (auto& job : significant["jobs"])
    if (job.value("done", false) == false)
      for (const char* live : {"iterations", "progress", "timings"}) job.erase(live);
  char etag[32];
  std::snprintf(etag, sizeof etag, "W/\"%016zx\"", std::hash<std::string>{}(significant.dump()));
  res.set_header("ETag", etag);
  res.set_header("Cache-Control", "private, no-cache");
  if (if_none_match_matches(req.get_header_value("If-None-Match"), etag)) {
    res.status = 304;
    return;
  }
  send_json(res, 200, answer);
}

void handle_get(RouteContext& ctx, const Request& req, Response& res) {
  const auto job = ctx.find_job(req, res);
  if (!job) return;
  int position = 0;
  const JobRecord record = ctx.queue.snapshot(*job, &position);
  send_json(res, 200, ctx.job_resource(record, position));
}

void handle_delete(RouteContext& ctx, const Request& req, Response& res) {
  const std::string id = req.matches.size() > 1 ? std::string(req.matches[1]) : std::string();
  if (!is_job_id(id)) {
    send_no_job(res, id, req.path);
    return;
  }
  std::string detail;
  switch (ctx.queue.remove(id, detail)) {  // a damaged job can be deleted too
    case JobQueue::RemoveOutcome::removed:
      res.status = 204;
      return;
    case JobQueue::RemoveOutcome::not_found:
      send_no_job(res, id, req.path);
      return;
    case JobQueue::RemoveOutcome::not_done: {
      const auto job = ctx.queue.find(id);
      const JobRecord record = job ? ctx.queue.snapshot(*job) : JobRecord{};
      send_problem(res, 409, "job-not-finished", "cancel the job first, then delete it when it has ended", req.path,
                   {{"state", to_string(record.state)}});
      return;
    }
    case JobQueue::RemoveOutcome::store_error:
      send_problem(res, 500, "store-error", detail, req.path);
      return;
  }
}

}  // namespace

bool is_cancel_path(const std::string& path) { return std::regex_match(path, kCancelRoute); }

void handle_cancel(RouteContext& ctx, const Request& req, Response& res) {
  std::smatch match;
  // Called from the pre-routing handler too (a POST without a body), where req.matches is not set.
  std::string id;
  if (std::regex_match(req.path, match, kCancelRoute)) id = match[1];
  const std::shared_ptr<Job> job = job_or_problem(ctx.queue, id, res, req.path);
  if (!job) return;
  const auto outcome = ctx.queue.cancel(id);
  int position = 0;
  const JobRecord record = ctx.queue.snapshot(*job, &position);
  switch (outcome) {
    case JobQueue::CancelOutcome::cancelled:
    case JobQueue::CancelOutcome::cancelling:
    case JobQueue::CancelOutcome::already_cancelled:
      res.set_header("Location", job_link(id));
      send_json(res, 202, ctx.job_resource(record, position));
      return;
    case JobQueue::CancelOutcome::already_done:
      send_problem(res, 409, "job-finished", "the job has already finished", req.path,
                   {{"state", to_string(record.state)}});
      return;
    case JobQueue::CancelOutcome::not_found:
      send_no_job(res, id, req.path);
      return;
    case JobQueue::CancelOutcome::store_error:
      send_problem(res, 500, "store-error", "the cancellation could not be stored; the job is still queued", req.path);
      return;
  }
}

void register_job_routes(Router& router, RouteContext& ctx) {
  router.get("/v1/jobs", [&ctx](const Request& req, Response& res) { handle_list(ctx, req, res); });
  router.get(kJobPath, [&ctx](const Request& req, Response& res) { handle_get(ctx, req, res); });
  router.post_body("/v1/jobs", [&ctx](const Request& req, Response& res, const ContentReader& reader) {
    handle_submit(ctx, req, res, reader);
  });
  router.post_body("/v1/validate", [&ctx](const Request& req, Response& res, const ContentReader& reader) {
    handle_validate(ctx, req, res, reader);
  });
  router.post(kJobPath + "/cancel", [&ctx](const Request& req, Response& res) { handle_cancel(ctx, req, res); });
  router.del(kJobPath, [&ctx](const Request& req, Response& res) { handle_delete(ctx, req, res); });
}

}  // namespace contactd

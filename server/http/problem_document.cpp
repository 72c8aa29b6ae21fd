#include "http/problem_document.hpp"

#include <iterator>

namespace contactd {

namespace {

// The problem types this API defines (RFC 9457 "type"): relative URIs that GET /problems/<slug> explains.
// Plain HTTP errors whose status says everything use "about:blank".
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
    {"busy", "The server is busy",
     "The server is at one of its limits on concurrent work (large request bodies being read and validated, or "
     "open connections). Retry after the number of seconds in the Retry-After header."},
    {"idempotency-key-reused", "The Idempotency-Key was used with another body",
     "A job was already submitted with this Idempotency-Key and a different body. Use a new key for a new job."},
    {"job-not-finished", "The job has not finished",
     "The operation needs a finished job (SUCCEEDED, FAILED or CANCELLED); `state` is the job's current state."},
    {"job-finished", "The job has already finished", "A finished job cannot be cancelled; `state` is its state."},
    {"no-result", "The job has no result file",
     "The job finished without a solution to store (it failed before the first iteration, or was cancelled "
     "before it started)."},
    {"no-progress", "The job has no per-pair progress",
     "GET /v1/jobs/{id}/pairs serves the last iteration's detail of the pairs named; the job has none (it has not "
     "run an iteration yet, or it ended without one). A finished job's result file has every pair."},
    {"no-such-pair", "No pair matches",
     "None of the job's contact pairs matches the names or patterns given in `names`; the job's pairs are in its "
     "iteration events (pairs_summary counts them) and in GET /v1/jobs/{id}/pairs?names=*."},
    {"corrupt-job", "The job's stored files are damaged",
     "The server found the job's files in its data directory damaged (state.json unreadable, a result file that is "
     "not the HDF5 file it wrote, a file replaced by a symbolic link). Nothing is served from them and nothing is "
     "deleted; `detail` says what was found. /readyz and /metrics list such jobs for the operator."},
    {"cross-site-request", "The request may come from another site",
     "A request that changes state (POST, DELETE) must carry 'Content-Type: application/json' or an "
     "X-Requested-With header, which a web page of another site cannot send without the server's consent, and an "
     "Origin header, when present, must name an allowed host."},
    {"host-not-allowed", "The Host header names a host this server does not serve",
     "contactd answers only requests whose Host header names one of its allowed hosts (loopback names by default, "
     "set with --allowed-hosts): this defeats DNS rebinding, where a web page reaches a local server through a "
     "name of its own."},
    {"store-error", "The job store failed",
     "The server could not read or write its data directory; `detail` says why."},
};

}  // namespace

const ProblemType* problem_types() { return kProblemTypes; }
std::size_t problem_type_count() { return std::size(kProblemTypes); }

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
    case 421:
      return "Misdirected Request";
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

std::string clip(const std::string& text, std::size_t max) {
  if (text.size() <= max) return text;
  std::size_t end = max;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return text.substr(0, end) + "...";
}

std::string dump(const nlohmann::json& j) { return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

std::string problem_document(int status, const std::string& slug, const std::string& detail,
                             const std::string& instance, nlohmann::json extra) {
  const char* title = reason_phrase(status);
  for (std::size_t k = 0; k < problem_type_count(); ++k)
    if (slug == kProblemTypes[k].slug) title = kProblemTypes[k].title;
  nlohmann::json problem = extra.is_object() ? std::move(extra) : nlohmann::json::object();
  problem["type"] = slug.empty() ? std::string("about:blank") : "/problems/" + slug;
  problem["title"] = title;
  problem["status"] = status;
  problem["detail"] = clip(detail, 1024);
  if (!instance.empty()) problem["instance"] = clip(instance, 1024);
  return dump(problem) + "\n";
}

void send_json(httplib::Response& res, int status, const nlohmann::json& j) {
  res.status = status;
  // With the parameter, httplib does not compress the response: it would use brotli at its slowest quality for
  // any client that accepts "br" (a long job list would cost a second of CPU).
  res.set_content(dump(j) + "\n", "application/json; charset=utf-8");
}

void send_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                  const std::string& instance, nlohmann::json extra) {
  res.status = status;
  res.set_content(problem_document(status, slug, detail, instance, std::move(extra)), "application/problem+json");
}

}  // namespace contactd

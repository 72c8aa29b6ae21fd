// The stream routes (routes.hpp): a job's progress events (SSE or NDJSON) and its result files (with ETag and
// ranges).
#include "http/routes.hpp"

#include "transport/http_transport.hpp"
#include "transport/request_guard.hpp"

#include "http/problem_document.hpp"
#include "http/range.hpp"
#include "jobs/events.hpp"

#include "contact/progress_json.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>

namespace contactd {

namespace {

std::string format_sse(const Event& e) {
  return "id: " + std::to_string(e.seq) + "\nevent: " + e.type + "\ndata: " + e.json + "\n\n";
}

// One progress stream's position. Owned by the content provider (shared with its releaser).
struct Stream {
  std::shared_ptr<Job> job;
  std::int64_t cursor = 0;  // the last seq sent
  bool ndjson = false;
  std::chrono::steady_clock::time_point last_write;
};

bool pump_stream(RouteContext& ctx, Stream& stream, httplib::DataSink& sink);

// GET /v1/jobs/{id}/pairs?names=a,b*: the last iteration's detail (force, pressure and, with friction, tangential
// traction profiles) of the pairs named, whatever the job's progress_pairs: live while the job runs, from
// pairs.json once it has ended. At most kMaxPairsSelected pairs per answer ("matched" counts them all).
void handle_pairs(RouteContext& ctx, const Request& req, Response& res) {
  const auto job = ctx.find_job(req, res);
  if (!job) return;
  std::vector<std::string> patterns;
  const std::string names = req.has_param("names") ? req.get_param_value("names") : std::string();
  if (names.size() > 2000) {
    send_problem(res, 400, "invalid-request", "names has " + std::to_string(names.size()) + " characters: at most 2000",
                 req.path);
    return;
  }
  std::size_t from = 0;
  for (std::size_t comma; from <= names.size(); from = comma + 1) {
    comma = std::min(names.find(',', from), names.size());
    if (comma > from) patterns.push_back(names.substr(from, comma - from));
  }
  if (patterns.empty() || patterns.size() > 16) {
    send_problem(res, 400, "invalid-request",
                 "names must list 1 to 16 pair names or patterns (* ?) separated by commas, e.g. "
                 "?names=b0_0.top-b1_0.bottom,b3_*",
                 req.path);
    return;
  }
  std::shared_ptr<const nlohmann::json> detail = job->pair_detail();
  const char* source = "live";
  if (!detail) {
    source = "final";
    if (auto text = ctx.store.read_pairs(job->record.id)) {
      auto parsed = nlohmann::json::parse(*text, nullptr, false);
      if (parsed.is_object()) detail = std::make_shared<const nlohmann::json>(std::move(parsed));
    }
  }
  const JobRecord record = ctx.queue.snapshot(*job);
  if (!detail) {
    send_problem(res, 404, "no-progress",
                 "job " + record.id + " (" + to_string(record.state) + ") has no iteration yet" +
                     (is_terminal(record.state) ? "; its result file, if any, has every pair" : ""),
                 req.path, {{"state", to_string(record.state)}});
    return;
  }
  nlohmann::json pairs = nlohmann::json::array();
  std::size_t matched = 0;
  if (auto all = detail->find("pairs"); all != detail->end() && all->is_array())
    for (const auto& pair : *all) {
      if (!pair.is_object() || !contact::io::matches_any(pair.value("name", std::string()), patterns)) continue;
      if (++matched <= contact::io::kMaxPairsSelected) pairs.push_back(pair);
    }
  if (matched == 0) {
    send_problem(res, 404, "no-such-pair", "no pair of job " + record.id + " matches '" + clip(names, 200) + "'",
                 req.path);
    return;
  }
  send_json(res, 200,
            {{"iteration", detail->value("iteration", 0)},
             {"source", source},
             {"state", to_string(record.state)},
             {"matched", matched},
             {"pairs", std::move(pairs)}});
}

void handle_result(RouteContext& ctx, const Request& req, Response& res, bool sidecar) {
  const auto job = ctx.find_job(req, res);
  if (!job) return;
  const JobRecord record = ctx.queue.snapshot(*job);
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
  // Never serve what the server did not write: a link, a truncated or replaced file.
  if (auto problem = ctx.store.check_result(record)) {
    ctx.queue.report_damage(record.id, *problem);
    send_problem(res, 500, "corrupt-job", "job " + record.id + ": " + *problem + "; it is not served", req.path);
    return;
  }
  // The descriptor keeps the file readable even if the job is deleted while it is being sent.
  const int fd = ctx.store.open_result(record.id, sidecar);
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
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
  res.set_header("Accept-Ranges", "bytes");
  res.set_header("Content-Disposition",
                 sidecar ? "attachment; filename=\"result.xmf\"" : "attachment; filename=\"result.hdf\"");
  const std::string if_none_match = req.get_header_value("If-None-Match");
  if (!if_none_match.empty() && (if_none_match == etag || if_none_match == "*")) {
    ::close(fd);
    res.status = 304;
    return;
  }
  const auto size = static_cast<std::uint64_t>(st.st_size);
  ByteRange range;
  // If-Range with another validator: the file changed, send it whole.
  if (req.has_header("Range") && (!req.has_header("If-Range") || req.get_header_value("If-Range") == etag))
    range = parse_range(req.get_header_value("Range"), size);
  if (range.kind == ByteRange::Kind::unsatisfiable) {
    ::close(fd);
    res.set_header("Content-Range", content_range(range, size));
    send_problem(res, 416, "", "the range is outside the file's " + std::to_string(size) + " bytes", req.path);
    return;
  }
  const std::uint64_t first = range.kind == ByteRange::Kind::partial ? range.first : 0;
  const std::uint64_t length = range.kind == ByteRange::Kind::partial ? range.length : size;
  if (range.kind == ByteRange::Kind::partial) res.set_header("Content-Range", content_range(range, size));
  res.status = range.kind == ByteRange::Kind::partial ? 206 : 200;
  auto descriptor = std::make_shared<int>(fd);
  res.set_content_provider(
      static_cast<std::size_t>(length), sidecar ? "application/xml; charset=utf-8" : "application/x-hdf5",
      [descriptor, first](std::size_t offset, std::size_t want_length, httplib::DataSink& sink) {
        char buffer[1 << 16];
        const std::size_t want = std::min(want_length, sizeof buffer);
        ssize_t n;
        do {
          n = ::pread(*descriptor, buffer, want, static_cast<off_t>(first + offset));
        } while (n < 0 && errno == EINTR);
        if (n <= 0) return false;
        return sink.write(buffer, static_cast<std::size_t>(n));
      },
      [descriptor](bool) { ::close(*descriptor); });
}

void handle_events(RouteContext& ctx, const Request& req, Response& res) {
  const auto job = ctx.find_job(req, res);
  if (!job) return;
  std::string resume = req.get_header_value("Last-Event-ID");
  if (resume.empty() && req.has_param("last_event_id")) resume = req.get_param_value("last_event_id");
  std::uint64_t after = 0;
  if (!resume.empty() && !parse_count(trim(resume), 1ull << 53, after)) {
    send_problem(res, 400, "invalid-request", "Last-Event-ID must be an event's seq (a non-negative integer)",
                 req.path);
    return;
  }
  if (ctx.state.streams.fetch_add(1) >= ctx.settings.max_streams) {
    --ctx.state.streams;
    res.set_header("Retry-After", "5");
    send_problem(res, 503, "too-many-streams",
                 "the server already serves " + std::to_string(ctx.settings.max_streams) + " progress streams",
                 req.path);
    return;
  }
  ctx.metrics.stream_opened();
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
      [&ctx, stream](std::size_t, httplib::DataSink& sink) { return pump_stream(ctx, *stream, sink); },
      [&ctx](bool) {
        --ctx.state.streams;
        ctx.metrics.stream_closed();
      });
}

// Called by httplib again and again on the connection's thread until it returns false (client gone) or calls
// sink.done(). Sends what is new; otherwise waits for the job's next event for at most a second, so that
// shutdown and heartbeats are never late; never blocks the worker appending events.
bool pump_stream(RouteContext& ctx, Stream& stream, httplib::DataSink& sink) {
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
  // Nothing new. Finished (a log without `end` after a crash is repaired at start-up), deleted, damaged (the
  // next event cannot be read), or shutting down: close the stream.
  if (stream.job->events.discarded() || stream.job->events.unreadable_after(stream.cursor) ||
      (stream.job->settled.load() && stream.cursor >= stream.job->events.last_seq())) {
    sink.done();
    return true;
  }
  if (ctx.state.closing_streams) {
    if (!stream.ndjson) {
      static const std::string bye = ": the server is shutting down; reconnect with Last-Event-ID to resume\n\n";
      sink.write(bye.data(), bye.size());
    }
    sink.done();
    return true;
  }
  const auto now = std::chrono::steady_clock::now();
  const auto heartbeat = std::chrono::seconds(ctx.settings.heartbeat_seconds);
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

}  // namespace

void register_stream_routes(Router& router, RouteContext& ctx) {
  const std::string job = R"(/v1/jobs/([^/]+))";
  router.get(job + "/events", [&ctx](const Request& req, Response& res) { handle_events(ctx, req, res); });
  router.get(job + "/pairs", [&ctx](const Request& req, Response& res) { handle_pairs(ctx, req, res); });
  router.get(job + "/result", [&ctx](const Request& req, Response& res) { handle_result(ctx, req, res, false); });
  router.get(job + R"(/result\.xmf)",
             [&ctx](const Request& req, Response& res) { handle_result(ctx, req, res, true); });
}

}  // namespace contactd

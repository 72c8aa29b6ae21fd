// The service routes (routes.hpp: /healthz, /readyz, /metrics, /problems/*, the schema and the API spec) and the job
// resource shared by the job handlers.
#include "http/routes.hpp"

#include "routes/assets.hpp"

#include "common/time.hpp"
#include "http/problem_document.hpp"
#include "jobs/events.hpp"

#include "contact/solve.hpp"

namespace contactd {

nlohmann::json RouteContext::job_resource(const JobRecord& r, int queue_position, bool listed) const {
  const std::int64_t now = now_unix_us();
  auto time_or_null = [](std::int64_t us) { return us > 0 ? nlohmann::json(iso8601_us(us)) : nlohmann::json(nullptr); };
  const std::int64_t queued_until = r.started_us > 0 ? r.started_us : (r.finished_us > 0 ? r.finished_us : now);
  nlohmann::json timings = {
      {"queued_seconds", static_cast<double>(queued_until - r.created_us) * 1e-6},
      {"run_seconds",
       r.started_us > 0 ? static_cast<double>((r.finished_us > 0 ? r.finished_us : now) - r.started_us) * 1e-6 : 0.0},
      {"solve_seconds", r.solve_seconds}};
  const std::string self = "/v1/jobs/" + r.id;
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
                      {"lane", r.small ? "small" : "general"},
                      {"attempts", r.attempts},
                      {"interruptions", r.interruptions},
                      {"iterations", r.iterations},
                      {"progress", !r.progress ? nlohmann::json(nullptr)
                                   : listed    ? progress_digest(*r.progress)
                                               : *r.progress},
                      {"timings", timings},
                      {"result_available", r.result_available},
                      {"result_bytes", r.result_available ? nlohmann::json(r.result_bytes) : nlohmann::json(nullptr)},
                      {"events_dropped", r.events_dropped},
                      {"warnings", r.warnings},
                      {"collapse", r.collapse},
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

namespace {

void handle_healthz(RouteContext& ctx, const Request&, Response& res) {
  const double uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - ctx.state.started).count();
  send_json(res, 200, {{"status", "ok"}, {"uptime_seconds", uptime}});
}

// ready (200): serving. degraded (200): serving, but damaged jobs were found (listed; they are not served and
// never deleted by retention). unavailable (503): the data directory is not writable, the disk is full (the
// reserve was used), a worker died or is stuck. starting, stopping (503).
void handle_readyz(RouteContext& ctx, const Request&, Response& res) {
  const bool writable = ctx.store.writable();
  const int alive = ctx.queue.workers_alive();
  const QueueHealth health = ctx.queue.health();
  const bool reserve_used = ctx.store.reserve_used();
  std::vector<std::string> problems;
  if (!writable) problems.push_back("the data directory is not writable");
  if (reserve_used) problems.push_back("the disk filled up: the reserve was used to store a state change");
  if (alive != ctx.queue.workers()) problems.push_back("a worker thread has died");
  if (!health.stuck.empty()) problems.push_back(std::to_string(health.stuck.size()) + " job(s) do not stop when told");
  const bool unavailable = !problems.empty();
  if (!health.damaged.empty())
    problems.push_back(std::to_string(health.damaged.size()) + " job(s) have damaged files in the data directory");
  std::string status = !ctx.state.ready     ? "starting"
                       : ctx.state.stopping ? "stopping"
                       : unavailable        ? "unavailable"
                       : !problems.empty()  ? "degraded"
                                            : "ready";
  nlohmann::json damaged = nlohmann::json::array();
  for (std::size_t k = 0; k < health.damaged.size() && k < 100; ++k)
    damaged.push_back({{"id", health.damaged[k].first}, {"problem", health.damaged[k].second}});
  nlohmann::json body = {{"status", status},
                         {"data_dir_writable", writable},
                         {"disk_reserve_used", reserve_used},
                         {"workers", ctx.queue.workers()},
                         {"small_job_workers", ctx.queue.small_workers()},
                         {"abandoned_factorisations", contact::abandoned_background_work()},
                         {"workers_alive", alive},
                         {"problems", problems},
                         {"damaged_jobs", damaged},
                         {"stuck_jobs", health.stuck}};
  const bool ok = status == "ready" || status == "degraded";
  if (!ok) res.set_header("Retry-After", "1");
  send_json(res, ok ? 200 : 503, body);
}

void handle_metrics(RouteContext& ctx, const Request&, Response& res) {
  res.status = 200;
  Metrics::Gauges gauges;
  gauges.jobs = ctx.queue.counts();
  gauges.workers = ctx.queue.workers();
  gauges.workers_busy = ctx.queue.workers_busy();
  gauges.abandoned_work = contact::abandoned_background_work();
  const QueueHealth health = ctx.queue.health();
  gauges.damaged_jobs = static_cast<std::int64_t>(health.damaged.size());
  gauges.stuck_jobs = static_cast<std::int64_t>(health.stuck.size());
  gauges.jobs_expired_total = health.expired_total;
  gauges.events_dropped_total = health.events_dropped_total;
  gauges.disk_reserve_used = ctx.store.reserve_used();
  gauges.connections = static_cast<std::int64_t>(ctx.open_connections());
  res.set_content(ctx.metrics.render(gauges), "text/plain; version=0.0.4; charset=utf-8");
}

void handle_problem_type(RouteContext&, const Request& req, Response& res) {
  const std::string slug = req.matches[1];
  for (std::size_t k = 0; k < problem_type_count(); ++k) {
    const ProblemType& t = problem_types()[k];
    if (slug == t.slug) {
      res.status = 200;
      res.set_content(std::string(t.title) + "\n\n" + t.description + "\n", "text/plain; charset=utf-8");
      return;
    }
  }
  send_problem(res, 404, "", "no problem type '" + clip(slug, 64) + "'", req.path);
}

void handle_schema(RouteContext&, const Request&, Response& res) {
  res.status = 200;
  res.set_content(std::string(assets::job_schema()), "application/schema+json");
}

void handle_openapi(RouteContext&, const Request&, Response& res) {
  res.status = 200;
  res.set_content(std::string(assets::openapi_yaml()), "application/yaml");
}

}  // namespace

void register_service_routes(Router& router, RouteContext& ctx) {
  auto get = [&](const std::string& pattern, void (*handler)(RouteContext&, const Request&, Response&)) {
    router.get(pattern, [&ctx, handler](const Request& req, Response& res) { handler(ctx, req, res); });
  };
  get("/healthz", handle_healthz);
  get("/readyz", handle_readyz);
  get("/metrics", handle_metrics);
  get(R"(/problems/([a-z-]+))", handle_problem_type);
  get("/v1/schema", handle_schema);
  get(R"(/v1/job\.schema\.json)", handle_schema);  // so that openapi.yaml's "./job.schema.json" resolves
  get(R"(/v1/openapi\.yaml)", handle_openapi);
}

}  // namespace contactd

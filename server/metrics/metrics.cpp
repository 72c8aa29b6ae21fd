#include "metrics/metrics.hpp"

#include "store/job_record.hpp"

#include "contact/solve.hpp"

#include <cstdio>
#include <sstream>

namespace contactd {

void Metrics::solve_finished(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  solve_seconds_ += seconds;
}

void Metrics::http_response(int status) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++responses_[status];
}

std::string Metrics::render(const Gauges& g) const {
  std::ostringstream out;
  auto gauge = [&out](const char* name, const char* help, std::int64_t value) {
    out << "# HELP " << name << " " << help << "\n# TYPE " << name << " gauge\n" << name << " " << value << "\n";
  };
  auto counter = [&out](const char* name, const char* help, std::int64_t value) {
    out << "# HELP " << name << " " << help << "\n# TYPE " << name << " counter\n" << name << " " << value << "\n";
  };
  out << "# HELP contactd_jobs Jobs known to the server, by state.\n# TYPE contactd_jobs gauge\n";
  for (int s = 0; s < 5; ++s)
    out << "contactd_jobs{state=\"" << to_string(static_cast<JobState>(s)) << "\"} "
        << g.jobs.by_state[static_cast<std::size_t>(s)] << "\n";
  gauge("contactd_queue_length", "Jobs waiting for a worker.", g.jobs.queue_length);
  gauge("contactd_workers", "Worker threads.", g.workers);
  gauge("contactd_workers_busy", "Worker threads running a job.", g.workers_busy);
  gauge("contactd_abandoned_factorisations",
        "Factorisations a cancel left running (each holds a core and memory until it ends; no job starts on a "
        "general worker while they and the running jobs fill the workers).",
        g.abandoned_work);
  gauge("contactd_jobs_damaged", "Jobs whose files in the data directory are damaged (listed by /readyz).",
        g.damaged_jobs);
  gauge("contactd_jobs_stuck", "Running jobs that did not stop when told to (listed by /readyz).", g.stuck_jobs);
  gauge("contactd_disk_reserve_used", "1 when the disk filled up and the reserve was used.", g.disk_reserve_used);
  gauge("contactd_connections", "Open client connections.", g.connections);
  counter("contactd_jobs_submitted_total", "Jobs accepted since start-up.", jobs_submitted_.load());
  counter("contactd_jobs_expired_total", "Finished jobs deleted by retention since start-up.", g.jobs_expired_total);
  counter("contactd_iterations_total", "Solver iterations done since start-up.", iterations_.load());
  counter("contactd_events_dropped_total",
          "Events not recorded in a job's event log: iteration events past its cap, or lost to a failed write.",
          g.events_dropped_total);
  gauge("contactd_stream_clients", "Open progress streams.", stream_clients_.load());
  std::lock_guard<std::mutex> lock(mutex_);
  char seconds[64];
  std::snprintf(seconds, sizeof seconds, "%.6f", solve_seconds_);
  out << "# HELP contactd_solve_seconds_total Wall time spent in the solver since start-up.\n"
      << "# TYPE contactd_solve_seconds_total counter\ncontactd_solve_seconds_total " << seconds << "\n";
  out << "# HELP contactd_http_requests_total HTTP responses sent, by status code.\n"
      << "# TYPE contactd_http_requests_total counter\n";
  for (const auto& [code, n] : responses_) out << "contactd_http_requests_total{code=\"" << code << "\"} " << n << "\n";
  out << "# HELP contactd_build_info The solver version.\n# TYPE contactd_build_info gauge\n"
      << "contactd_build_info{version=\"" << contact::solver_version() << "\"} 1\n";
  return out.str();
}

}  // namespace contactd

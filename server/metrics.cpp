#include "metrics.hpp"

#include "job.hpp"

#include "solve.hpp"

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

std::string Metrics::render(const JobCounts& counts, int workers_busy, int workers) const {
  std::ostringstream out;
  out << "# HELP contactd_jobs Jobs known to the server, by state.\n# TYPE contactd_jobs gauge\n";
  for (int s = 0; s < 5; ++s)
    out << "contactd_jobs{state=\"" << to_string(static_cast<JobState>(s)) << "\"} "
        << counts.by_state[static_cast<std::size_t>(s)] << "\n";
  out << "# HELP contactd_queue_length Jobs waiting for a worker.\n# TYPE contactd_queue_length gauge\n"
      << "contactd_queue_length " << counts.queue_length << "\n";
  out << "# HELP contactd_workers Worker threads.\n# TYPE contactd_workers gauge\ncontactd_workers " << workers << "\n";
  out << "# HELP contactd_workers_busy Worker threads running a job.\n# TYPE contactd_workers_busy gauge\n"
      << "contactd_workers_busy " << workers_busy << "\n";
  out << "# HELP contactd_jobs_submitted_total Jobs accepted since start-up.\n# TYPE contactd_jobs_submitted_total "
         "counter\n"
      << "contactd_jobs_submitted_total " << jobs_submitted_.load() << "\n";
  out << "# HELP contactd_iterations_total Solver iterations done since start-up.\n# TYPE contactd_iterations_total "
         "counter\n"
      << "contactd_iterations_total " << iterations_.load() << "\n";
  out << "# HELP contactd_stream_clients Open progress streams.\n# TYPE contactd_stream_clients gauge\n"
      << "contactd_stream_clients " << stream_clients_.load() << "\n";
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

// The settings of the jobs (contactd's command line), and the validation of a job against their limits.
#pragma once

#include "jobs/mpi_job.hpp"

#include "contact/job.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

namespace contactd {

struct QueueSettings {
  int workers = 1;  // jobs solved at once
  // The small-job lane: this many more workers that take only small jobs (small_job), so that a job of seconds
  // never waits behind long ones; and the size below which a job is small: unknowns x load steps.
  int small_workers = 1;
  long small_job_dofs = 20'000;
  // A run on the small lane that takes longer than this is stopped and queued again for a general worker (its size
  // said small, its solve was not: a tight tolerance, a slow method), so that the lane stays free for small jobs.
  double small_job_seconds = 10.0;
  std::size_t max_queued = 100;  // QUEUED jobs beyond which submissions are refused (503)
  long max_dofs = 2'000'000;     // job::Limits::max_dofs
  // job::Limits::max_bodies and max_contacts: a server's share of the machine, a setting. The 64 x 64 frictional
  // brick wall (4,129 bodies, 12,192 pairs) fits: about 20 s and 630 MB through contactd.
  int max_bodies = 8192;
  int max_contacts = 32768;
  int max_load_steps = 1000;           // job::Limits::max_load_steps
  double max_result_bytes = 2e9;       // job::Limits::max_result_bytes: the estimated result (and kept steps)
  double max_interface_bytes = 4e9;    // job::Limits::max_interface_bytes: the interface problem's dense blocks
  double max_validation_seconds = 30;  // job::Limits::max_validation_seconds: a request's validation
  double time_limit_seconds = 3600.0;  // per run; 0 = none
  int max_attempts = 3;                // runs cut short by the server dying, after which a job ends FAILED
  std::uint64_t max_event_log_bytes = 256u << 20;  // per job; iteration events beyond are not recorded
  double stuck_after_seconds = 60.0;               // a job still running this long after it was told to stop is "stuck"
  double retention_seconds = 7 * 86400.0;          // finished jobs older than this are deleted; 0 = kept
  std::uint64_t retention_bytes = 10ull << 30;     // finished jobs beyond this total are deleted, oldest first
  double janitor_interval_seconds = 10.0;          // how often retention runs
  MpiSettings mpi;                                 // jobs with parallel.ranks > 1 (mpi_job.hpp)
};

// A job the small-job lane may take: one process, no adaptivity (it grows), at most 16 bodies and at most
// small_job_dofs unknowns times load steps.
bool small_job(const QueueSettings& settings, const contact::Problem& problem);

// The bytes the job's result file is estimated to take, as the job reader checks it against --max-result-bytes
// (contact::io::estimated_result_bytes: the nodes of the steps kept; an adaptive job's at the most it may refine to).
// What the workers' disk budget reserves for a running job.
std::int64_t estimated_result(const contact::Problem& problem);

// Parses and validates a job body within the settings' limits (the ranks a job may ask for depend on
// whether MPI jobs are possible). `time_limited`: within --max-validation-seconds too (a request's validation; a
// worker's parse again of a job validated at submission is not, so that a loaded machine does not fail it).
contact::job::ParseResult validate_job(const QueueSettings& settings, const std::string& body,
                                       bool time_limited = true);

}  // namespace contactd

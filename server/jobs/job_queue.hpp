// The one entry point the routes use for jobs: a facade over the parts that hold the jobs' state, each with its
// own lock (docs/architecture.md, `server/jobs/`):
//   JobRegistry    the jobs' records, lookups, counts, damage and commit() (job_registry.hpp)
//   WorkerPool     the queue and the worker threads (worker_pool.hpp); a JobRun is one run of a job (job_run.hpp)
//   Janitor        time limits, stuck jobs, retention (janitor.hpp)
//   JobRecovery    the store read back at start-up (job_recovery.hpp)
// Jobs on MPI ranks are mpi_job.hpp; a job's events its EventLog (event_log.hpp), fed by a ProgressObserver.
// The facade holds none of their state: it wires them together and does what spans several of them (a
// submission, a cancel).
//
// Life of a job: submit() validates it, stores it (JobStore::create) and queues it (QUEUED); a worker takes it
// (RUNNING), runs it (job_run.hpp: the outcomes) and ends it SUCCEEDED, FAILED or CANCELLED with an `end` event.
// A server that died while a job ran queues it again at the next start-up, or ends it FAILED: with stop_reason
// "crashed" when the job's own solve took the fatal signal (store/crash_marker.hpp), "interrupted" once it has
// been cut short max_attempts times (a job that kills the server by other means).
//
// Lock order: WorkerPool's mutex, then JobRegistry's; a job's EventLog lock and the Janitor's are never held while
// another is taken. None is held while solving, writing result files or waiting for a client.
//
// Thread safety: every public member may be called from any thread.
#pragma once

#include "jobs/body_budget.hpp"
#include "jobs/janitor.hpp"
#include "jobs/job.hpp"
#include "jobs/job_registry.hpp"
#include "jobs/job_run.hpp"
#include "jobs/queue_settings.hpp"
#include "jobs/worker_pool.hpp"
#include "metrics/metrics.hpp"
#include "store/job_store.hpp"

#include "contact/job.hpp"

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace contactd {

// What /readyz and /metrics report about the jobs.
struct QueueHealth {
  std::vector<std::pair<std::string, std::string>> damaged;  // (id, problem)
  std::vector<std::string> stuck;                            // ids of jobs that do not stop
  std::int64_t expired_total = 0;                            // jobs deleted by retention since start-up
  std::int64_t events_dropped_total = 0;                     // iteration events not recorded (log caps)
};

class JobQueue {
 public:
  // A worker parses its job again under one of `budget`'s validation slots (shared with the HTTP server).
  JobQueue(JobStore& store, Metrics& metrics, BodyBudget& budget, QueueSettings settings);
  ~JobQueue();
  JobQueue(const JobQueue&) = delete;
  JobQueue& operator=(const JobQueue&) = delete;

  // Reads the store back (before start()): see job_recovery.hpp.
  void recover();
  // Starts the workers and the janitor.
  void start();
  // No job starts from now on; running jobs are cancelled and stored back as QUEUED. Waits up to `grace` for
  // the workers to finish that; returns false if one did not (the caller should then exit without joining).
  bool shutdown(std::chrono::milliseconds grace);

  struct Submission {
    enum class Outcome { accepted, replayed, invalid, key_conflict, key_damaged, queue_full, unavailable, store_error };
    Outcome outcome = Outcome::invalid;
    std::shared_ptr<Job> job;
    std::vector<contact::job::ValidationError> errors;  // invalid
    std::string detail;                                 // store_error; key_damaged: the job's id
  };
  // Queues a job validated by validate(). With a non-empty idempotency key already used: the same body returns
  // the existing job (replayed), another body is a key_conflict (key_damaged: that job's files are damaged).
  Submission submit(const std::string& body, contact::job::ParseResult parsed, const std::string& idempotency_key);

  // Validates only.
  contact::job::ParseResult validate(const std::string& body) const { return validate_job(settings_, body); }

  // A stored job (nullptr when unknown, damaged, or still being stored).
  std::shared_ptr<Job> find(const std::string& id) const { return registry_.find(id); }
  // What is wrong with a job's files, if the store found damage.
  std::optional<std::string> damage(const std::string& id) const { return registry_.damage(id); }
  // Records damage found while serving a job (a result file that is not what was written).
  void report_damage(const std::string& id, const std::string& problem) { registry_.report_damage(id, problem); }
  QueueHealth health() const;
  // A consistent copy of the job's record, and its place in the queue (1 = next; 0 when not waiting).
  JobRecord snapshot(const Job& job, int* queue_position = nullptr) const;

  enum class CancelOutcome { cancelled, cancelling, already_cancelled, already_done, not_found, store_error };
  CancelOutcome cancel(const std::string& id);

  using RemoveOutcome = JobRegistry::RemoveOutcome;
  RemoveOutcome remove(const std::string& id, std::string& detail) { return registry_.remove(id, detail); }

  // Listing, newest first, resuming after `after` (created_us, id) when given.
  using Cursor = JobRegistry::Cursor;
  using Page = JobRegistry::Page;
  Page list(std::optional<JobState> state, std::size_t page_size, const std::optional<Cursor>& after) const {
    return registry_.list(state, page_size, after);
  }

  JobCounts counts() const { return registry_.counts(); }
  int workers() const { return settings_.workers + settings_.small_workers; }  // threads: both lanes
  int small_workers() const { return settings_.small_workers; }
  int workers_busy() const { return pool_.busy(); }
  int workers_alive() const { return pool_.alive(); }
  bool stopping() const { return pool_.stopping(); }

 private:
  // A submission whose idempotency key names a job: that job (replayed) once stored, or a key_conflict.
  Submission replay(const JobRegistry::Admission& admission) const;

  const QueueSettings settings_;
  JobStore& store_;
  Metrics& metrics_;
  JobRegistry registry_;
  WorkerPool pool_;
  Janitor janitor_;
  const RunContext run_context_;
};

}  // namespace contactd

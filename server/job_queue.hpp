// The jobs the server knows, the queue of those waiting, and the worker threads that run them.
//
// Life of a job: submit() validates it, stores it (JobStore::create) and queues it (QUEUED); a worker takes it
// (RUNNING), runs contact::solve() with an observer that appends one `iteration` event per iteration, writes the
// result file and ends it SUCCEEDED, FAILED or CANCELLED with an `end` event. Mapping of the solver's stop reason:
//   converged                  -> SUCCEEDED, converged true
//   max_iterations, stagnation -> SUCCEEDED, converged false (the result file is written and useful)
//   error                      -> FAILED with the solver's message (no result file)
//   cancelled by the user      -> CANCELLED (the result file of the last iterate is written when the solver
//                                 returned one)
//   cancelled by the time limit-> FAILED with stop_reason "time_limit" (result file as for CANCELLED)
//   cancelled by shutdown      -> back to QUEUED on disk: it runs again, from the start, at the next start-up.
//
// Thread safety: every public member may be called from any thread. One mutex guards the registry and every
// job's record; it is never held while solving, writing result files or waiting for a client.
#pragma once

#include "job.hpp"
#include "job_store.hpp"
#include "metrics.hpp"

#include "job/job.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

namespace contactd {

struct QueueSettings {
  int workers = 1;                  // jobs solved at once
  std::size_t max_queued = 100;     // QUEUED jobs beyond which submissions are refused (503)
  long max_dofs = 2'000'000;        // job::Limits::max_dofs
  double time_limit_seconds = 0.0;  // per run; 0 = none
};

class JobQueue {
 public:
  JobQueue(JobStore& store, Metrics& metrics, QueueSettings settings);
  ~JobQueue();
  JobQueue(const JobQueue&) = delete;
  JobQueue& operator=(const JobQueue&) = delete;

  // Reads the store back (before start()): finished jobs are kept as they are (an `end` event missing after a
  // crash is added); QUEUED and interrupted RUNNING jobs are queued again, oldest first.
  void recover();
  // Starts the workers and the time-limit watchdog.
  void start();
  // No job starts from now on; running jobs are cancelled and stored back as QUEUED. Waits up to `grace` for
  // the workers to finish that; returns false if one did not (the caller should then exit without joining).
  bool shutdown(std::chrono::milliseconds grace);

  struct Submission {
    enum class Outcome { accepted, replayed, invalid, key_conflict, queue_full, unavailable, store_error };
    Outcome outcome = Outcome::invalid;
    std::shared_ptr<Job> job;
    std::vector<contact::job::ValidationError> errors;  // invalid
    std::string detail;                                 // store_error
  };
  // Validates and queues a job. With a non-empty idempotency key already used: the same body returns the
  // existing job (replayed), another body is a key_conflict.
  Submission submit(const std::string& body, const std::string& idempotency_key);

  // Validates only.
  contact::job::ParseResult validate(const std::string& body) const;

  std::shared_ptr<Job> find(const std::string& id) const;
  // A consistent copy of the job's record, and its place in the queue (1 = next; 0 when not waiting).
  JobRecord snapshot(const Job& job, int* queue_position = nullptr) const;

  enum class CancelOutcome { cancelled, cancelling, already_cancelled, already_done, not_found };
  CancelOutcome cancel(const std::string& id);

  enum class RemoveOutcome { removed, not_found, not_done, store_error };
  RemoveOutcome remove(const std::string& id, std::string& detail);

  // Listing, newest first, resuming after `after` (created_us, id) when given.
  struct Cursor {
    std::int64_t created_us = 0;
    std::string id;
  };
  struct Page {
    std::vector<JobRecord> jobs;
    std::optional<Cursor> next;  // set when more jobs follow
  };
  Page list(std::optional<JobState> state, std::size_t page_size, const std::optional<Cursor>& after) const;

  JobCounts counts() const;
  int workers() const { return settings_.workers; }
  int workers_busy() const;
  int workers_alive() const { return workers_alive_.load(); }
  bool stopping() const;

 private:
  using TimeKey = std::pair<std::int64_t, std::string>;

  void worker_loop();
  void watchdog_loop();
  void run(const std::shared_ptr<Job>& job);
  // Sets job->settled under the queue lock and wakes remove() calls waiting for it.
  void mark_settled(const std::shared_ptr<Job>& job);
  void finish(const std::shared_ptr<Job>& job, JobRecord outcome);
  void requeue_after_shutdown(const std::shared_ptr<Job>& job);
  void persist(const std::shared_ptr<Job>& job, bool durable = true);
  void set_state_locked(Job& job, JobState state);
  void register_locked(const std::shared_ptr<Job>& job);
  void unregister_locked(const std::shared_ptr<Job>& job);

  JobStore& store_;
  Metrics& metrics_;
  const QueueSettings settings_;

  mutable std::mutex mutex_;
  std::condition_variable work_;      // a job was queued, or stopping
  std::condition_variable watchdog_;  // stopping
  std::condition_variable idle_;      // a worker finished a job or exited
  std::condition_variable settled_;   // a job's `end` event was written (it may now be deleted)
  std::unordered_map<std::string, std::shared_ptr<Job>> jobs_;
  std::map<TimeKey, std::shared_ptr<Job>> by_time_;         // (created_us, id), oldest first
  std::unordered_map<std::string, std::string> by_key_;     // idempotency key -> id
  std::unordered_map<std::string, std::size_t> body_hash_;  // id -> hash of job.json (jobs with a key)
  std::deque<std::shared_ptr<Job>> queue_;
  std::vector<std::shared_ptr<Job>> running_;
  std::array<std::int64_t, 5> state_counts_{};
  std::int64_t last_created_us_ = 0;
  bool started_ = false;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
  std::thread watchdog_thread_;
  std::atomic<int> workers_alive_{0};
};

}  // namespace contactd

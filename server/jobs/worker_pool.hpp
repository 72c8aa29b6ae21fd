// The worker threads and the queue of jobs waiting for them. A worker takes the next QUEUED job, stores it
// RUNNING (not fsync'ed: whether a crash leaves QUEUED or RUNNING on disk, the job is queued again at start-up),
// gives it its time limit and hands it to `run` (a JobRun), until the pool stops.
//
// Two lanes. The general workers take the jobs in the order they came; before a general worker starts a job it
// waits while the factorisations that cancels left running (contact::abandoned_background_work) and the general
// jobs running fill the general workers: each such factorisation holds a core and its memory until it ends, and
// a loop of submit-and-cancel ran more factorisations at once than there are workers (6.2 GB with 2). The
// small-job workers take only jobs marked small at submission (JobRecord::small), the first in the queue, so a
// job of seconds does not wait behind long ones (it waited 94 s behind two frictional walls on two workers).
//
// Thread safety: every public member may be called from any thread. One mutex guards the queue, the jobs the
// workers hold (taken or running) and their deadlines and cancel requests; the registry's mutex may be taken
// while it is held (a job's state is read under both), never the other way round. It is never held while a
// job runs or its state is written.
#pragma once

#include "jobs/job.hpp"
#include "jobs/job_registry.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace contactd {

class WorkerPool {
 public:
  using Run = std::function<void(const std::shared_ptr<Job>&)>;

  // `workers` general threads and `small_workers` for small jobs; a run is stopped by its time limit after
  // `time_limit_seconds` (0: none).
  // A small-lane run past `small_job_seconds` is given lane_deadline (the janitor stops it; its run queues it again
  // as a general job, and release() puts it back in the queue).
  //
  // The disk budget: a job starts only when its estimated result (JobRecord::result_estimate) fits in what the data
  // directory has free (`disk.free`) less what the running jobs' results will still take (their estimates less what
  // their directories hold, `disk.used`). A job that does not fit waits, its record's message saying why, and the
  // jobs behind it that fit go first; it is looked at again every few seconds (another job's end, a file deleted).
  struct Disk {
    std::function<std::int64_t()> free;                    // bytes free (-1: unknown, then nothing is held back)
    std::function<std::int64_t(const std::string&)> used;  // bytes a job's directory holds
  };
  WorkerPool(JobRegistry& registry, int workers, int small_workers, double time_limit_seconds, double small_job_seconds,
             Disk disk, Run run);
  ~WorkerPool();  // threads shutdown() gave up on are left to the exiting process
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  void start();
  // No job starts from now on; running jobs are cancelled (CancelReason::shutdown). Waits up to `grace` for the
  // workers to exit; returns false if one did not (the caller should then exit without joining).
  bool shutdown(std::chrono::milliseconds grace);
  bool stopping() const { return stopping_.load(); }
  // Waits up to `timeout` for shutdown(); true once the pool stops.
  bool wait_for_stop(std::chrono::milliseconds timeout) const;

  // Queues a stored QUEUED job (at the back; nothing while stopping).
  void enqueue(const std::shared_ptr<Job>& job);
  // A cancel of the job `id` (set in `job` when found): a job waiting in the queue leaves it (withdraw), a job a
  // worker holds is told to stop.
  JobRegistry::CancelStep cancel(const std::string& id, std::shared_ptr<Job>& job);
  // A withdrawn job whose CANCELLED state could not be stored: back in its place by creation time if QUEUED.
  void restore_after_failed_cancel(const std::shared_ptr<Job>& job);

  // The job's record and its place in the queue (1 = next; 0 when not waiting), consistently.
  JobRecord snapshot(const Job& job, int& queue_position) const;
  int busy() const;
  int alive() const { return workers_alive_.load(); }
  // Calls `visit` for every job a worker holds, with the pool's lock held (request_cancel may be called).
  void for_each_running(const std::function<void(Job&)>& visit) const;

 private:
  void worker_loop(bool small_lane);
  std::shared_ptr<Job> take(bool small_lane);  // null once stopping
  // With the lock held: the general lane has no room while abandoned factorisations and its running jobs fill it.
  bool general_lane_full() const;
  // With the lock held: what the data directory has free and what the running jobs' results will still write (their
  // estimates less what their directories hold), asked once per look at the queue.
  struct DiskRoom {
    bool known = false;
    std::int64_t free = 0, pending = 0;
  };
  DiskRoom disk_room() const;
  // Whether `job`'s result fits in that room; if not, `why` says so.
  bool fits_on_disk(const Job& job, const DiskRoom& room, std::string& why) const;
  // Puts `why` in a waiting job's record (once per change; with the pool's lock held: the registry's is taken after).
  void note_waiting(const std::shared_ptr<Job>& job, const std::string& why);
  bool store_running(const std::shared_ptr<Job>& job, bool small_lane);
  void release(const std::shared_ptr<Job>& job, bool small_lane);

  JobRegistry& registry_;
  const int workers_, small_workers_;
  const double time_limit_seconds_, small_job_seconds_;
  const Disk disk_;
  const Run run_;

  mutable std::mutex mutex_;
  std::condition_variable work_;          // a job was queued, or stopping
  std::condition_variable idle_;          // a worker finished a job or exited
  mutable std::condition_variable stop_;  // stopping
  std::deque<std::shared_ptr<Job>> queue_;
  std::vector<std::shared_ptr<Job>> running_;  // taken by a worker (stored RUNNING, or being stored)
  int general_running_ = 0;                    // of running_, those a general worker took
  std::vector<std::thread> threads_;
  std::atomic<int> workers_alive_{0};
  bool started_ = false;
  std::atomic<bool> stopping_{false};  // written under mutex_
};

}  // namespace contactd

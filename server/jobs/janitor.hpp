// The janitor's thread: the time limit of running jobs, jobs that do not stop when told (stuck), the retention
// of finished jobs (age and total size), and the disk reserve. It wakes every 100 ms for the running jobs, runs
// retention every `janitor_interval_seconds` and at once after a job is settled (retention by size).
//
// Thread safety: every public member may be called from any thread. Its mutex guards its own state only and is
// never held while it takes another lock.
#pragma once

#include "jobs/job_registry.hpp"
#include "jobs/queue_settings.hpp"
#include "jobs/worker_pool.hpp"
#include "store/job_store.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace contactd {

class Janitor {
 public:
  Janitor(JobRegistry& registry, WorkerPool& pool, JobStore& store, const QueueSettings& settings);
  ~Janitor();
  Janitor(const Janitor&) = delete;
  Janitor& operator=(const Janitor&) = delete;

  void start();
  void request_stop();  // the thread ends at its next wake-up
  void join();
  // A job was settled: retention runs at once.
  void retention_due();

  std::vector<std::string> stuck() const;  // ids of jobs that do not stop
  std::int64_t expired_total() const;      // jobs deleted by retention since start-up

 private:
  void loop();
  void watch_running(std::chrono::steady_clock::time_point now);
  void apply_retention();

  JobRegistry& registry_;
  WorkerPool& pool_;
  JobStore& store_;
  const QueueSettings& settings_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;  // stopping, or retention due
  bool stopping_ = false;
  bool retention_due_ = false;
  std::vector<std::string> stuck_;
  std::int64_t expired_total_ = 0;
  std::thread thread_;
};

}  // namespace contactd

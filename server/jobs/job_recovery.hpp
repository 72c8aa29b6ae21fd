// Start-up recovery: the store read back into the registry (before the workers start). Finished jobs are kept
// as they are (an `end` event missing after a crash is added); QUEUED jobs are queued again, oldest first; a
// RUNNING job was cut short by the server dying: it ends FAILED with stop_reason "crashed" when its own solve took
// the fatal signal (store/crash_marker.hpp), else it is queued again, or ends FAILED with stop_reason
// "interrupted" once that has happened max_attempts times (a job that kills the server by other means).
#pragma once

#include "jobs/job.hpp"
#include "jobs/job_run.hpp"
#include "jobs/worker_pool.hpp"

#include <memory>
#include <string>

namespace contactd {

class JobRecovery {
 public:
  JobRecovery(const RunContext& context, WorkerPool& pool) : context_(context), pool_(pool) {}
  // Throws std::runtime_error when a recovered job's new state cannot be stored.
  void run();

 private:
  void recover(const std::shared_ptr<Job>& job);
  void check_finished(const std::shared_ptr<Job>& job);
  void give_up(const std::shared_ptr<Job>& job, int interruptions, const std::string& stop_reason,
               const std::string& message);
  void requeue_interrupted(const std::shared_ptr<Job>& job, int interruptions);
  void commit_or_throw(const std::shared_ptr<Job>& job, const JobRegistry::Change& change);

  const RunContext& context_;
  WorkerPool& pool_;
  int requeued_ = 0;
};

}  // namespace contactd

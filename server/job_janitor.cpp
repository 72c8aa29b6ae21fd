// The queue's watchdog thread: the time limit of running jobs, jobs that do not stop when told (stuck), the
// retention of finished jobs (age and total size), and the disk reserve.
#include "job_queue.hpp"

#include "util.hpp"

#include <cstdio>

namespace contactd {

void JobQueue::watchdog_loop() {
  using Clock = std::chrono::steady_clock;
  const auto interval = std::chrono::milliseconds(static_cast<std::int64_t>(settings_.janitor_interval_seconds * 1e3));
  auto next_janitor = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    watchdog_.wait_for(lock, std::chrono::milliseconds(100));
    if (stopping_) break;
    const auto now = Clock::now();
    watch_running_locked(now);
    if (now >= next_janitor || retention_due_) {  // due after every job that finishes (retention by size)
      next_janitor = now + interval;
      retention_due_ = false;
      lock.unlock();
      apply_retention();
      if (store_.reserve_used()) store_.restore_reserve();
      lock.lock();
    }
  }
}

void JobQueue::watch_running_locked(std::chrono::steady_clock::time_point now) {
  std::vector<std::string> stuck;
  for (const auto& job : running_) {
    if (now >= job->deadline && job->cancel_reason.load() == static_cast<int>(CancelReason::none)) {
      job->request_cancel(CancelReason::time_limit);
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", settings_.time_limit_seconds);
      log_line("job " + job->record.id + ": time limit of " + limit + " s reached; stopping it");
    }
    // Told to stop (cancel, time limit, shutdown) and still running long after: its worker is stuck (a solve
    // that never reaches its next iteration). Reported by /readyz; the job cannot be stopped from here.
    if (job->cancel_reason.load() != static_cast<int>(CancelReason::none) &&
        now - job->cancel_requested_at > std::chrono::duration<double>(settings_.stuck_after_seconds)) {
      stuck.push_back(job->record.id);
      if (std::find(stuck_.begin(), stuck_.end(), job->record.id) == stuck_.end())
        log_line("job " + job->record.id + ": still running " + std::to_string(settings_.stuck_after_seconds) +
                 " s after it was told to stop: its worker is stuck");
    }
  }
  stuck_ = std::move(stuck);
}

void JobQueue::apply_retention() {
  if (settings_.retention_seconds <= 0 && settings_.retention_bytes == 0) return;
  std::vector<std::string> doomed;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::int64_t now = now_unix_us();
    std::int64_t bytes = finished_bytes_;
    for (const auto& [key, job] : by_finished_) {  // oldest first
      if (damaged_.count(key.second)) continue;     // left for the operator to look at
      const bool too_old =
          settings_.retention_seconds > 0 && now - key.first > static_cast<std::int64_t>(settings_.retention_seconds * 1e6);
      const bool too_much = settings_.retention_bytes > 0 && bytes > static_cast<std::int64_t>(settings_.retention_bytes);
      if (!too_old && !too_much) break;
      doomed.push_back(key.second);
      bytes -= job->disk_bytes;
    }
  }
  for (const auto& id : doomed) {
    std::string detail;
    if (remove(id, detail) == RemoveOutcome::removed) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++expired_total_;
      log_line("retention: deleted job " + id);
    }
  }
}

}  // namespace contactd

#include "jobs/janitor.hpp"

#include "common/log.hpp"

#include <algorithm>
#include <cstdio>

namespace contactd {

Janitor::Janitor(JobRegistry& registry, WorkerPool& pool, JobStore& store, const QueueSettings& settings)
    : registry_(registry), pool_(pool), store_(store), settings_(settings) {}

Janitor::~Janitor() {
  request_stop();
  join();
}

void Janitor::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (thread_.joinable() || stopping_) return;
  thread_ = std::thread([this] { loop(); });
}

void Janitor::request_stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
}

void Janitor::join() {
  if (thread_.joinable()) thread_.join();
}

void Janitor::retention_due() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    retention_due_ = true;
  }
  wake_.notify_all();
}

std::vector<std::string> Janitor::stuck() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stuck_;
}

std::int64_t Janitor::expired_total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return expired_total_;
}

void Janitor::loop() {
  using Clock = std::chrono::steady_clock;
  const auto interval = std::chrono::milliseconds(static_cast<std::int64_t>(settings_.janitor_interval_seconds * 1e3));
  auto next_retention = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, std::chrono::milliseconds(100));
    if (stopping_) break;
    const auto now = Clock::now();
    const bool retention = now >= next_retention || retention_due_;  // due after every job that finishes
    if (retention) {
      next_retention = now + interval;
      retention_due_ = false;
    }
    lock.unlock();
    watch_running(now);
    if (retention) {
      apply_retention();
      if (store_.reserve_used()) store_.restore_reserve();
    }
    lock.lock();
  }
}

void Janitor::watch_running(std::chrono::steady_clock::time_point now) {
  std::vector<std::string> stuck;
  // stuck_ is written by this thread only: read here without the lock.
  pool_.for_each_running([&](Job& job) {
    if (now >= job.lane_deadline && job.cancel_reason.load() == static_cast<int>(CancelReason::none)) {
      job.request_cancel(CancelReason::lane);
      log_line("job " + job.record.id + ": ran past the small-job lane's time; moving it to the general lane");
    }
    if (now >= job.deadline && job.cancel_reason.load() == static_cast<int>(CancelReason::none)) {
      job.request_cancel(CancelReason::time_limit);
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", settings_.time_limit_seconds);
      log_line("job " + job.record.id + ": time limit of " + limit + " s reached; stopping it");
    }
    // Told to stop (cancel, time limit, shutdown) and still running long after: its worker is stuck (a solve
    // that never reaches its next iteration). Reported by /readyz; the job cannot be stopped from here.
    if (job.cancel_reason.load() != static_cast<int>(CancelReason::none) &&
        now - job.cancel_requested_at > std::chrono::duration<double>(settings_.stuck_after_seconds)) {
      stuck.push_back(job.record.id);
      if (std::find(stuck_.begin(), stuck_.end(), job.record.id) == stuck_.end())
        log_line("job " + job.record.id + ": still running " + std::to_string(settings_.stuck_after_seconds) +
                 " s after it was told to stop: its worker is stuck");
    }
  });
  std::lock_guard<std::mutex> lock(mutex_);
  stuck_ = std::move(stuck);
}

void Janitor::apply_retention() {
  if (settings_.retention_seconds <= 0 && settings_.retention_bytes == 0) return;
  for (const auto& id : registry_.expired(settings_.retention_seconds, settings_.retention_bytes)) {
    std::string detail;
    if (registry_.remove(id, detail) == JobRegistry::RemoveOutcome::removed) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++expired_total_;
      log_line("retention: deleted job " + id);
    }
  }
}

}  // namespace contactd

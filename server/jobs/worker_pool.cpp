#include "jobs/worker_pool.hpp"

#include "common/log.hpp"
#include "common/time.hpp"

#include <algorithm>

namespace contactd {

WorkerPool::WorkerPool(JobRegistry& registry, int workers, double time_limit_seconds, Run run)
    : registry_(registry), workers_(workers), time_limit_seconds_(time_limit_seconds), run_(std::move(run)) {}

WorkerPool::~WorkerPool() {
  for (auto& t : threads_)
    if (t.joinable()) t.detach();  // shutdown() gave up on it; the process is exiting
}

void WorkerPool::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (started_) return;
  started_ = true;
  for (int i = 0; i < workers_; ++i) {
    ++workers_alive_;
    threads_.emplace_back([this] { worker_loop(); });
  }
}

bool WorkerPool::shutdown(std::chrono::milliseconds grace) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!stopping_) {
    stopping_ = true;
    for (const auto& job : running_) job->request_cancel(CancelReason::shutdown);
  }
  work_.notify_all();
  stop_.notify_all();
  const bool stopped = idle_.wait_for(lock, grace, [this] { return workers_alive_.load() == 0; });
  lock.unlock();
  if (stopped) {
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }
  return stopped;
}

bool WorkerPool::wait_for_stop(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return stop_.wait_for(lock, timeout, [this] { return stopping_.load(); });
}

void WorkerPool::enqueue(const std::shared_ptr<Job>& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!registry_.is_queued(*job) || stopping_) return;
  queue_.push_back(job);
  work_.notify_one();
}

JobRegistry::CancelStep WorkerPool::cancel(const std::string& id, std::shared_ptr<Job>& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto taken = [this](const Job& candidate) {
    return std::any_of(running_.begin(), running_.end(),
                       [&](const std::shared_ptr<Job>& held) { return held.get() == &candidate; });
  };
  const JobRegistry::CancelStep step = registry_.cancel_step(id, taken, job);
  if (step == JobRegistry::CancelStep::stop_run) {
    job->request_cancel(CancelReason::user);  // the solver stops within one iteration
  } else if (step == JobRegistry::CancelStep::withdraw) {
    // It never starts: a worker only takes a job it finds QUEUED in the queue, under this lock.
    queue_.erase(std::remove(queue_.begin(), queue_.end(), job), queue_.end());
  }
  return step;
}

void WorkerPool::restore_after_failed_cancel(const std::shared_ptr<Job>& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!registry_.cancel_failed(*job) || stopping_) return;
  // created_us never changes after a job is made: read without the registry's lock.
  const auto later = std::find_if(queue_.begin(), queue_.end(), [&](const std::shared_ptr<Job>& other) {
    return other->record.created_us > job->record.created_us;
  });
  queue_.insert(later, job);
  work_.notify_one();
}

JobRecord WorkerPool::snapshot(const Job& job, int& queue_position) const {
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord record = registry_.snapshot(job);
  queue_position = 0;
  if (record.state == JobState::queued) {
    int position = 1;
    for (const auto& waiting : queue_) {
      if (waiting.get() == &job) break;
      if (registry_.is_queued(*waiting)) ++position;
    }
    queue_position = position;
  }
  return record;
}

int WorkerPool::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(running_.size());
}

void WorkerPool::for_each_running(const std::function<void(Job&)>& visit) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& job : running_) visit(*job);
}

void WorkerPool::worker_loop() {
  while (const std::shared_ptr<Job> job = take()) {
    if (!store_running(job)) continue;
    try {
      run_(job);
    } catch (const std::exception& e) {  // a run handles the solver's failures; this is a bug or no memory
      log_line("job " + job->record.id + ": unexpected error: " + e.what());
    }
    release(job);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    --workers_alive_;
  }
  idle_.notify_all();
}

std::shared_ptr<Job> WorkerPool::take() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    work_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (stopping_) return nullptr;
    std::shared_ptr<Job> job = queue_.front();
    queue_.pop_front();
    if (!registry_.is_queued(*job)) continue;  // cancelled while waiting
    running_.push_back(job);  // from now on a cancel finds it among the running (its state says QUEUED)
    return job;
  }
}

// RUNNING is on disk before the API says so (not fsync'ed: whether a crash leaves QUEUED or RUNNING on disk, the
// job is queued again at start-up). False when the store cannot take the change (a full disk): the job waits at
// the front of the queue, and the worker a second.
bool WorkerPool::store_running(const std::shared_ptr<Job>& job) {
  const std::int64_t started = now_unix_us();
  const bool stored = registry_.commit(
      job,
      [started](JobRecord& r) {
        r.state = JobState::running;
        r.started_us = started;
        r.attempts += 1;
        r.iterations = 0;
        r.progress = nullptr;
        r.message.clear();
      },
      /*durable=*/false);
  std::unique_lock<std::mutex> lock(mutex_);
  if (!stored) {
    running_.erase(std::remove(running_.begin(), running_.end(), job), running_.end());
    if (registry_.is_queued(*job)) queue_.push_front(job);
    stop_.wait_for(lock, std::chrono::seconds(1), [this] { return stopping_.load(); });
    return false;
  }
  job->deadline = time_limit_seconds_ > 0
                      ? std::chrono::steady_clock::now() +
                            std::chrono::microseconds(static_cast<std::int64_t>(time_limit_seconds_ * 1e6))
                      : std::chrono::steady_clock::time_point::max();
  return true;
}

void WorkerPool::release(const std::shared_ptr<Job>& job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_.erase(std::remove(running_.begin(), running_.end(), job), running_.end());
  }
  idle_.notify_all();
}

}  // namespace contactd

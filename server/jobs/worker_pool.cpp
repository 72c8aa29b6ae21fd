#include "jobs/worker_pool.hpp"

#include "common/log.hpp"
#include "common/time.hpp"

#include "contact/solve.hpp"

#include <malloc.h>

#include <algorithm>
#include <cstdio>

namespace contactd {

WorkerPool::WorkerPool(JobRegistry& registry, int workers, int small_workers, double time_limit_seconds,
                       double small_job_seconds, Disk disk, Run run)
    : registry_(registry),
      workers_(workers),
      small_workers_(small_workers),
      time_limit_seconds_(time_limit_seconds),
      small_job_seconds_(small_job_seconds),
      disk_(std::move(disk)),
      run_(std::move(run)) {}

WorkerPool::~WorkerPool() {
  for (auto& t : threads_)
    if (t.joinable()) t.detach();  // shutdown() gave up on it; the process is exiting
}

void WorkerPool::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (started_) return;
  started_ = true;
  for (int i = 0; i < workers_ + small_workers_; ++i) {
    ++workers_alive_;
    const bool small_lane = i >= workers_;
    threads_.emplace_back([this, small_lane] { worker_loop(small_lane); });
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
  work_.notify_all();  // the lanes take different jobs: wake both
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
  work_.notify_all();  // the lanes take different jobs: wake both
}

JobRecord WorkerPool::snapshot(const Job& job, int& queue_position) const {
  std::lock_guard<std::mutex> lock(mutex_);
  JobRecord record = registry_.snapshot(job);
  queue_position = 0;
  if (record.state == JobState::queued) {
    // Stored QUEUED but not (yet) in the queue (a run moved out of the small lane, between its record's change and
    // its release) has no position: 0, not one past every job waiting.
    int position = 1;
    for (const auto& waiting : queue_) {
      if (waiting.get() == &job) {
        queue_position = position;
        break;
      }
      if (registry_.is_queued(*waiting)) ++position;
    }
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

void WorkerPool::worker_loop(bool small_lane) {
  while (const std::shared_ptr<Job> job = take(small_lane)) {
    if (!store_running(job, small_lane)) continue;
    try {
      run_(job);
    } catch (const std::exception& e) {  // a run handles the solver's failures; this is a bug or no memory
      log_line("job " + job->record.id + ": unexpected error: " + e.what());
    }
    // The run's meshes, fields and factorisations are freed: give the memory back to the system now rather than
    // keep it in the allocator's arenas until the next validation trims them (a job of 1000 load steps left the
    // server 2.3 GB larger after it ended).
    ::malloc_trim(0);
    release(job, small_lane);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    --workers_alive_;
  }
  idle_.notify_all();
}

namespace {

std::string megabytes(std::int64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

}  // namespace

WorkerPool::DiskRoom WorkerPool::disk_room() const {
  DiskRoom room;
  if (!disk_.free) return room;
  room.free = disk_.free();
  if (room.free < 0) return room;  // cannot be asked: nothing is held back
  room.known = true;
  // result_estimate is set before a job is queued and never changed: read without the registry's lock.
  for (const auto& running : running_)
    room.pending += std::max<std::int64_t>(0, running->record.result_estimate - disk_.used(running->record.id));
  return room;
}

bool WorkerPool::fits_on_disk(const Job& job, const DiskRoom& room, std::string& why) const {
  const std::int64_t needed = job.record.result_estimate, free = room.free, pending = room.pending;
  if (needed <= 0 || !room.known || needed <= free - pending) return true;
  why = "waiting for disk space: its result is estimated at " + megabytes(needed) + ", and the data directory has " +
        megabytes(free) + " free" +
        (pending > 0 ? ", of which the running jobs' results will take " + megabytes(pending) : std::string()) +
        "; it starts when there is room (free some, or delete finished jobs)";
  return false;
}

void WorkerPool::note_waiting(const std::shared_ptr<Job>& job, const std::string& why) {
  // Once a wait: its figures are those of when it began (stored again at every look, a full disk's state.json
  // would be rewritten every few seconds).
  if (!job->disk_wait.empty()) return;
  job->disk_wait = why;
  if (!registry_.commit(
          job, [&why](JobRecord& r) { r.message = why; }, /*durable=*/false))
    job->disk_wait.clear();  // not stored (the disk is full): said again at the next look
}

bool WorkerPool::general_lane_full() const {
  return general_running_ + contact::abandoned_background_work() >= workers_;
}

std::shared_ptr<Job> WorkerPool::take(bool small_lane) {
  std::unique_lock<std::mutex> lock(mutex_);
  // JobRecord::small is set before a job is queued and changed only while it is out of the queue (a run moved to the
  // general lane, before release() queues it again): read without the registry's lock.
  const auto mine = [small_lane](const std::shared_ptr<Job>& job) { return !small_lane || job->record.small; };
  while (true) {
    const auto ready = [&] {
      return stopping_ || (std::any_of(queue_.begin(), queue_.end(), mine) && (small_lane || !general_lane_full()));
    };
    // Abandoned factorisations end on their own threads, unannounced: while one holds back a job, a general worker
    // looks again every 100 ms; otherwise an enqueue, a release or the shutdown wakes it.
    if (!small_lane && contact::abandoned_background_work() > 0)
      work_.wait_for(lock, std::chrono::milliseconds(100), ready);
    else
      work_.wait(lock, ready);
    if (stopping_) return nullptr;
    if (!small_lane && general_lane_full()) continue;
    // The first of this lane's jobs whose result fits on the disk; the ones before it that do not are told why.
    auto it = queue_.end();
    const DiskRoom room = disk_room();
    for (auto candidate = queue_.begin(); candidate != queue_.end(); ++candidate) {
      if (!mine(*candidate)) continue;
      std::string why;
      if (fits_on_disk(**candidate, room, why)) {
        it = candidate;
        break;
      }
      note_waiting(*candidate, why);
    }
    if (it == queue_.end()) {
      if (std::any_of(queue_.begin(), queue_.end(), mine))  // all held back by the disk: look again in a while
        stop_.wait_for(lock, std::chrono::seconds(2), [this] { return stopping_.load(); });
      continue;
    }
    std::shared_ptr<Job> job = *it;
    queue_.erase(it);
    if (!registry_.is_queued(*job)) continue;  // cancelled while waiting
    running_.push_back(job);  // from now on a cancel finds it among the running (its state says QUEUED)
    general_running_ += small_lane ? 0 : 1;
    return job;
  }
}

// RUNNING is on disk before the API says so (not fsync'ed: whether a crash leaves QUEUED or RUNNING on disk, the
// job is queued again at start-up). False when the store cannot take the change (a full disk): the job waits at
// the front of the queue, and the worker a second.
bool WorkerPool::store_running(const std::shared_ptr<Job>& job, bool small_lane) {
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
    general_running_ -= small_lane ? 0 : 1;
    if (registry_.is_queued(*job)) queue_.push_front(job);
    stop_.wait_for(lock, std::chrono::seconds(1), [this] { return stopping_.load(); });
    return false;
  }
  const auto after = [](double seconds) {
    return seconds > 0
               ? std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<std::int64_t>(seconds * 1e6))
               : std::chrono::steady_clock::time_point::max();
  };
  job->deadline = after(time_limit_seconds_);
  job->disk_wait.clear();
  job->lane_deadline = small_lane ? after(small_job_seconds_) : std::chrono::steady_clock::time_point::max();
  return true;
}

void WorkerPool::release(const std::shared_ptr<Job>& job, bool small_lane) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_.erase(std::remove(running_.begin(), running_.end(), job), running_.end());
    general_running_ -= small_lane ? 0 : 1;
    job->lane_deadline = std::chrono::steady_clock::time_point::max();
    // Moved out of the small lane (its run stored it QUEUED and no longer small): first in line for a general
    // worker, where it would have been had it not been classed small.
    if (job->cancel_reason.load() == static_cast<int>(CancelReason::lane) && registry_.is_queued(*job)) {
      job->cancel_reason.store(static_cast<int>(CancelReason::none));
      job->cancel.reset();
      queue_.push_front(job);
    }
  }
  idle_.notify_all();
  work_.notify_all();  // a general worker may have waited for room
}

}  // namespace contactd

// The queue's life cycle: submission, cancellation, deletion, listing, and the state changes (commit) they all
// go through. The workers and a run's outcome are in job_worker.cpp; start-up recovery and the store's health in
// job_recovery.cpp; the watchdog (time limits, stuck jobs, retention) in job_janitor.cpp.
#include "job_queue.hpp"

#include "events.hpp"
#include "util.hpp"

#include <algorithm>
#include <string_view>

namespace contactd {

namespace {

std::size_t hash_body(const std::string& body) { return std::hash<std::string_view>{}(body); }

}  // namespace

JobQueue::JobQueue(JobStore& store, Metrics& metrics, BodyBudget& budget, QueueSettings settings)
    : store_(store), metrics_(metrics), budget_(budget), settings_(settings) {}

JobQueue::~JobQueue() {
  shutdown(std::chrono::milliseconds(0));
  for (auto& t : threads_)
    if (t.joinable()) t.detach();  // shutdown() gave up on it; the process is exiting
  if (watchdog_thread_.joinable()) watchdog_thread_.join();
}

std::shared_ptr<Job> JobQueue::make_job(const JobRecord& record) {
  auto job = std::make_shared<Job>(record, store_.events_path(record.id), settings_.max_event_log_bytes);
  const std::string id = record.id;
  job->events.on_damage([this, id](const std::string& problem) { report_damage(id, problem); });
  return job;
}

void JobQueue::set_state_locked(Job& job, JobState state) {
  --state_counts_[static_cast<std::size_t>(job.record.state)];
  job.record.state = state;
  ++state_counts_[static_cast<std::size_t>(state)];
}

void JobQueue::register_locked(const std::shared_ptr<Job>& job) {
  const JobRecord& r = job->record;
  jobs_[r.id] = job;
  by_time_[{r.created_us, r.id}] = job;
  if (!r.idempotency_key.empty()) by_key_[r.idempotency_key] = r.id;
  ++state_counts_[static_cast<std::size_t>(r.state)];
  last_created_us_ = std::max(last_created_us_, r.created_us);
}

void JobQueue::unregister_locked(const std::shared_ptr<Job>& job) {
  const JobRecord& r = job->record;
  jobs_.erase(r.id);
  by_time_.erase({r.created_us, r.id});
  if (by_finished_.erase({r.finished_us, r.id}) > 0) finished_bytes_ -= job->disk_bytes;
  const auto key = by_key_.find(r.idempotency_key);
  if (key != by_key_.end() && key->second == r.id) by_key_.erase(key);
  body_hash_.erase(r.id);
  --state_counts_[static_cast<std::size_t>(r.state)];
}

void JobQueue::note_finished_locked(const std::shared_ptr<Job>& job) {
  if (by_finished_.emplace(TimeKey{job->record.finished_us, job->record.id}, job).second)
    finished_bytes_ += job->disk_bytes;
}

bool JobQueue::commit(const std::shared_ptr<Job>& job, const Change& change, bool durable, std::string* error) {
  std::lock_guard<std::mutex> persist_lock(job->persist_mutex);
  JobRecord next;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    next = job->record;
  }
  change(next);
  try {
    store_.save_state(next, durable);
  } catch (const std::exception& e) {
    log_line("job " + next.id + ": cannot store its state " + to_string(next.state) + ": " + e.what());
    if (error) *error = public_message(e.what(), store_.data_dir());
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  set_state_locked(*job, next.state);
  change(job->record);  // the same change on the live record (the observer may have moved its progress on)
  return true;
}

bool JobQueue::commit_patiently(const std::shared_ptr<Job>& job, const Change& change) {
  for (int attempt = 0;; ++attempt) {
    if (commit(job, change, /*durable=*/true)) return true;
    if (attempt == 0) log_line("job " + job->record.id + ": retrying every second until its outcome can be stored");
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (watchdog_.wait_for(lock, std::chrono::seconds(1), [this] { return stopping_; })) return false;
    }
    store_.restore_reserve();
  }
}

void JobQueue::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (started_) return;
  started_ = true;
  for (int i = 0; i < settings_.workers; ++i) {
    ++workers_alive_;
    threads_.emplace_back([this] { worker_loop(); });
  }
  watchdog_thread_ = std::thread([this] { watchdog_loop(); });
}

bool JobQueue::shutdown(std::chrono::milliseconds grace) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!stopping_) {
    stopping_ = true;
    for (const auto& job : running_) job->request_cancel(CancelReason::shutdown);
  }
  work_.notify_all();
  watchdog_.notify_all();
  const bool stopped = idle_.wait_for(lock, grace, [this] { return workers_alive_.load() == 0; });
  lock.unlock();
  if (stopped) {
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }
  if (watchdog_thread_.joinable()) watchdog_thread_.join();
  return stopped;
}

bool JobQueue::stopping() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stopping_;
}

void JobQueue::mark_settled(const std::shared_ptr<Job>& job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job->settled = true;
    note_finished_locked(job);
    retention_due_ = true;
  }
  settled_.notify_all();
  watchdog_.notify_all();
}

contact::job::ParseResult JobQueue::validate(const std::string& body) const {
  contact::job::Limits limits;
  limits.max_dofs = settings_.max_dofs;
  limits.max_bodies = settings_.max_bodies;
  limits.max_contacts = settings_.max_contacts;
  limits.max_ranks = settings_.mpi.launcher.empty() ? 1 : settings_.mpi.max_ranks;
  limits.ranks_hint = settings_.mpi.launcher.empty()
                          ? "this server solves every job in its own process: it was started without --mpi-launcher"
                          : "contactd --max-ranks";
  return contact::job::parse_text(body, limits);
}

JobQueue::Submission JobQueue::submit(const std::string& body, contact::job::ParseResult parsed,
                                      const std::string& idempotency_key) {
  Submission submission;
  if (!parsed.ok()) {
    submission.outcome = Submission::Outcome::invalid;
    submission.errors = std::move(parsed.errors);
    return submission;
  }
  const std::size_t hash = hash_body(body);

  std::unique_lock<std::mutex> lock(mutex_);
  if (!idempotency_key.empty()) {
    const auto known = by_key_.find(idempotency_key);
    if (known != by_key_.end()) {
      const auto found = jobs_.find(known->second);
      if (found == jobs_.end()) {  // the job of this key is damaged (its state.json cannot be read)
        submission.outcome = Submission::Outcome::key_damaged;
        submission.detail = known->second;
        return submission;
      }
      const auto job = found->second;
      const auto h = body_hash_.find(known->second);
      const bool same = h != body_hash_.end() && h->second == hash &&
                        job->record.body_bytes == static_cast<std::int64_t>(body.size());
      lock.unlock();
      if (same && !job->stored) {
        // Another request with this key is storing it now: wait for it (it holds the job's persist lock).
        std::lock_guard<std::mutex> wait(job->persist_mutex);
        if (!job->stored) {
          submission.outcome = Submission::Outcome::store_error;
          submission.detail = "the job could not be stored";
          return submission;
        }
      }
      submission.outcome = same ? Submission::Outcome::replayed : Submission::Outcome::key_conflict;
      submission.job = job;
      return submission;
    }
  }
  if (stopping_) {
    submission.outcome = Submission::Outcome::unavailable;
    return submission;
  }
  if (static_cast<std::size_t>(state_counts_[static_cast<std::size_t>(JobState::queued)]) >= settings_.max_queued) {
    submission.outcome = Submission::Outcome::queue_full;
    return submission;
  }
  JobRecord record;
  record.id = new_job_id();
  record.name = parsed.problem->name;
  record.state = JobState::queued;
  record.created_us = std::max(now_unix_us(), last_created_us_ + 1);  // strictly increasing: a total order
  record.idempotency_key = idempotency_key;
  record.body_bytes = static_cast<std::int64_t>(body.size());
  auto job = make_job(record);
  // Held until the files exist: anyone persisting this job (a cancel) waits for them. Registered (for the key)
  // but invisible to the API (find, list) until stored.
  std::unique_lock<std::mutex> persist_lock(job->persist_mutex);
  register_locked(job);
  if (!idempotency_key.empty()) body_hash_[record.id] = hash;
  lock.unlock();

  try {
    store_.create(record, body);
  } catch (const std::exception& e) {
    log_line("job " + record.id + ": not accepted: " + e.what());
    lock.lock();
    unregister_locked(job);
    submission.outcome = Submission::Outcome::store_error;
    submission.detail = public_message(e.what(), store_.data_dir());
    return submission;
  }
  job->stored = true;
  job->events.append("state", state_event(JobState::queued, "accepted", 0));
  persist_lock.unlock();
  metrics_.job_submitted();

  lock.lock();
  if (job->record.state == JobState::queued && !stopping_) {
    queue_.push_back(job);
    work_.notify_one();
  }
  submission.outcome = Submission::Outcome::accepted;
  submission.job = job;
  return submission;
}

std::shared_ptr<Job> JobQueue::find(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = jobs_.find(id);
  return it == jobs_.end() || !it->second->stored ? nullptr : it->second;
}

JobRecord JobQueue::snapshot(const Job& job, int* queue_position) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (queue_position) {
    *queue_position = 0;
    if (job.record.state == JobState::queued) {
      int position = 1;
      for (const auto& waiting : queue_) {
        if (waiting.get() == &job) break;
        if (waiting->record.state == JobState::queued) ++position;
      }
      *queue_position = position;
    }
  }
  return job.record;
}

JobQueue::CancelOutcome JobQueue::cancel(const std::string& id) {
  std::shared_ptr<Job> job;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = jobs_.find(id);
    if (it == jobs_.end() || !it->second->stored) return CancelOutcome::not_found;
    job = it->second;
    const bool taken = std::find(running_.begin(), running_.end(), job) != running_.end();
    switch (job->record.state) {
      case JobState::running:
        job->request_cancel(CancelReason::user);  // the solver stops within one iteration
        return CancelOutcome::cancelling;
      case JobState::cancelled:
        return CancelOutcome::already_cancelled;
      case JobState::succeeded:
      case JobState::failed:
        return CancelOutcome::already_done;
      case JobState::queued:
        if (taken) {  // a worker is storing it as RUNNING: stopped as soon as it starts
          job->request_cancel(CancelReason::user);
          return CancelOutcome::cancelling;
        }
        // Another cancel is storing CANCELLED: one request stores it (a second write could come after a DELETE
        // that followed the first, into a directory that is gone).
        if (job->cancelling_queued) return CancelOutcome::cancelling;
        break;
    }
    // Queued: it never starts. (A worker only takes a job it finds QUEUED under this same lock.)
    queue_.erase(std::remove(queue_.begin(), queue_.end(), job), queue_.end());
    job->cancelling_queued = true;
  }
  const std::int64_t now = now_unix_us();
  const bool stored = commit(job, [now](JobRecord& r) {
    r.state = JobState::cancelled;
    r.finished_us = now;
    r.stop_reason = "cancelled";
    r.message = "cancelled before it started";
    r.converged = false;
  }, /*durable=*/true);
  if (!stored) {
    std::lock_guard<std::mutex> lock(mutex_);
    job->cancelling_queued = false;
    if (job->record.state == JobState::queued && !stopping_) {  // still queued, in its place by creation time
      const auto later = std::find_if(queue_.begin(), queue_.end(), [&](const std::shared_ptr<Job>& other) {
        return other->record.created_us > job->record.created_us;
      });
      queue_.insert(later, job);
      work_.notify_one();
    }
    return CancelOutcome::store_error;
  }
  JobRecord after = snapshot(*job);
  job->events.append("end", end_event(after));
  job->events.sync_and_close();
  const std::int64_t bytes = store_.disk_usage(id);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job->disk_bytes = bytes;
  }
  mark_settled(job);
  log_line("job " + id + ": cancelled while queued");
  return CancelOutcome::cancelled;
}

JobQueue::RemoveOutcome JobQueue::remove(const std::string& id, std::string& detail) {
  std::shared_ptr<Job> job;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto damaged = damaged_.find(id);
    if (damaged != damaged_.end() && jobs_.count(id) == 0) {
      // A job whose state cannot be read: deleting it is the way to clear it. Taken out of the registry first,
      // so that a concurrent DELETE finds nothing to remove (404) rather than a directory already gone.
      const std::string problem = damaged->second;
      damaged_.erase(damaged);
      lock.unlock();
      try {
        store_.remove(id);
      } catch (const std::exception& e) {
        detail = public_message(e.what(), store_.data_dir());
        lock.lock();
        damaged_.emplace(id, problem);
        return RemoveOutcome::store_error;
      }
      lock.lock();
      for (auto it = by_key_.begin(); it != by_key_.end();)
        it = it->second == id ? by_key_.erase(it) : std::next(it);
      log_line("job " + id + ": deleted (it was damaged)");
      return RemoveOutcome::removed;
    }
    const auto it = jobs_.find(id);
    if (it == jobs_.end() || !it->second->stored) return RemoveOutcome::not_found;
    job = it->second;
    if (!is_terminal(job->record.state)) return RemoveOutcome::not_done;
    // A terminal job whose `end` event is still being written (a client that saw `end` may delete at once):
    // wait for it briefly rather than answer 409.
    if (!settled_.wait_for(lock, std::chrono::seconds(5), [&] { return job->settled.load(); }))
      return RemoveOutcome::not_done;
    // The wait let go of the lock: another DELETE (or retention) may have removed the job meanwhile.
    const auto still = jobs_.find(id);
    if (still == jobs_.end() || still->second != job) return RemoveOutcome::not_found;
    unregister_locked(job);
    damaged_.erase(id);
  }
  job->events.discard();  // open streams end
  std::lock_guard<std::mutex> persist_lock(job->persist_mutex);
  try {
    store_.remove(id);
  } catch (const std::exception& e) {
    detail = public_message(e.what(), store_.data_dir());
    log_line("job " + id + ": " + e.what());
    return RemoveOutcome::store_error;
  }
  log_line("job " + id + ": deleted");
  return RemoveOutcome::removed;
}

JobQueue::Page JobQueue::list(std::optional<JobState> state, std::size_t page_size,
                              const std::optional<Cursor>& after) const {
  Page page;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = after ? by_time_.lower_bound({after->created_us, after->id}) : by_time_.end();
  while (it != by_time_.begin()) {
    --it;
    const JobRecord& r = it->second->record;
    if (!it->second->stored || (state && r.state != *state)) continue;
    if (page.jobs.size() == page_size) {  // one more exists: this page is full and another follows
      const JobRecord& last = page.jobs.back();
      page.next = Cursor{last.created_us, last.id};
      break;
    }
    page.jobs.push_back(r);
  }
  return page;
}

JobCounts JobQueue::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  JobCounts counts;
  counts.by_state = state_counts_;
  counts.queue_length = state_counts_[static_cast<std::size_t>(JobState::queued)];
  return counts;
}

int JobQueue::workers_busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(running_.size());
}

}  // namespace contactd

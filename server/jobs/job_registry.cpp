#include "jobs/job_registry.hpp"

#include "common/job_id.hpp"
#include "common/log.hpp"
#include "common/public_message.hpp"
#include "common/time.hpp"

#include <algorithm>

namespace contactd {

JobRegistry::JobRegistry(JobStore& store, std::uint64_t max_event_log_bytes)
    : store_(store), max_event_log_bytes_(max_event_log_bytes) {}

std::shared_ptr<Job> JobRegistry::make_job(const JobRecord& record) {
  auto job = std::make_shared<Job>(record, store_.events_path(record.id), max_event_log_bytes_);
  const std::string id = record.id;
  job->events.on_damage([this, id](const std::string& problem) { report_damage(id, problem); });
  return job;
}

void JobRegistry::set_state_locked(Job& job, JobState state) {
  --state_counts_[static_cast<std::size_t>(job.record.state)];
  job.record.state = state;
  ++state_counts_[static_cast<std::size_t>(state)];
}

void JobRegistry::register_locked(const std::shared_ptr<Job>& job) {
  const JobRecord& r = job->record;
  jobs_[r.id] = job;
  by_time_[{r.created_us, r.id}] = job;
  if (!r.idempotency_key.empty()) by_key_[r.idempotency_key] = r.id;
  ++state_counts_[static_cast<std::size_t>(r.state)];
  last_created_us_ = std::max(last_created_us_, r.created_us);
}

void JobRegistry::unregister_locked(const std::shared_ptr<Job>& job) {
  const JobRecord& r = job->record;
  jobs_.erase(r.id);
  by_time_.erase({r.created_us, r.id});
  if (by_finished_.erase({r.finished_us, r.id}) > 0) finished_bytes_ -= job->disk_bytes;
  const auto key = by_key_.find(r.idempotency_key);
  if (key != by_key_.end() && key->second == r.id) by_key_.erase(key);
  body_hash_.erase(r.id);
  --state_counts_[static_cast<std::size_t>(r.state)];
}

void JobRegistry::note_finished_locked(const std::shared_ptr<Job>& job) {
  if (by_finished_.emplace(TimeKey{job->record.finished_us, job->record.id}, job).second)
    finished_bytes_ += job->disk_bytes;
}

JobRegistry::Admission JobRegistry::admit(const std::string& name, const std::string& idempotency_key,
                                          std::size_t body_hash, std::int64_t body_bytes, bool stopping,
                                          std::size_t max_queued) {
  Admission admission;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!idempotency_key.empty()) {
    const auto known = by_key_.find(idempotency_key);
    if (known != by_key_.end()) {
      const auto found = jobs_.find(known->second);
      if (found == jobs_.end()) {  // the job of this key is damaged (its state.json cannot be read)
        admission.outcome = Admission::Outcome::key_damaged;
        admission.damaged_id = known->second;
        return admission;
      }
      admission.outcome = Admission::Outcome::existing;
      admission.job = found->second;
      const auto h = body_hash_.find(known->second);
      admission.same_body =
          h != body_hash_.end() && h->second == body_hash && admission.job->record.body_bytes == body_bytes;
      return admission;
    }
  }
  if (stopping) {
    admission.outcome = Admission::Outcome::unavailable;
    return admission;
  }
  if (static_cast<std::size_t>(state_counts_[static_cast<std::size_t>(JobState::queued)]) >= max_queued) {
    admission.outcome = Admission::Outcome::queue_full;
    return admission;
  }
  JobRecord record;
  record.id = new_job_id();
  record.name = name;
  record.state = JobState::queued;
  record.created_us = std::max(now_unix_us(), last_created_us_ + 1);  // strictly increasing: a total order
  record.idempotency_key = idempotency_key;
  record.body_bytes = body_bytes;
  admission.outcome = Admission::Outcome::admitted;
  admission.job = make_job(record);
  // Held until the files exist: anyone persisting this job (a cancel) waits for them. Registered (for the key)
  // but invisible to the API (find, list) until stored.
  admission.persisting = std::unique_lock<std::mutex>(admission.job->persist_mutex);
  register_locked(admission.job);
  if (!idempotency_key.empty()) body_hash_[record.id] = body_hash;
  return admission;
}

void JobRegistry::forget(const std::shared_ptr<Job>& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  unregister_locked(job);
}

void JobRegistry::add_recovered(const std::shared_ptr<Job>& job, std::optional<std::size_t> body_hash) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (body_hash) body_hash_[job->record.id] = *body_hash;
  register_locked(job);
}

void JobRegistry::add_damaged(const std::vector<JobStore::Damaged>& damaged) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& d : damaged) {
    damaged_[d.id] = d.problem;
    if (!d.idempotency_key.empty()) by_key_[d.idempotency_key] = d.id;
  }
}

std::shared_ptr<Job> JobRegistry::find(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = jobs_.find(id);
  return it == jobs_.end() || !it->second->stored ? nullptr : it->second;
}

JobRecord JobRegistry::snapshot(const Job& job) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return job.record;
}

bool JobRegistry::is_queued(const Job& job) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return job.record.state == JobState::queued;
}

bool JobRegistry::commit(const std::shared_ptr<Job>& job, const Change& change, bool durable, std::string* error) {
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

void JobRegistry::update_progress(Job& job, int iterations, nlohmann::json summary) {
  std::lock_guard<std::mutex> lock(mutex_);
  job.record.iterations = iterations;
  job.record.progress = std::make_shared<const nlohmann::json>(std::move(summary));
}

JobRecord JobRegistry::count_outcome(Job& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  job.disk_bytes = 0;
  events_dropped_total_ += job.record.events_dropped;
  return job.record;
}

void JobRegistry::settle(const std::shared_ptr<Job>& job, std::optional<std::int64_t> disk_bytes) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (disk_bytes) job->disk_bytes = *disk_bytes;
    job->settled = true;
    note_finished_locked(job);
  }
  settled_.notify_all();
}

JobRegistry::CancelStep JobRegistry::cancel_step(const std::string& id, const std::function<bool(const Job&)>& taken,
                                                 std::shared_ptr<Job>& found) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = jobs_.find(id);
  if (it == jobs_.end() || !it->second->stored) return CancelStep::not_found;
  found = it->second;
  Job& job = *found;
  switch (job.record.state) {
    case JobState::running:
      return CancelStep::stop_run;
    case JobState::cancelled:
      return CancelStep::already_cancelled;
    case JobState::succeeded:
    case JobState::failed:
      return CancelStep::already_done;
    case JobState::queued:
      break;
  }
  if (taken(job)) return CancelStep::stop_run;  // a worker is storing it as RUNNING: stopped as soon as it starts
  // Another cancel is storing CANCELLED: one request stores it (a second write could come after a DELETE that
  // followed the first, into a directory that is gone).
  if (job.cancelling_queued) return CancelStep::in_progress;
  job.cancelling_queued = true;
  return CancelStep::withdraw;
}

bool JobRegistry::cancel_failed(Job& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  job.cancelling_queued = false;
  return job.record.state == JobState::queued;
}

JobRegistry::RemoveOutcome JobRegistry::remove_damaged_locked(std::unique_lock<std::mutex>& lock, const std::string& id,
                                                              std::string& detail) {
  // A job whose state cannot be read: deleting it is the way to clear it. Taken out of the registry first, so
  // that a concurrent DELETE finds nothing to remove (404) rather than a directory already gone.
  const auto damaged = damaged_.find(id);
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
  for (auto it = by_key_.begin(); it != by_key_.end();) it = it->second == id ? by_key_.erase(it) : std::next(it);
  log_line("job " + id + ": deleted (it was damaged)");
  return RemoveOutcome::removed;
}

JobRegistry::RemoveOutcome JobRegistry::remove(const std::string& id, std::string& detail) {
  std::shared_ptr<Job> job;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (damaged_.count(id) && jobs_.count(id) == 0) return remove_damaged_locked(lock, id, detail);
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

JobRegistry::Page JobRegistry::list(std::optional<JobState> state, std::size_t page_size,
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

JobCounts JobRegistry::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  JobCounts counts;
  counts.by_state = state_counts_;
  counts.queue_length = state_counts_[static_cast<std::size_t>(JobState::queued)];
  return counts;
}

std::vector<std::string> JobRegistry::expired(double max_age_seconds, std::uint64_t max_bytes) const {
  std::vector<std::string> doomed;
  std::lock_guard<std::mutex> lock(mutex_);
  const std::int64_t now = now_unix_us();
  std::int64_t bytes = finished_bytes_;
  for (const auto& [key, job] : by_finished_) {  // oldest first
    if (damaged_.count(key.second)) continue;    // left for the operator to look at
    const bool too_old = max_age_seconds > 0 && now - key.first > static_cast<std::int64_t>(max_age_seconds * 1e6);
    const bool too_much = max_bytes > 0 && bytes > static_cast<std::int64_t>(max_bytes);
    if (!too_old && !too_much) break;
    doomed.push_back(key.second);
    bytes -= job->disk_bytes;
  }
  return doomed;
}

std::optional<std::string> JobRegistry::damage(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = damaged_.find(id);
  if (it == damaged_.end()) return std::nullopt;
  return it->second;
}

void JobRegistry::report_damage(const std::string& id, const std::string& problem) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto [it, inserted] = damaged_.emplace(id, problem);
  if (inserted) log_line("store: job " + id + " is damaged: " + problem);
}

std::vector<std::pair<std::string, std::string>> JobRegistry::damaged() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {damaged_.begin(), damaged_.end()};
}

std::int64_t JobRegistry::events_dropped_total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_dropped_total_;
}

}  // namespace contactd

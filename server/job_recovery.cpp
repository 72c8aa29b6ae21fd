// Start-up recovery of the job store, and the registry of damage found in it (docs/server.md, "Data directory"
// and "Health, readiness and metrics").
#include "job_queue.hpp"

#include "events.hpp"
#include "util.hpp"

#include <algorithm>
#include <functional>
#include <string_view>

namespace contactd {

void JobQueue::recover() {
  JobStore::Contents contents = store_.load_all();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& d : contents.damaged) {
      damaged_[d.id] = d.problem;
      // Its key stays taken: a retry with it must not create a second job.
      if (!d.idempotency_key.empty()) by_key_[d.idempotency_key] = d.id;
    }
  }
  int requeued = 0;
  for (const JobRecord& loaded : contents.jobs) recover_job(make_job(loaded), requeued);
  log_line("store: " + std::to_string(contents.jobs.size()) + " jobs read back from " + store_.data_dir() + ", " +
           std::to_string(requeued) + " queued to run" +
           (contents.damaged.empty() ? std::string() : ", " + std::to_string(contents.damaged.size()) + " damaged"));
}

void JobQueue::recover_job(const std::shared_ptr<Job>& job, int& requeued) {
  job->stored = true;
  job->events.load();
  const std::string id = job->record.id;
  if (const std::string problem = job->events.problem(); !problem.empty()) report_damage(id, problem);
  if (!job->record.idempotency_key.empty()) {
    try {
      const std::string body = store_.read_job(id);
      std::lock_guard<std::mutex> lock(mutex_);
      body_hash_[id] = std::hash<std::string_view>{}(body);
    } catch (const std::exception& e) {
      log_line("job " + id + ": " + e.what());
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    register_locked(job);
  }
  JobRecord& r = job->record;
  if (is_terminal(r.state)) {
    if (r.result_available)
      if (auto problem = store_.check_result(r)) report_damage(id, *problem);
    if (job->events.last_type() != "end") {  // crashed between storing the outcome and announcing it
      job->events.append("end", end_event(r));
      job->events.sync_and_close();
    }
    const std::int64_t bytes = store_.disk_usage(id);
    std::lock_guard<std::mutex> lock(mutex_);
    job->settled = true;
    job->disk_bytes = bytes;
    note_finished_locked(job);
    return;
  }
  if (r.state == JobState::running) {
    // Its run was cut short by the server dying (a crash, kill -9, running out of memory). A job that does that
    // every time would do it at every start: after max_attempts such runs it ends FAILED.
    store_.remove_result(id);  // of the interrupted run, if it got that far
    const int interruptions = r.interruptions + 1;
    if (interruptions >= settings_.max_attempts) {
      const std::string message = "interrupted " + std::to_string(interruptions) +
                                  " times: the server stopped (crashed, was killed or ran out of memory) while it "
                                  "ran; it is not run again";
      const std::int64_t now = now_unix_us();
      std::string error;
      if (!commit(job, [&](JobRecord& x) {
            x.state = JobState::failed;
            x.interruptions = interruptions;
            x.finished_us = now;
            x.stop_reason = "interrupted";
            x.message = message;
            x.converged = false;
            x.result_available = false;
            x.progress = nullptr;
          }, /*durable=*/true, &error))
        throw std::runtime_error("cannot store the state of job " + id + ": " + error);
      job->events.append("end", end_event(snapshot(*job)));
      job->events.sync_and_close();
      log_line("job " + id + ": " + message);
      std::lock_guard<std::mutex> lock(mutex_);
      job->settled = true;
      note_finished_locked(job);
      return;
    }
    const std::string message = "re-queued: its run was interrupted (the server stopped)";
    std::string error;
    if (!commit(job, [&](JobRecord& x) {
          x.state = JobState::queued;
          x.interruptions = interruptions;
          x.started_us = 0;
          x.iterations = 0;
          x.progress = nullptr;
          x.message = message;
        }, /*durable=*/true, &error))
      throw std::runtime_error("cannot store the state of job " + id + ": " + error);
    job->events.append("state", state_event(JobState::queued, message, r.attempts));
    job->events.sync_and_close();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  queue_.push_back(job);
  ++requeued;
}

std::optional<std::string> JobQueue::damage(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = damaged_.find(id);
  if (it == damaged_.end()) return std::nullopt;
  return it->second;
}

void JobQueue::report_damage(const std::string& id, const std::string& problem) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto [it, inserted] = damaged_.emplace(id, problem);
  if (inserted) log_line("store: job " + id + " is damaged: " + problem);
}

QueueHealth JobQueue::health() const {
  std::lock_guard<std::mutex> lock(mutex_);
  QueueHealth h;
  h.damaged.assign(damaged_.begin(), damaged_.end());
  h.stuck = stuck_;
  h.expired_total = expired_total_;
  h.events_dropped_total = events_dropped_total_;
  return h;
}

}  // namespace contactd

// The facade's own work: wiring the parts together, and what spans several of them (a submission, a cancel).
#include "jobs/job_queue.hpp"

#include "common/log.hpp"
#include "common/public_message.hpp"
#include "common/time.hpp"
#include "contact/warning.hpp"
#include "jobs/events.hpp"
#include "jobs/job_recovery.hpp"

#include <string_view>

namespace contactd {

namespace {

std::size_t hash_body(const std::string& body) { return std::hash<std::string_view>{}(body); }

}  // namespace

JobQueue::JobQueue(JobStore& store, Metrics& metrics, BodyBudget& budget, QueueSettings settings)
    : settings_(std::move(settings)),
      store_(store),
      metrics_(metrics),
      registry_(store, settings_.max_event_log_bytes),
      pool_(registry_, settings_.workers, settings_.small_workers, settings_.time_limit_seconds,
            settings_.small_job_seconds,
            WorkerPool::Disk{[&store] { return store.free_bytes(); },
                             [&store](const std::string& id) { return store.disk_usage(id); }},
            [this](const std::shared_ptr<Job>& job) { JobRun(run_context_, job).execute(); }),
      janitor_(registry_, pool_, store, settings_),
      run_context_{registry_,
                   store,
                   metrics,
                   budget,
                   settings_,
                   [this](std::chrono::milliseconds timeout) { return pool_.wait_for_stop(timeout); },
                   [this] { janitor_.retention_due(); }} {}

JobQueue::~JobQueue() { shutdown(std::chrono::milliseconds(0)); }

void JobQueue::recover() { JobRecovery(run_context_, pool_).run(); }

void JobQueue::start() {
  pool_.start();
  janitor_.start();
}

bool JobQueue::shutdown(std::chrono::milliseconds grace) {
  janitor_.request_stop();
  const bool stopped = pool_.shutdown(grace);
  janitor_.join();
  return stopped;
}

JobQueue::Submission JobQueue::submit(const std::string& body, contact::job::ParseResult parsed,
                                      const std::string& idempotency_key) {
  Submission submission;
  if (!parsed.ok()) {
    submission.outcome = Submission::Outcome::invalid;
    submission.errors = std::move(parsed.errors);
    return submission;
  }
  JobRegistry::Admission admission =
      registry_.admit(parsed.problem->name, idempotency_key, hash_body(body), static_cast<std::int64_t>(body.size()),
                      pool_.stopping(), settings_.max_queued);
  using Admitted = JobRegistry::Admission::Outcome;
  switch (admission.outcome) {
    case Admitted::existing:
      return replay(admission);
    case Admitted::key_damaged:
      submission.outcome = Submission::Outcome::key_damaged;
      submission.detail = admission.damaged_id;
      return submission;
    case Admitted::unavailable:
      submission.outcome = Submission::Outcome::unavailable;
      return submission;
    case Admitted::queue_full:
      submission.outcome = Submission::Outcome::queue_full;
      return submission;
    case Admitted::admitted:
      break;
  }
  const std::shared_ptr<Job> job = admission.job;
  job->record.small = small_job(settings_, *parsed.problem);  // not yet visible: nobody reads it concurrently
  job->record.result_estimate = estimated_result(*parsed.problem);
  job->record.warnings = contact::warnings_json(parsed.warnings);
  const JobRecord record = job->record;  // nobody changes it before it is stored (persist lock held)
  try {
    store_.create(record, body);
  } catch (const std::exception& e) {
    log_line("job " + record.id + ": not accepted: " + e.what());
    registry_.forget(job);
    submission.outcome = Submission::Outcome::store_error;
    submission.detail = public_message(e.what(), store_.data_dir());
    return submission;
  }
  job->stored = true;
  job->events.append("state", state_event(JobState::queued, "accepted", 0));
  admission.persisting.unlock();
  metrics_.job_submitted();
  pool_.enqueue(job);
  submission.outcome = Submission::Outcome::accepted;
  submission.job = job;
  return submission;
}

JobQueue::Submission JobQueue::replay(const JobRegistry::Admission& admission) const {
  Submission submission;
  const std::shared_ptr<Job>& job = admission.job;
  if (admission.same_body && !job->stored) {
    // Another request with this key is storing it now: wait for it (it holds the job's persist lock).
    std::lock_guard<std::mutex> wait(job->persist_mutex);
    if (!job->stored) {
      submission.outcome = Submission::Outcome::store_error;
      submission.detail = "the job could not be stored";
      return submission;
    }
  }
  submission.outcome = admission.same_body ? Submission::Outcome::replayed : Submission::Outcome::key_conflict;
  submission.job = job;
  return submission;
}

JobRecord JobQueue::snapshot(const Job& job, int* queue_position) const {
  return queue_position ? pool_.snapshot(job, *queue_position) : registry_.snapshot(job);
}

JobQueue::CancelOutcome JobQueue::cancel(const std::string& id) {
  std::shared_ptr<Job> job;
  switch (pool_.cancel(id, job)) {
    case JobRegistry::CancelStep::not_found:
      return CancelOutcome::not_found;
    case JobRegistry::CancelStep::stop_run:
    case JobRegistry::CancelStep::in_progress:
      return CancelOutcome::cancelling;
    case JobRegistry::CancelStep::already_cancelled:
      return CancelOutcome::already_cancelled;
    case JobRegistry::CancelStep::already_done:
      return CancelOutcome::already_done;
    case JobRegistry::CancelStep::withdraw:
      break;
  }
  const std::int64_t now = now_unix_us();
  const bool stored = registry_.commit(
      job,
      [now](JobRecord& r) {
        r.state = JobState::cancelled;
        r.finished_us = now;
        r.stop_reason = "cancelled";
        r.message = "cancelled before it started";
        r.converged = false;
      },
      /*durable=*/true);
  if (!stored) {
    pool_.restore_after_failed_cancel(job);
    return CancelOutcome::store_error;
  }
  announce_end(run_context_, job, registry_.snapshot(*job));
  log_line("job " + id + ": cancelled while queued");
  return CancelOutcome::cancelled;
}

QueueHealth JobQueue::health() const {
  QueueHealth h;
  h.damaged = registry_.damaged();
  h.stuck = janitor_.stuck();
  h.expired_total = janitor_.expired_total();
  h.events_dropped_total = registry_.events_dropped_total();
  return h;
}

}  // namespace contactd

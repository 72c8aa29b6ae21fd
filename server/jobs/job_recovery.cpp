#include "jobs/job_recovery.hpp"

#include "common/log.hpp"
#include "common/time.hpp"
#include "jobs/events.hpp"
#include "store/crash_marker.hpp"

#include <functional>
#include <stdexcept>
#include <string_view>

namespace contactd {

void JobRecovery::run() {
  JobStore& store = context_.store;
  JobStore::Contents contents = store.load_all();
  context_.registry.add_damaged(contents.damaged);
  for (const JobRecord& loaded : contents.jobs) recover(context_.registry.make_job(loaded));
  log_line("store: " + std::to_string(contents.jobs.size()) + " jobs read back from " + store.data_dir() + ", " +
           std::to_string(requeued_) + " queued to run" +
           (contents.damaged.empty() ? std::string() : ", " + std::to_string(contents.damaged.size()) + " damaged"));
}

void JobRecovery::recover(const std::shared_ptr<Job>& job) {
  job->stored = true;
  job->events.load();
  const std::string id = job->record.id;
  if (const std::string problem = job->events.problem(); !problem.empty()) context_.registry.report_damage(id, problem);
  std::optional<std::size_t> body_hash;
  if (!job->record.idempotency_key.empty()) {
    try {
      body_hash = std::hash<std::string_view>{}(context_.store.read_job(id));
    } catch (const std::exception& e) {
      log_line("job " + id + ": " + e.what());
    }
  }
  context_.registry.add_recovered(job, body_hash);
  const JobRecord& r = job->record;
  if (is_terminal(r.state)) {
    remove_crash_marker(context_.store.job_dir(id));  // a crash after its outcome was stored marks nothing
    check_finished(job);
    return;
  }
  if (r.state == JobState::running) {
    // Its run was cut short by the server dying (a crash, kill -9, running out of memory). A job whose own solve
    // took a fatal signal is marked (store/crash_marker.hpp) and is not run again: it would bring the server down
    // at every start, and the jobs beside it with it. Any other interrupted job runs again, up to max_attempts
    // times (one that kills the server without a signal it can catch, e.g. by running out of memory).
    context_.store.remove_result(id);  // of the interrupted run, if it got that far
    const int interruptions = r.interruptions + 1;
    if (const auto signal = read_crash_marker(context_.store.job_dir(id))) {
      give_up(job, interruptions, "crashed",
              "the server crashed (" + *signal +
                  ") while it solved this job; it is not run again. This is a "
                  "defect of the solver, not of the job: please report it with the job");
      remove_crash_marker(context_.store.job_dir(id));
      return;
    }
    if (interruptions >= context_.settings.max_attempts) {
      give_up(job, interruptions, "interrupted",
              "interrupted " + std::to_string(interruptions) +
                  " times: the server stopped (crashed, was killed or ran out of memory) while it ran; it is not "
                  "run again");
      return;
    }
    requeue_interrupted(job, interruptions);
  }
  remove_crash_marker(context_.store.job_dir(id));  // of an earlier crash, once the job's fate is recorded
  pool_.enqueue(job);
  ++requeued_;
}

void JobRecovery::check_finished(const std::shared_ptr<Job>& job) {
  const JobRecord& r = job->record;
  if (r.result_available)
    if (auto problem = context_.store.check_result(r)) context_.registry.report_damage(r.id, *problem);
  if (job->events.last_type() != "end") {  // crashed between storing the outcome and announcing it
    job->events.append("end", end_event(r));
    job->events.sync_and_close();
  }
  context_.registry.settle(job, context_.store.disk_usage(r.id));
}

void JobRecovery::give_up(const std::shared_ptr<Job>& job, int interruptions, const std::string& stop_reason,
                          const std::string& message) {
  const std::int64_t now = now_unix_us();
  commit_or_throw(job, [&](JobRecord& x) {
    x.state = JobState::failed;
    x.interruptions = interruptions;
    x.finished_us = now;
    x.stop_reason = stop_reason;
    x.message = message;
    x.converged = false;
    x.result_available = false;
    x.progress = nullptr;
  });
  job->events.append("end", end_event(context_.registry.snapshot(*job)));
  job->events.sync_and_close();
  log_line("job " + job->record.id + ": " + message);
  context_.registry.settle(job, std::nullopt);
}

void JobRecovery::requeue_interrupted(const std::shared_ptr<Job>& job, int interruptions) {
  const std::string message = "re-queued: its run was interrupted (the server stopped)";
  commit_or_throw(job, [&](JobRecord& x) {
    x.state = JobState::queued;
    x.interruptions = interruptions;
    x.started_us = 0;
    x.iterations = 0;
    x.progress = nullptr;
    x.message = message;
  });
  job->events.append("state", state_event(JobState::queued, message, job->record.attempts));
  job->events.sync_and_close();
}

void JobRecovery::commit_or_throw(const std::shared_ptr<Job>& job, const JobRegistry::Change& change) {
  std::string error;
  if (!context_.registry.commit(job, change, /*durable=*/true, &error))
    throw std::runtime_error("cannot store the state of job " + job->record.id + ": " + error);
}

}  // namespace contactd

#include "jobs/job_run.hpp"

#include "common/log.hpp"
#include "common/public_message.hpp"
#include "common/time.hpp"
#include "contact/warning.hpp"
#include "jobs/events.hpp"
#include "jobs/progress_observer.hpp"

#include "contact/progress_json.hpp"
#include "contact/result_file.hpp"
#include "contact/solve.hpp"
#include "contact/work_label.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <new>

namespace contactd {

namespace {

std::string format_seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", s);
  return text;
}

// What a client is told about a failed write of the result file: HDF5's error stack names the system's reason
// ("error message = 'No space left on device'") among addresses and paths; only the reason is public.
std::string write_error_summary(const std::string& what, const std::string& data_dir) {
  static const std::string marker = "error message = '";
  const auto at = what.find(marker);
  if (at != std::string::npos) {
    const auto end = what.find('\'', at + marker.size());
    if (end != std::string::npos) return what.substr(at + marker.size(), end - at - marker.size());
  }
  return public_message(what, data_dir);
}

contact::Result failed(const std::string& message) {
  contact::Result result;
  result.stop_reason = contact::StopReason::error;
  result.message = message;
  return result;
}

}  // namespace

void announce_end(const RunContext& context, const std::shared_ptr<Job>& job, const JobRecord& record) {
  job->events.append("end", end_event(record));
  job->events.sync_and_close();
  context.registry.settle(job, context.store.disk_usage(record.id));
  context.on_settled();
}

JobRun::JobRun(const RunContext& context, std::shared_ptr<Job> job)
    : context_(context), job_(std::move(job)), id_(job_->record.id) {}

void JobRun::execute() {
  // The run's threads, and those the solver starts for it, carry the job's id: a fatal signal in any of them marks
  // this job (store/crash_marker.hpp), which then is not run again.
  const contact::WorkLabelScope label(id_);
  announce_start();
  const contact::Result result = solve();
  context_.metrics.solve_finished(result.wall_seconds);
  const auto reason = static_cast<CancelReason>(job_->cancel_reason.load());
  if (result.stop_reason == contact::StopReason::cancelled && reason == CancelReason::shutdown) {
    requeue_after_shutdown();
    return;
  }
  if (result.stop_reason == contact::StopReason::cancelled && reason == CancelReason::lane) {
    requeue_in_general_lane();
    return;
  }
  JobRecord outcome = outcome_of(result, reason);
  // The result file: written before the job is marked done, so that `end` means "downloadable now".
  write_result_files(result, outcome);
  keep_pair_detail();
  for (const auto& step : result.step_history) job_->events.append("step", step_event(step));
  finish(std::move(outcome));
}

void JobRun::announce_start() {
  const int attempt = context_.registry.snapshot(*job_).attempts;
  job_->events.append("state", state_event(JobState::running, "a worker started the job", attempt));
  log_line("job " + id_ + ": started (attempt " + std::to_string(attempt) + ")");
}

contact::Result JobRun::solve() {
  contact::Result result;
  try {
    problem_ = parse_again(result);
    if (!problem_) return result;
    ProgressObserver observer(*job_, context_.registry, context_.metrics,
                              contact::io::ProgressSelection{problem_->output.progress_pairs, false});
    if (problem_->ranks > 1) return solve_on_ranks(observer);
    JobStore& store = context_.store;
    stream_ = std::make_unique<contact::io::ResultStream>(store.result_path(id_), store.xmf_path(id_), "result.hdf");
    observer.set_step_sink(stream_.get());
    return contact::solve(*problem_, observer, job_->cancel);
  } catch (const std::bad_alloc&) {
    return failed("out of memory");
  } catch (const std::exception& e) {
    return failed("internal error: " + public_message(e.what(), context_.store.data_dir()));
  }
}

std::optional<contact::Problem> JobRun::parse_again(contact::Result& result) {
  Job& job = *job_;
  const std::string body = context_.store.read_job(id_);
  BodyBudget::Slot slot = context_.budget.for_validation_until(body.size(), [&job] { return job.cancel.cancelled(); });
  if (slot) {
    auto parsed = validate_job(context_.settings, body, /*time_limited=*/false);
    slot.release();
    if (!parsed.ok()) {
      // Valid when submitted; invalid now (a smaller --max-dofs since, or another solver version).
      result.stop_reason = contact::StopReason::error;
      result.message = "the job is no longer valid: " + contact::job::format_errors(parsed.errors);
      return std::nullopt;
    }
    if (!job.cancel.cancelled()) return std::move(parsed.problem);
  }
  result.stop_reason = contact::StopReason::cancelled;
  result.message = "cancelled before the solve started";
  return std::nullopt;
}

contact::Result JobRun::solve_on_ranks(ProgressObserver& observer) {
  const QueueSettings& settings = context_.settings;
  JobStore& store = context_.store;
  mpi_ = run_mpi_job(
      settings.mpi, problem_->ranks, store.job_path(id_), store.result_path(id_), id_, settings.max_dofs,
      [&](const std::string& type, const nlohmann::json& j) {
        if (type == "iteration") observer.on_iteration_json(j);
        if (type == "adaptive_step") observer.on_adaptive_step_json(j);
        if (type == "load_step") observer.on_load_step_json(j);
      },
      job_->cancel);
  contact::Result result;
  result.stop_reason = mpi_->stop_reason;
  result.message = public_message(mpi_->message, store.data_dir());
  result.iterations = mpi_->iterations;
  result.converged = mpi_->converged;
  result.wall_seconds = mpi_->wall_seconds;
  result.warnings = contact::warnings_of(mpi_->warnings);
  return result;
}

JobRecord JobRun::outcome_of(const contact::Result& result, CancelReason reason) const {
  JobRecord outcome;
  outcome.converged = false;
  outcome.iterations = result.iterations;
  outcome.solve_seconds = result.wall_seconds;
  outcome.message = result.message;
  outcome.stop_reason = contact::to_string(result.stop_reason);
  outcome.warnings = contact::warnings_json(result.warnings);
  // A collapse analysis's answer or a failed step's statics verdict: a run on MPI ranks reports it as JSON already.
  outcome.collapse = mpi_ ? mpi_->collapse : contact::io::collapse_json(result.collapse);
  switch (result.stop_reason) {
    case contact::StopReason::converged:
      outcome.state = JobState::succeeded;
      outcome.converged = true;
      break;
    case contact::StopReason::max_iterations:
    case contact::StopReason::stagnation:
      // Not an answer: the job fails; the result keeps the steps that held (and the last iterate, flagged
      // converged 0, only if the job asked for it: output.iterate), as the message says.
      outcome.state = JobState::failed;
      outcome.message = "the solve did not converge (" + outcome.stop_reason + "): " + result.message;
      break;
    case contact::StopReason::error:
      outcome.state = JobState::failed;
      break;
    case contact::StopReason::cancelled:
      if (reason == CancelReason::time_limit) {
        outcome.state = JobState::failed;
        outcome.stop_reason = "time_limit";
        outcome.message = "stopped by the time limit of " + format_seconds(context_.settings.time_limit_seconds) +
                          " s after " + std::to_string(result.iterations) + " iterations";
      } else {
        outcome.state = JobState::cancelled;
        outcome.message = "cancelled after " + std::to_string(result.iterations) + " iterations";
      }
      if (!result.kept.empty()) outcome.message += "; " + result.kept;
      break;
  }
  return outcome;
}

void JobRun::write_result_files(const contact::Result& result, JobRecord& outcome) {
  JobStore& store = context_.store;
  if (mpi_) {
    outcome.result_available = mpi_->result_written;  // with the steps that held, also when a later one failed
    if (!outcome.result_available) store.remove_result(id_);
    for (const auto& step : mpi_->steps) job_->events.append("step", step);
    return;
  }
  // Every step that held is kept, also when a later one failed (an error stop: the statics refused a load step,
  // the friction Newton did not converge); the file's steps say which converged, the job's message which step
  // failed, why, and what the result keeps (Result::kept). Nothing is written when no step is kept.
  if (!problem_ || !stream_ || result.steps.empty()) {
    stream_.reset();  // a partial file is removed
    return;
  }
  try {
    contact::io::WriteInfo info;
    info.job_id = id_;
    stream_->finish(*problem_, result, info);
    stream_.reset();
    outcome.result_available = true;
  } catch (const std::exception& e) {
    stream_.reset();
    log_line("job " + id_ + ": cannot write the result file: " + e.what());
    store.remove_result(id_);  // also frees the space a full disk needs for the state change below
    outcome.state = JobState::failed;
    outcome.stop_reason = "error";
    outcome.message = "cannot write the result file: " + write_error_summary(e.what(), store.data_dir());
  }
}

// The last iteration's detail of every pair goes from memory to pairs.json, so that GET /v1/jobs/{id}/pairs
// still answers after the job (and after a restart). Not a reason to fail the job: without it the route says so.
void JobRun::keep_pair_detail() {
  const auto detail = job_->pair_detail();
  if (!detail) return;
  try {
    context_.store.save_pairs(id_, detail->dump());
  } catch (const std::exception& e) {
    log_line("job " + id_ + ": cannot store the pairs' detail: " + e.what());
  }
  job_->set_pair_detail(nullptr);
}

void JobRun::finish(JobRecord outcome) {
  outcome.finished_us = now_unix_us();
  outcome.events_dropped = job_->events.dropped();
  if (outcome.result_available) {
    outcome.result_bytes = 0;
    const int fd = context_.store.open_result(id_, false);
    struct stat st {};
    if (fd >= 0 && ::fstat(fd, &st) == 0) outcome.result_bytes = static_cast<std::int64_t>(st.st_size);
    if (fd >= 0) ::close(fd);
  }
  const JobRegistry::Change change = [&outcome](JobRecord& r) {
    r.state = outcome.state;
    r.finished_us = outcome.finished_us;
    r.stop_reason = outcome.stop_reason;
    r.message = outcome.message;
    r.converged = outcome.converged;
    r.iterations = outcome.iterations;
    r.solve_seconds = outcome.solve_seconds;
    r.result_available = outcome.result_available;
    r.result_bytes = outcome.result_bytes;
    r.events_dropped = outcome.events_dropped;
    r.warnings = outcome.warnings;
    r.collapse = outcome.collapse;
  };
  // The outcome is on disk before anyone is told: on a full disk the worker waits here (the job stays RUNNING
  // on disk and in the API) rather than report an outcome a restart would not find.
  if (!commit_patiently(change)) {
    log_line("job " + id_ + ": stopping before its outcome could be stored; it runs again at the next start");
    return;
  }
  const JobRecord after = context_.registry.count_outcome(*job_);
  announce_end(context_, job_, after);
  log_line("job " + after.id + ": " + to_string(after.state) + " (" + after.stop_reason + ", " +
           std::to_string(after.iterations) + " iterations, " + format_seconds(after.solve_seconds) + " s)");
}

void JobRun::requeue_after_shutdown() {
  if (store_queued_again("interrupted by a shutdown; it runs again when the server restarts", false))
    log_line("job " + id_ + ": interrupted by the shutdown, stored as QUEUED");
}

// A run on the small-job lane past --small-job-seconds: sized small, it is not, and it held the lane that keeps
// small jobs from waiting behind long ones. Stored QUEUED as a general job; the worker pool puts it first in line for
// a general worker (WorkerPool::release), where it runs again from the start.
void JobRun::requeue_in_general_lane() {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", context_.settings.small_job_seconds);
  if (store_queued_again(std::string("moved to the general lane: it ran past the small-job lane's ") + seconds +
                             " s; it runs again from the start on a general worker",
                         true))
    log_line("job " + id_ + ": moved from the small-job lane to the general lane");
}

// Stored QUEUED again (its partial result files removed), with `message` on its stream; false if the store could
// not take the change (then it is RUNNING on disk, and the next start queues it again as interrupted).
bool JobRun::store_queued_again(const std::string& message, bool general) {
  job_->set_pair_detail(nullptr);
  stream_.reset();  // its partial file is removed
  context_.store.remove_result(id_);
  const JobRegistry::Change change = [&message, general](JobRecord& r) {
    r.state = JobState::queued;
    r.started_us = 0;
    r.iterations = 0;
    r.progress = nullptr;
    r.message = message;
    if (general) r.small = false;  // read by the pool only after this (it queues the job once the run ends)
  };
  // A shutdown does not wait for the disk; a move to the general lane does (a job RUNNING in the store but in no
  // worker's hands would be lost until the next start).
  if (general ? !commit_patiently(change) : !context_.registry.commit(job_, change, /*durable=*/true)) return false;
  const int attempts = context_.registry.snapshot(*job_).attempts;
  job_->events.append("state", state_event(JobState::queued, message, attempts));
  job_->events.sync_and_close();
  return true;
}

bool JobRun::commit_patiently(const JobRegistry::Change& change) {
  for (int attempt = 0;; ++attempt) {
    if (context_.registry.commit(job_, change, /*durable=*/true)) return true;
    if (attempt == 0) log_line("job " + id_ + ": retrying every second until its outcome can be stored");
    if (context_.wait_for_stop(std::chrono::seconds(1))) return false;
    context_.store.restore_reserve();
  }
}

}  // namespace contactd

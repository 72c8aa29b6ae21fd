// The workers: each takes the next QUEUED job, stores it RUNNING, solves it with an observer that appends its
// progress events, writes the result file and stores the outcome (docs/server.md, "States and outcomes").
#include "job_queue.hpp"

#include "events.hpp"
#include "util.hpp"

#include "contact/result_file.hpp"
#include "contact/solve.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
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

// Appends one `iteration` event per solver iteration and keeps the job's progress summary current.
// Runs on the worker's thread; it only takes short locks and never waits for a client.
class EventObserver final : public contact::Observer {
 public:
  EventObserver(Job& job, std::mutex& records_mutex, Metrics& metrics)
      : job_(job), records_mutex_(records_mutex), metrics_(metrics) {}

  void on_iteration(const contact::IterationReport& report) override { on_iteration_json(iteration_event(report)); }

  // The same for an iteration as JSON (from an MPI run's progress lines).
  void on_iteration_json(const nlohmann::json& event) {
    job_.events.append("iteration", event);
    nlohmann::json summary = event;  // the summary is the event without the pressure profiles
    if (summary.contains("pairs") && summary["pairs"].is_array())
      for (auto& pair : summary["pairs"])
        if (pair.is_object()) {
          pair.erase("positions");
          pair.erase("pressures");
          pair.erase("tangential_tractions");
          pair.erase("stick");
        }
    {
      std::lock_guard<std::mutex> lock(records_mutex_);
      job_.record.iterations = event.value("iteration", 0);
      job_.record.progress = std::move(summary);
    }
    metrics_.iteration_done();
  }

 private:
  Job& job_;
  std::mutex& records_mutex_;
  Metrics& metrics_;
};

}  // namespace

void JobQueue::worker_loop() {
  while (true) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) break;
      job = queue_.front();
      queue_.pop_front();
      if (job->record.state != JobState::queued) continue;  // cancelled while waiting
      running_.push_back(job);  // from now on cancel() finds it among the running (its state says QUEUED)
    }
    // RUNNING is on disk before the API says so (not fsync'ed: whether a crash leaves QUEUED or RUNNING on disk,
    // the job is queued again at start-up).
    const std::int64_t started = now_unix_us();
    const bool stored = commit(
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
    if (!stored) {
      // The store cannot take the change (a full disk): the job waits at the front of the queue.
      std::unique_lock<std::mutex> lock(mutex_);
      running_.erase(std::remove(running_.begin(), running_.end(), job), running_.end());
      if (job->record.state == JobState::queued) queue_.push_front(job);
      watchdog_.wait_for(lock, std::chrono::seconds(1), [this] { return stopping_; });
      continue;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job->deadline = settings_.time_limit_seconds > 0
                          ? std::chrono::steady_clock::now() +
                                std::chrono::microseconds(static_cast<std::int64_t>(settings_.time_limit_seconds * 1e6))
                          : std::chrono::steady_clock::time_point::max();
    }
    try {
      run(job);
    } catch (const std::exception& e) {  // run() handles the solver's failures; this is a bug or no memory
      log_line("job " + job->record.id + ": unexpected error: " + e.what());
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      running_.erase(std::remove(running_.begin(), running_.end(), job), running_.end());
    }
    idle_.notify_all();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    --workers_alive_;
  }
  idle_.notify_all();
}

std::optional<contact::Problem> JobQueue::parse_for_run(Job& job, contact::Result& result) {
  const std::string body = store_.read_job(job.record.id);
  BodyBudget::Slot slot = budget_.for_validation_until(body.size(), [&job] { return job.cancel.cancelled(); });
  if (slot) {
    auto parsed = validate(body);
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

void JobQueue::run(const std::shared_ptr<Job>& job) {
  const std::string id = job->record.id;
  int attempt = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    attempt = job->record.attempts;
  }
  job->events.append("state", state_event(JobState::running, "a worker started the job", attempt));
  log_line("job " + id + ": started (attempt " + std::to_string(attempt) + ")");

  JobRecord outcome;
  outcome.converged = false;
  contact::Result result;
  std::optional<contact::Problem> problem;
  std::optional<MpiOutcome> mpi;  // a job run on MPI ranks: the child wrote the result file
  try {
    problem = parse_for_run(*job, result);
    if (problem) {
      EventObserver observer(*job, mutex_, metrics_);
      if (problem->ranks > 1) {
        mpi = run_mpi_job(settings_.mpi, problem->ranks, store_.job_path(id), store_.result_path(id), id,
                          settings_.max_dofs, [&](const nlohmann::json& j) { observer.on_iteration_json(j); },
                          job->cancel);
        result.stop_reason = mpi->stop_reason;
        result.message = public_message(mpi->message, store_.data_dir());
        result.iterations = mpi->iterations;
        result.converged = mpi->converged;
        result.wall_seconds = mpi->wall_seconds;
      } else {
        result = contact::solve(*problem, observer, job->cancel);
      }
    }
  } catch (const std::bad_alloc&) {
    result = contact::Result{};
    result.stop_reason = contact::StopReason::error;
    result.message = "out of memory";
  } catch (const std::exception& e) {
    result = contact::Result{};
    result.stop_reason = contact::StopReason::error;
    result.message = "internal error: " + public_message(e.what(), store_.data_dir());
  }
  metrics_.solve_finished(result.wall_seconds);

  const auto reason = static_cast<CancelReason>(job->cancel_reason.load());
  if (result.stop_reason == contact::StopReason::cancelled && reason == CancelReason::shutdown) {
    requeue_after_shutdown(job);
    return;
  }

  outcome.iterations = result.iterations;
  outcome.solve_seconds = result.wall_seconds;
  outcome.message = result.message;
  outcome.stop_reason = contact::to_string(result.stop_reason);
  switch (result.stop_reason) {
    case contact::StopReason::converged:
      outcome.state = JobState::succeeded;
      outcome.converged = true;
      break;
    case contact::StopReason::max_iterations:
    case contact::StopReason::stagnation:
      outcome.state = JobState::succeeded;
      break;
    case contact::StopReason::error:
      outcome.state = JobState::failed;
      break;
    case contact::StopReason::cancelled:
      if (reason == CancelReason::time_limit) {
        outcome.state = JobState::failed;
        outcome.stop_reason = "time_limit";
        outcome.message = "stopped by the time limit of " + format_seconds(settings_.time_limit_seconds) + " s after " +
                          std::to_string(result.iterations) + " iterations";
      } else {
        outcome.state = JobState::cancelled;
        outcome.message = "cancelled after " + std::to_string(result.iterations) + " iterations";
      }
      break;
  }

  // The result file: written before the job is marked done, so that `end` means "downloadable now".
  if (mpi) {
    outcome.result_available = mpi->result_written && result.stop_reason != contact::StopReason::error;
    if (!outcome.result_available) store_.remove_result(id);
    for (const auto& step : mpi->steps) job->events.append("step", step);
  } else if (problem && !result.steps.empty() && result.stop_reason != contact::StopReason::error) {
    try {
      contact::io::WriteInfo info;
      info.job_id = id;
      contact::io::write_result(store_.result_path(id), *problem, result, info);
      contact::io::write_xdmf(store_.xmf_path(id), "result.hdf", result);
      outcome.result_available = true;
    } catch (const std::exception& e) {
      log_line("job " + id + ": cannot write the result file: " + e.what());
      store_.remove_result(id);  // also frees the space a full disk needs for the state change below
      outcome.state = JobState::failed;
      outcome.stop_reason = "error";
      outcome.message = "cannot write the result file: " + write_error_summary(e.what(), store_.data_dir());
    }
  }
  for (const auto& step : result.step_history) job->events.append("step", step_event(step));
  finish(job, std::move(outcome));
}

void JobQueue::finish(const std::shared_ptr<Job>& job, JobRecord outcome) {
  outcome.finished_us = now_unix_us();
  outcome.events_dropped = job->events.dropped();
  if (outcome.result_available) {
    outcome.result_bytes = 0;
    const int fd = store_.open_result(job->record.id, false);
    struct stat st {};
    if (fd >= 0 && ::fstat(fd, &st) == 0) outcome.result_bytes = static_cast<std::int64_t>(st.st_size);
    if (fd >= 0) ::close(fd);
  }
  const Change change = [&outcome](JobRecord& r) {
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
  };
  // The outcome is on disk before anyone is told: on a full disk the worker waits here (the job stays RUNNING
  // on disk and in the API) rather than report an outcome a restart would not find.
  if (!commit_patiently(job, change)) {
    log_line("job " + job->record.id + ": stopping before its outcome could be stored; it runs again at the next start");
    return;
  }
  JobRecord after;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    after = job->record;
    job->disk_bytes = 0;
    events_dropped_total_ += after.events_dropped;
  }
  nlohmann::json end = end_event(after);
  job->events.append("end", end);
  job->events.sync_and_close();
  const std::int64_t bytes = store_.disk_usage(after.id);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job->disk_bytes = bytes;
  }
  mark_settled(job);
  log_line("job " + after.id + ": " + to_string(after.state) + " (" + after.stop_reason + ", " +
           std::to_string(after.iterations) + " iterations, " + format_seconds(after.solve_seconds) + " s)");
}

void JobQueue::requeue_after_shutdown(const std::shared_ptr<Job>& job) {
  store_.remove_result(job->record.id);
  const std::string message = "interrupted by a shutdown; it runs again when the server restarts";
  if (!commit(job, [&message](JobRecord& r) {
        r.state = JobState::queued;
        r.started_us = 0;
        r.iterations = 0;
        r.progress = nullptr;
        r.message = message;
      }, /*durable=*/true)) {
    return;  // RUNNING on disk: the next start queues it again (as interrupted)
  }
  int attempts = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    attempts = job->record.attempts;
  }
  job->events.append("state", state_event(JobState::queued, message, attempts));
  job->events.sync_and_close();
  log_line("job " + job->record.id + ": interrupted by the shutdown, stored as QUEUED");
}

}  // namespace contactd

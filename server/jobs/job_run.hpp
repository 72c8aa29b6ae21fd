// One run of a job on a worker's thread, in its phases: announce the start, parse the job again, solve it (in
// this process, or on MPI ranks: mpi_job.hpp), map the solver's stop reason to the job's outcome, write the
// result file, store the outcome and announce the end (docs/server.md, "States and outcomes"):
//   converged                  -> SUCCEEDED, converged true
//   max_iterations, stagnation -> SUCCEEDED, converged false (the result file is written and useful)
//   error                      -> FAILED with the solver's message (no result file)
//   cancelled by the user      -> CANCELLED (the result file of the last iterate is written when the solver
//                                 returned one)
//   cancelled by the time limit-> FAILED with stop_reason "time_limit" (result file as for CANCELLED)
//   cancelled by shutdown      -> back to QUEUED on disk: it runs again, from the start, at the next start-up.
// The outcome is on disk before anyone is told: a worker whose job cannot be stored as finished (a full disk)
// keeps trying until it can, or until the pool stops.
#pragma once

#include "jobs/body_budget.hpp"
#include "jobs/job.hpp"
#include "jobs/job_registry.hpp"
#include "jobs/mpi_job.hpp"
#include "jobs/queue_settings.hpp"
#include "metrics/metrics.hpp"
#include "store/job_store.hpp"

#include "contact/problem.hpp"
#include "contact/result.hpp"
#include "contact/result_file.hpp"

#include <chrono>
#include <functional>
#include <memory>
#include <optional>

namespace contactd {

class ProgressObserver;

// What a run uses, owned elsewhere (by the JobQueue).
struct RunContext {
  JobRegistry& registry;
  JobStore& store;
  Metrics& metrics;
  BodyBudget& budget;  // a run parses its job again under one of its validation slots
  const QueueSettings& settings;
  std::function<bool(std::chrono::milliseconds)> wait_for_stop;  // true once the workers stop
  std::function<void()> on_settled;                              // a job was settled: retention may run
};

// Announces a finished job (its record stored): the `end` event, the event log synced and closed, the job's
// disk usage counted and the job settled.
void announce_end(const RunContext& context, const std::shared_ptr<Job>& job, const JobRecord& record);

class JobRun {
 public:
  JobRun(const RunContext& context, std::shared_ptr<Job> job);
  void execute();

 private:
  void announce_start();
  contact::Result solve();
  // The job parsed again (it was valid when submitted) under a validation slot, as a submission is. A cancel or
  // the time limit while it waits for the slot or is parsed ends it before any solve: nullopt, `result` says why.
  std::optional<contact::Problem> parse_again(contact::Result& result);
  contact::Result solve_on_ranks(ProgressObserver& observer);
  JobRecord outcome_of(const contact::Result& result, CancelReason reason) const;
  void write_result_files(const contact::Result& result, JobRecord& outcome);
  void keep_pair_detail();
  void finish(JobRecord outcome);
  void requeue_after_shutdown();
  void requeue_in_general_lane();
  bool store_queued_again(const std::string& message, bool general);
  // commit() until it succeeds or the workers stop; false if stopped.
  bool commit_patiently(const JobRegistry::Change& change);

  const RunContext& context_;
  const std::shared_ptr<Job> job_;
  const std::string id_;
  std::optional<contact::Problem> problem_;
  std::optional<MpiOutcome> mpi_;  // a job run on MPI ranks: the child wrote the result file
  // A job run here: its result file, written as the steps are reached and put in place by write_result_files
  // (removed unfinished if the run leaves no result).
  std::unique_ptr<contact::io::ResultStream> stream_;
};

}  // namespace contactd

// The solver's progress as a job's events: one `iteration` event per iteration, bounded whatever the job's size
// (the totals over all pairs, and the detail of the pairs the job selects or that stand out:
// contact/progress_json.hpp); the job's progress summary (the event without its profiles) kept current in its
// record; and every pair's detail of the last iteration kept for GET /v1/jobs/{id}/pairs.
#pragma once

#include "jobs/job.hpp"
#include "jobs/job_registry.hpp"
#include "metrics/metrics.hpp"

#include "contact/progress_json.hpp"
#include "contact/result.hpp"

#include <nlohmann/json.hpp>

namespace contactd {

// Runs on the worker's thread; it only takes short locks and never waits for a client.
class ProgressObserver final : public contact::Observer {
 public:
  ProgressObserver(Job& job, JobRegistry& registry, Metrics& metrics, contact::io::ProgressSelection selection)
      : job_(job), registry_(registry), metrics_(metrics), selection_(std::move(selection)) {}

  void on_iteration(const contact::IterationReport& report) override;
  // The same for an iteration as JSON with every pair (an MPI run's progress lines: contactd asks for all).
  void on_iteration_json(nlohmann::json full);
  // An adaptive step (its estimates, cells and unknowns) as an "adaptive_step" event; the JSON form is an MPI
  // run's progress line.
  void on_adaptive_step(const contact::AdaptiveStepReport& report) override;
  void on_adaptive_step_json(nlohmann::json step);
  void on_load_step(const contact::LoadStepReport& report) override;
  void on_load_step_json(nlohmann::json step);
  // Where the job's steps go as they are reached: its result file (contact::io::ResultStream).
  void set_step_sink(contact::StepSink* sink) { sink_ = sink; }
  contact::StepSink* step_sink() override { return sink_; }

 private:
  Job& job_;
  JobRegistry& registry_;
  Metrics& metrics_;
  contact::io::ProgressSelection selection_;
  contact::StepSink* sink_ = nullptr;
};

}  // namespace contactd

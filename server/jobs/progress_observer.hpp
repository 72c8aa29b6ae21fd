// The solver's progress as a job's events: one `iteration` event per iteration (with the pressure profiles),
// and the job's progress summary (the same without them) kept current in its record.
#pragma once

#include "jobs/job.hpp"
#include "jobs/job_registry.hpp"
#include "metrics/metrics.hpp"

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

namespace contactd {

// Runs on the worker's thread; it only takes short locks and never waits for a client.
class ProgressObserver final : public contact::Observer {
 public:
  ProgressObserver(Job& job, JobRegistry& registry, Metrics& metrics)
      : job_(job), registry_(registry), metrics_(metrics) {}

  void on_iteration(const contact::IterationReport& report) override;
  // The same for an iteration as JSON (from an MPI run's progress lines).
  void on_iteration_json(const nlohmann::json& event);

 private:
  Job& job_;
  JobRegistry& registry_;
  Metrics& metrics_;
};

}  // namespace contactd

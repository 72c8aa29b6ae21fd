#include "jobs/queue_settings.hpp"

#include <algorithm>

#include "contact/result_file.hpp"

namespace contactd {

bool small_job(const QueueSettings& settings, const contact::Problem& problem) {
  if (settings.small_workers <= 0 || problem.ranks > 1 || problem.adaptivity.enabled || problem.bodies.size() > 16)
    return false;
  double dofs = 0;
  for (const auto& b : problem.bodies) dofs += 2.0 * b.mesh.num_nodes();
  return dofs * static_cast<double>(std::max<std::size_t>(1, problem.loading.factors.size())) <=
         static_cast<double>(settings.small_job_dofs);
}

std::int64_t estimated_result(const contact::Problem& problem) {
  double nodes = 0;
  for (const auto& b : problem.bodies) nodes += b.mesh.num_nodes();
  const bool all = problem.output.steps == contact::StepOutput::all;
  double kept = 1;
  if (problem.adaptivity.enabled) {
    kept = all ? problem.adaptivity.max_steps + 1.0 : 1.0;
    nodes = std::max(nodes, problem.adaptivity.max_kept_nodes);
  } else if (all) {
    kept = static_cast<double>(std::max<std::size_t>(1, problem.loading.factors.size()));
  }
  return static_cast<std::int64_t>(contact::io::estimated_result_bytes(
      nodes, static_cast<double>(problem.bodies.size()), static_cast<double>(problem.contacts.size()), kept));
}

contact::job::ParseResult validate_job(const QueueSettings& settings, const std::string& body, bool time_limited) {
  contact::job::Limits limits;
  limits.max_dofs = settings.max_dofs;
  limits.max_bodies = settings.max_bodies;
  limits.max_contacts = settings.max_contacts;
  limits.max_load_steps = settings.max_load_steps;
  limits.max_result_bytes = settings.max_result_bytes;
  limits.result_bytes_hint = "contactd --max-result-bytes";
  limits.max_interface_bytes = settings.max_interface_bytes;
  limits.interface_bytes_hint = "contactd --max-interface-bytes";
  limits.max_validation_seconds = time_limited ? settings.max_validation_seconds : 0.0;
  limits.validation_seconds_hint = "contactd --max-validation-seconds";
  limits.max_ranks = settings.mpi.launcher.empty() ? 1 : settings.mpi.max_ranks;
  limits.ranks_hint = settings.mpi.launcher.empty()
                          ? "this server solves every job in its own process: it was started without --mpi-launcher"
                          : "contactd --max-ranks";
  return contact::job::parse_text(body, limits);
}

}  // namespace contactd

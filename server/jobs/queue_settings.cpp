#include "jobs/queue_settings.hpp"

namespace contactd {

contact::job::ParseResult validate_job(const QueueSettings& settings, const std::string& body) {
  contact::job::Limits limits;
  limits.max_dofs = settings.max_dofs;
  limits.max_bodies = settings.max_bodies;
  limits.max_contacts = settings.max_contacts;
  limits.max_ranks = settings.mpi.launcher.empty() ? 1 : settings.mpi.max_ranks;
  limits.ranks_hint = settings.mpi.launcher.empty()
                          ? "this server solves every job in its own process: it was started without --mpi-launcher"
                          : "contactd --max-ranks";
  return contact::job::parse_text(body, limits);
}

}  // namespace contactd

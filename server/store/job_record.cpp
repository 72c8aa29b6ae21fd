#include "store/job_record.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace contactd {

const char* to_string(JobState state) {
  switch (state) {
    case JobState::queued:
      return "QUEUED";
    case JobState::running:
      return "RUNNING";
    case JobState::succeeded:
      return "SUCCEEDED";
    case JobState::failed:
      return "FAILED";
    case JobState::cancelled:
      return "CANCELLED";
  }
  return "FAILED";
}

std::optional<JobState> job_state_from_string(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (JobState s : {JobState::queued, JobState::running, JobState::succeeded, JobState::failed, JobState::cancelled})
    if (text == to_string(s)) return s;
  return std::nullopt;
}

nlohmann::json to_state_json(const JobRecord& r) {
  nlohmann::json j = {{"format", "contactd-job-state"},
                      {"version", 1},
                      {"id", r.id},
                      {"name", r.name},
                      {"state", to_string(r.state)},
                      {"created_us", r.created_us},
                      {"started_us", r.started_us},
                      {"finished_us", r.finished_us},
                      {"attempts", r.attempts},
                      {"interruptions", r.interruptions},
                      {"idempotency_key", r.idempotency_key},
                      {"body_bytes", r.body_bytes},
                      {"small", r.small},
                      {"result_estimate_bytes", r.result_estimate},
                      {"stop_reason", r.stop_reason},
                      {"message", r.message},
                      {"iterations", r.iterations},
                      {"solve_seconds", r.solve_seconds},
                      {"result_available", r.result_available},
                      {"result_bytes", r.result_bytes},
                      {"events_dropped", r.events_dropped},
                      {"warnings", r.warnings},
                      {"collapse", r.collapse},
                      {"progress", r.progress ? *r.progress : nlohmann::json(nullptr)}};
  j["converged"] = r.converged ? nlohmann::json(*r.converged) : nlohmann::json(nullptr);
  return j;
}

JobRecord from_state_json(const nlohmann::json& j) {
  if (!j.is_object() || j.value("format", "") != "contactd-job-state")
    throw std::runtime_error("not a contactd job state document");
  if (j.value("version", 0) != 1) throw std::runtime_error("unknown job state version");
  JobRecord r;
  r.id = j.at("id").get<std::string>();
  r.name = j.value("name", "");
  const auto state = job_state_from_string(j.at("state").get<std::string>());
  if (!state) throw std::runtime_error("unknown job state '" + j.at("state").get<std::string>() + "'");
  r.state = *state;
  r.created_us = j.at("created_us").get<std::int64_t>();
  r.started_us = j.value("started_us", std::int64_t{0});
  r.finished_us = j.value("finished_us", std::int64_t{0});
  r.attempts = j.value("attempts", 0);
  r.interruptions = j.value("interruptions", 0);
  r.idempotency_key = j.value("idempotency_key", "");
  r.body_bytes = j.value("body_bytes", std::int64_t{0});
  r.small = j.value("small", false);
  r.result_estimate = j.value("result_estimate_bytes", std::int64_t{0});
  r.stop_reason = j.value("stop_reason", "");
  r.message = j.value("message", "");
  r.iterations = j.value("iterations", 0);
  r.solve_seconds = j.value("solve_seconds", 0.0);
  r.result_available = j.value("result_available", false);
  r.result_bytes = j.value("result_bytes", std::int64_t{0});
  r.events_dropped = j.value("events_dropped", std::int64_t{0});
  if (j.contains("warnings") && j["warnings"].is_array()) r.warnings = j["warnings"];
  if (j.contains("collapse") && j["collapse"].is_object()) r.collapse = j["collapse"];
  if (j.contains("converged") && j["converged"].is_boolean()) r.converged = j["converged"].get<bool>();
  if (j.contains("progress") && !j["progress"].is_null())
    r.progress = std::make_shared<const nlohmann::json>(j["progress"]);
  return r;
}

}  // namespace contactd

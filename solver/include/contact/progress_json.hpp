// Progress as JSON: one object per solver iteration and per result step. The server streams these as its
// `iteration` and `step` events (docs/server.md, "Events"), and `contact-solve --progress ndjson` prints them one
// per line, which is how the server follows a job that runs under mpirun.
#pragma once

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

namespace contact::io {

// Every field of the report; the pressure profile of every pair (positions, pressures) only with `profiles`.
nlohmann::json iteration_json(const IterationReport& report, bool profiles = true);

// One step of the result (Result::step_history: every step, whether its fields are kept or not):
// {"step", "iteration", "bodies": [{"name", "elements", "nodes"}]}.
nlohmann::json step_json(const StepSummary& step);

}  // namespace contact::io

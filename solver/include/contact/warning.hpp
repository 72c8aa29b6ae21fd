// A model that solves but looks wrong (an overlap the job does not declare, a body moved far against its size).
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace contact {

// What is wrong, at which JSON pointer of the job ("/contacts/3", "/bodies/0"). A warning never changes the answer; a
// strict job (Problem::strict) is refused for one before the solve, and fails after it (docs/job-format.md,
// "Warnings").
struct Warning {
  std::string pointer;
  std::string message;
};

// Warnings as the command line's ndjson, the server's API and its state.json give them: [{"pointer", "message"}].
inline nlohmann::json warnings_json(const std::vector<Warning>& list) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& w : list) out.push_back({{"pointer", w.pointer}, {"message", w.message}});
  return out;
}

// The reverse, for a list another process reported (an MPI run's result line); entries that are not
// {"pointer": str, "message": str} are left out.
inline std::vector<Warning> warnings_of(const nlohmann::json& list) {
  std::vector<Warning> out;
  if (!list.is_array()) return out;
  for (const auto& w : list)
    if (w.is_object() && w.value("pointer", nlohmann::json()).is_string() &&
        w.value("message", nlohmann::json()).is_string())
      out.push_back({w["pointer"].get<std::string>(), w["message"].get<std::string>()});
  return out;
}

}  // namespace contact

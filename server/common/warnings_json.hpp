// The model checks' warnings (contact/warning.hpp) as the API shows and state.json keeps them: an array of
// {"pointer", "message"} (docs/server.md, "Warnings").
#pragma once

#include "contact/warning.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace contactd {

inline nlohmann::json warnings_json(const std::vector<contact::Warning>& list) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& w : list) out.push_back({{"pointer", w.pointer}, {"message", w.message}});
  return out;
}

// The reverse, for a list a child process reported (an MPI run's result line); entries that are not
// {"pointer": str, "message": str} are left out.
inline std::vector<contact::Warning> warnings_of(const nlohmann::json& list) {
  std::vector<contact::Warning> out;
  if (!list.is_array()) return out;
  for (const auto& w : list)
    if (w.is_object() && w.value("pointer", nlohmann::json()).is_string() &&
        w.value("message", nlohmann::json()).is_string())
      out.push_back({w["pointer"].get<std::string>(), w["message"].get<std::string>()});
  return out;
}

}  // namespace contactd

// Internal to solver/io: atomic file replacement and small facts about the machine.
#pragma once

#include <functional>
#include <string>

namespace contact::io::detail {

// Calls write(tmp) with tmp = path + ".tmp", syncs tmp to disk, then renames it over `path`. On any failure
// removes tmp and throws std::runtime_error("cannot write <what> '<path>': <reason>").
void write_atomically(const std::string& path, const std::string& what,
                      const std::function<void(const std::string& tmp)>& write);

std::string utc_now_iso8601();  // "2024-05-01T12:00:00Z"
std::string host_name();        // "" if unknown

}  // namespace contact::io::detail

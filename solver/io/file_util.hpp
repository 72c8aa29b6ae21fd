// Internal to solver/io: the result files' atomic replacement (contact/files.hpp) with the file named in its
// errors, and small facts about the machine.
#pragma once

#include <functional>
#include <string>

namespace contact::io::detail {

// contact::replace_file_atomically(path, write), durable; any failure is rethrown as
// std::runtime_error("cannot write <what> '<path>': <reason>").
void write_atomically(const std::string& path, const std::string& what,
                      const std::function<void(const std::string& tmp)>& write);

std::string host_name();  // "" if unknown

}  // namespace contact::io::detail

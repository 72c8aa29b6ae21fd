// contactd's log: one line per event to stderr.
#pragma once

#include <string>

namespace contactd {

// One line to stderr with a UTC time stamp: "2024-05-01T12:00:00.123456Z contactd: <text>".
void log_line(const std::string& text);

}  // namespace contactd

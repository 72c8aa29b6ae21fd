// Job ids: random version 4 UUIDs, and the check that keeps anything else away from the disk.
#pragma once

#include <string>
#include <string_view>

namespace contactd {

// A random (version 4) UUID in lower case, from std::random_device. Thread-safe.
std::string new_job_id();

// True for the ids new_job_id() makes (lower-case UUID v4). Anything else is never looked up on disk.
bool is_job_id(std::string_view text);

}  // namespace contactd

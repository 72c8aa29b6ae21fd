// Wall-clock time and its ISO 8601 form, the one formatting the result file's `created` attribute and contactd's
// job and event timestamps share.
#pragma once

#include <cstdint>
#include <string>

namespace contact {

// Wall-clock time as microseconds since the Unix epoch (UTC).
std::int64_t now_unix_us();

enum class TimePrecision { seconds, microseconds };

// ISO 8601 UTC: "2024-05-01T12:00:00Z" (seconds) or "2024-05-01T12:00:00.123456Z" (microseconds).
std::string iso8601_utc(std::int64_t unix_us, TimePrecision precision);

}  // namespace contact

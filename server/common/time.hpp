// Clocks and ISO 8601 times of contactd: job and event timestamps (the formatting is the solver's one,
// contact/utc_time.hpp).
#pragma once

#include "contact/utc_time.hpp"

#include <cstdint>
#include <string>

namespace contactd {

using contact::now_unix_us;  // wall-clock time as microseconds since the Unix epoch (UTC)

// ISO 8601 UTC with microseconds, e.g. "2024-05-01T12:00:00.123456Z". Event and job timestamps use it.
inline std::string iso8601_us(std::int64_t unix_us) {
  return contact::iso8601_utc(unix_us, contact::TimePrecision::microseconds);
}
inline std::string now_iso8601() { return iso8601_us(now_unix_us()); }

}  // namespace contactd

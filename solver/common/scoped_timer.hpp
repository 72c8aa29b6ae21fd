// One way of timing for the whole solver: a ScopedTimer adds the seconds its scope took to a total (a result's or
// a report's field) when the scope ends, however it ends (early returns, exceptions), so that what the result
// reports is what was measured, and no timing is forgotten on a new return path.
#pragma once

#include <chrono>

namespace contact {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class ScopedTimer {
 public:
  explicit ScopedTimer(double& total) : total_(total), start_(Clock::now()) {}
  ~ScopedTimer() { total_ += seconds_since(start_); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;
  double seconds() const { return seconds_since(start_); }  // so far

 private:
  double& total_;
  Clock::time_point start_;
};

}  // namespace contact

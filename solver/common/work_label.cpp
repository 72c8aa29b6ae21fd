#include "contact/work_label.hpp"

#include <cstring>

namespace contact {

namespace {

// A plain array in static thread-local storage (the library is linked statically into the programs, so the
// initial-exec model: reading it in a signal handler allocates nothing).
thread_local char current[kWorkLabelSize] = {};

void set(const std::string& label) {
  const std::size_t n = std::min(label.size(), static_cast<std::size_t>(kWorkLabelSize - 1));
  std::memcpy(current, label.data(), n);
  current[n] = '\0';
}

}  // namespace

const char* work_label() noexcept { return current; }

WorkLabelScope::WorkLabelScope(const std::string& label) : previous_(current) { set(label); }

WorkLabelScope::~WorkLabelScope() { set(previous_); }

}  // namespace contact

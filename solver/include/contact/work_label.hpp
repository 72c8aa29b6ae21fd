// Which piece of work a thread does, for a crash handler to name: a program labels the thread that calls solve()
// (contactd: the job's id), and the solver carries the label onto every thread that works for that call (the
// per-body threads, a factorisation left on a thread of its own). A fatal signal's handler reads the label of the
// thread that took the signal, so that a server can tell which job brought it down and not run that job again.
#pragma once

#include <string>

namespace contact {

// The calling thread's label; an empty string when it has none. Async-signal-safe: it reads a buffer of the
// thread's own (at most kWorkLabelSize - 1 characters, NUL-terminated) and never allocates.
const char* work_label() noexcept;

constexpr int kWorkLabelSize = 64;

// Labels the calling thread for the scope's life (a longer label is cut to kWorkLabelSize - 1 characters); the
// previous label comes back at its end.
class WorkLabelScope {
 public:
  explicit WorkLabelScope(const std::string& label);
  ~WorkLabelScope();
  WorkLabelScope(const WorkLabelScope&) = delete;
  WorkLabelScope& operator=(const WorkLabelScope&) = delete;

 private:
  std::string previous_;
};

}  // namespace contact

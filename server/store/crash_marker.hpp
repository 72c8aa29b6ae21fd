// A job that brings the server down is marked on disk by the signal that kills it, so that the next start does
// not run it again blindly (docs/server.md, "Restarts").
//
// A fatal signal (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) taken on a thread that works for a job's solve (its
// worker, or a thread the solver started for it: contact/work_label.hpp carries the job's id there) writes
// <data>/jobs/<id>/crashed, holding the signal's name, and then dies of the signal as it would have. At the next
// start JobRecovery fails that job at once with the signal named, while the other jobs the crash interrupted are
// queued again as usual. A crash on a thread that works for no job marks nothing: every job it interrupted counts
// one interruption (--max-attempts).
#pragma once

#include <optional>
#include <string>

namespace contactd {

constexpr const char* kCrashMarkerFile = "crashed";

// Installs the handler for the fatal signals (once per process; `jobs_dir` is <data>/jobs).
void install_crash_marker(const std::string& jobs_dir);

// The signal's name in a job directory's marker (e.g. "SIGSEGV"), or nullopt when there is none.
std::optional<std::string> read_crash_marker(const std::string& job_dir);
// Removes the marker (the job's fate is recorded in its state by then).
void remove_crash_marker(const std::string& job_dir);

}  // namespace contactd

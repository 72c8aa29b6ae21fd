#include "store/crash_marker.hpp"

#include "contact/work_label.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cstring>
#include <fstream>

namespace contactd {

namespace {

// Everything below runs inside a signal handler: only async-signal-safe calls (open, write, fsync, close, raise),
// no allocation, paths built in fixed buffers.
constexpr std::size_t kPathSize = 4096;
char jobs_dir_path[kPathSize] = {};

constexpr int kFatalSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

const char* signal_name(int signal) {
  switch (signal) {
    case SIGSEGV:
      return "SIGSEGV";
    case SIGBUS:
      return "SIGBUS";
    case SIGFPE:
      return "SIGFPE";
    case SIGILL:
      return "SIGILL";
    case SIGABRT:
      return "SIGABRT";
    default:
      return "a fatal signal";
  }
}

void write_text(int fd, const char* text) {
  std::size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = ::write(fd, text, left);
    if (n <= 0) return;
    text += n;
    left -= static_cast<std::size_t>(n);
  }
}

// Appends `text` to the NUL-terminated `buffer` of kPathSize; false if it does not fit.
bool append(char* buffer, const char* text) {
  const std::size_t have = std::strlen(buffer), add = std::strlen(text);
  if (have + add + 1 > kPathSize) return false;
  std::memcpy(buffer + have, text, add + 1);
  return true;
}

// The job's id is checked to be one (a UUID: it becomes a path) by its characters alone: is_job_id allocates
// nothing, but a label is any text a program set.
bool marks_a_job(const char* label) {
  const std::size_t n = std::strlen(label);
  if (n != 36) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const char c = label[i];
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? c != '-' : !((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

void on_fatal_signal(int signal) {
  const char* label = contact::work_label();
  const char* name = signal_name(signal);
  if (marks_a_job(label)) {
    char path[kPathSize] = {};
    if (append(path, jobs_dir_path) && append(path, "/") && append(path, label) && append(path, "/") &&
        append(path, kCrashMarkerFile)) {
      const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
      if (fd >= 0) {
        write_text(fd, name);
        write_text(fd, "\n");
        ::fsync(fd);
        ::close(fd);
      }
    }
    write_text(2, "contactd: ");
    write_text(2, name);
    write_text(2, " while solving job ");
    write_text(2, label);
    write_text(2, ": the job is marked and will not run again at the next start\n");
  } else {
    write_text(2, "contactd: ");
    write_text(2, name);
    write_text(2, " outside any job's solve\n");
  }
  // SA_RESETHAND put the default action back: the process dies of the signal as it would have (a core where
  // the system keeps cores), and whoever supervises it sees the real cause.
  ::raise(signal);
}

}  // namespace

void install_crash_marker(const std::string& jobs_dir) {
  jobs_dir_path[0] = '\0';
  if (jobs_dir.size() + 1 > kPathSize) return;  // no room: nothing is marked, interruptions still count
  std::memcpy(jobs_dir_path, jobs_dir.c_str(), jobs_dir.size() + 1);
  struct sigaction action {};
  action.sa_handler = on_fatal_signal;
  action.sa_flags = SA_RESETHAND | SA_NODEFER;
  sigemptyset(&action.sa_mask);
  for (const int signal : kFatalSignals) ::sigaction(signal, &action, nullptr);
}

std::optional<std::string> read_crash_marker(const std::string& job_dir) {
  std::ifstream in(job_dir + "/" + kCrashMarkerFile);
  if (!in) return std::nullopt;
  std::string name;
  std::getline(in, name);
  if (name.rfind("SIG", 0) != 0 || name.size() > 16) name = "a fatal signal";
  return name;
}

void remove_crash_marker(const std::string& job_dir) { ::unlink((job_dir + "/" + kCrashMarkerFile).c_str()); }

}  // namespace contactd

#include "jobs/mpi_job.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <sstream>

namespace contactd {

namespace {

constexpr std::size_t kMaxLine = 64u << 20;  // an iteration line of a huge job; more is a broken child
constexpr std::size_t kStderrTail = 4096;    // the child's last words kept for the message

contact::StopReason stop_reason_of(const std::string& s) {
  for (auto r : {contact::StopReason::converged, contact::StopReason::max_iterations, contact::StopReason::stagnation,
                 contact::StopReason::cancelled, contact::StopReason::error})
    if (s == contact::to_string(r)) return r;
  return contact::StopReason::error;
}

// The last n non-empty lines of the child's stderr, joined by " / " (mpirun's banner lines of dashes skipped).
std::string last_lines(const std::string& text, size_t n) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (l.find_first_not_of(" -") != std::string::npos) lines.push_back(l);
  std::string out;
  for (size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i)
    out += (out.empty() ? "" : " / ") + lines[i];
  return out;
}

}  // namespace

std::vector<std::string> split_launcher(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

namespace {

// One MPI run: the child (the launcher, its ranks) started in its own process group, its stdout read as progress
// lines and its stderr kept for the message, a stop request forwarded, and its end read back as an outcome.
class MpiRun {
 public:
  MpiRun(const MpiSettings& settings, const ProgressLine& on_progress, const contact::CancelToken& cancel)
      : settings_(settings), on_progress_(on_progress), cancel_(cancel) {}

  MpiOutcome run(std::vector<std::string> args) {
    start_ = std::chrono::steady_clock::now();
    if (!spawn(args)) return outcome_;
    pump();
    wait_for_child();
    return outcome_of_child();
  }

 private:
  // Forks and executes `args`, its stdout and stderr on pipes; false (outcome_'s message says why) if it cannot.
  bool spawn(std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (::pipe2(out_pipe_, O_CLOEXEC) != 0) return cannot_start();
    if (::pipe2(err_pipe_, O_CLOEXEC) != 0) {
      ::close(out_pipe_[0]);
      ::close(out_pipe_[1]);
      return cannot_start();
    }
    pid_ = ::fork();
    if (pid_ == 0) exec_child(argv);
    ::close(out_pipe_[1]);
    ::close(err_pipe_[1]);
    if (pid_ < 0) {
      ::close(out_pipe_[0]);
      ::close(err_pipe_[0]);
      return cannot_start();
    }
    ::setpgid(pid_, pid_);
    return true;
  }

  bool cannot_start() {
    outcome_.message = std::string("cannot start the MPI launcher: ") + std::strerror(errno);
    return false;
  }

  // In the child after fork().
  [[noreturn]] void exec_child(std::vector<char*>& argv) {
    ::setpgid(0, 0);  // its own process group: a stuck run is killed whole
    // contactd blocks SIGTERM/SIGINT in its threads and ignores SIGPIPE; the child starts with neither.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::signal(SIGPIPE, SIG_DFL);
    ::dup2(out_pipe_[1], 1);
    ::dup2(err_pipe_[1], 2);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, 0);
    ::execvp(argv[0], argv.data());
    const char* what = "cannot run the MPI launcher: exec failed\n";
    (void)!::write(2, what, std::strlen(what));
    ::_exit(127);
  }

  // Reads both pipes until the child closes them, passing on a stop request.
  void pump() {
    bool out_open = true, err_open = true;
    char buffer[65536];
    while (out_open || err_open) {
      forward_stop_request();
      pollfd fds[2] = {{out_open ? out_pipe_[0] : -1, POLLIN, 0}, {err_open ? err_pipe_[0] : -1, POLLIN, 0}};
      if (::poll(fds, 2, 200) < 0 && errno != EINTR) break;
      for (int i = 0; i < 2; ++i) {
        if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
        const ssize_t n = ::read(fds[i].fd, buffer, sizeof buffer);
        if (n <= 0) {
          if (n < 0 && errno == EINTR) continue;
          (i == 0 ? out_open : err_open) = false;
          continue;
        }
        if (i == 0)
          take_output(buffer, static_cast<size_t>(n));
        else
          take_error_output(buffer, static_cast<size_t>(n));
      }
    }
    take_line();
    ::close(out_pipe_[0]);
    ::close(err_pipe_[0]);
  }

  // SIGUSR1 once the job is cancelled (mpirun forwards it to the ranks; a direct child takes it itself), and
  // the whole process group killed kill_after_seconds later.
  void forward_stop_request() {
    if (cancel_.cancelled() && !asked_) {
      ::kill(pid_, SIGUSR1);
      asked_ = true;
      asked_at_ = std::chrono::steady_clock::now();
    }
    if (asked_ && !killed_ &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - asked_at_).count() >
            settings_.kill_after_seconds) {
      ::kill(-pid_, SIGKILL);
      killed_ = true;
    }
  }

  void take_output(const char* bytes, size_t n) {
    for (size_t k = 0; k < n; ++k) {
      if (bytes[k] == '\n') {
        take_line();
      } else if (line_.size() < kMaxLine) {
        line_.push_back(bytes[k]);
      } else {
        broken_ = true;
      }
    }
  }

  void take_error_output(const char* bytes, size_t n) {
    err_.append(bytes, n);
    if (err_.size() > 2 * kStderrTail) err_.erase(0, err_.size() - kStderrTail);
  }

  // One progress line: an iteration or an adaptive step (passed on) or the result.
  void take_line() {
    if (line_.empty()) return;
    nlohmann::json j = nlohmann::json::parse(line_, nullptr, false);
    line_.clear();
    if (!j.is_object() || !j.contains("type")) {
      broken_ = true;
      return;
    }
    const std::string type = j.value("type", "");
    j.erase("type");
    if (type == "iteration") {
      // The iterations done so far, also for a run that ends without its result object.
      if (j.contains("iteration") && j["iteration"].is_number_integer())
        outcome_.iterations = j["iteration"].get<int>();
      on_progress_("iteration", j);
    }
    if (type == "adaptive_step" || type == "load_step") on_progress_(type, j);
    if (type == "result") result_ = std::move(j);
  }

  void wait_for_child() {
    while (::waitpid(pid_, &status_, 0) < 0 && errno == EINTR) {
    }
    outcome_.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  MpiOutcome outcome_of_child() {
    if (result_.is_object()) {
      outcome_.stop_reason = stop_reason_of(result_.value("stop_reason", "error"));
      outcome_.message = result_.value("message", "");
      outcome_.iterations = result_.value("iterations", 0);
      outcome_.converged = result_.value("converged", false);
      outcome_.wall_seconds = result_.value("wall_seconds", outcome_.wall_seconds);
      outcome_.result_written = result_.value("result_written", false);
      if (result_.contains("steps") && result_["steps"].is_array()) outcome_.steps = result_["steps"];
      if (result_.contains("warnings") && result_["warnings"].is_array()) outcome_.warnings = result_["warnings"];
      if (result_.contains("collapse") && result_["collapse"].is_object()) outcome_.collapse = result_["collapse"];
      return outcome_;
    }
    std::ostringstream os;
    os << "the MPI run ended without a result (";
    if (WIFEXITED(status_))
      os << "exit code " << WEXITSTATUS(status_);
    else if (WIFSIGNALED(status_))
      os << "killed by signal " << WTERMSIG(status_);
    os << (broken_ ? ", unreadable progress" : "") << ")";
    const std::string words = last_lines(err_, 3);
    if (!words.empty()) os << ": " << words;
    outcome_.stop_reason = asked_ ? contact::StopReason::cancelled : contact::StopReason::error;
    outcome_.message = os.str();
    return outcome_;
  }

  const MpiSettings& settings_;
  const ProgressLine& on_progress_;
  const contact::CancelToken& cancel_;
  MpiOutcome outcome_;
  std::chrono::steady_clock::time_point start_;
  int out_pipe_[2] = {-1, -1}, err_pipe_[2] = {-1, -1};
  pid_t pid_ = -1;
  int status_ = 0;
  std::string line_, err_;  // the progress line being read; the tail of stderr
  nlohmann::json result_;
  bool asked_ = false, killed_ = false, broken_ = false;
  std::chrono::steady_clock::time_point asked_at_;
};

}  // namespace

MpiOutcome run_mpi_job(const MpiSettings& settings, int ranks, const std::string& job_file,
                       const std::string& result_path, const std::string& job_id, long max_dofs,
                       const ProgressLine& on_progress, const contact::CancelToken& cancel) {
  std::vector<std::string> args;
  for (std::string a : settings.launcher) {
    for (size_t at; (at = a.find("{ranks}")) != std::string::npos;) a.replace(at, 7, std::to_string(ranks));
    args.push_back(a);
  }
  for (const std::string& a :
       {settings.solver, job_file, std::string("-o"), result_path, std::string("--progress"), std::string("ndjson"),
        std::string("--progress-pairs"), std::string("all"), std::string("--job-id"), job_id, std::string("--max-dofs"),
        std::to_string(max_dofs), std::string("--no-mesh-files")})
    args.push_back(a);
  return MpiRun(settings, on_progress, cancel).run(std::move(args));
}

}  // namespace contactd

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

constexpr std::size_t kMaxLine = 64u << 20;     // an iteration line of a huge job; more is a broken child
constexpr std::size_t kStderrTail = 4096;        // the child's last words kept for the message

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

MpiOutcome run_mpi_job(const MpiSettings& settings, int ranks, const std::string& job_file,
                       const std::string& result_path, const std::string& job_id, long max_dofs,
                       const std::function<void(const nlohmann::json&)>& on_iteration,
                       const contact::CancelToken& cancel) {
  MpiOutcome outcome;
  std::vector<std::string> args;
  for (std::string a : settings.launcher) {
    for (size_t at; (at = a.find("{ranks}")) != std::string::npos;) a.replace(at, 7, std::to_string(ranks));
    args.push_back(a);
  }
  for (const std::string& a : {settings.solver, job_file, std::string("-o"), result_path, std::string("--progress"),
                               std::string("ndjson"), std::string("--job-id"), job_id, std::string("--max-dofs"),
                               std::to_string(max_dofs), std::string("--no-mesh-files")})
    args.push_back(a);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int out_pipe[2], err_pipe[2];
  if (::pipe2(out_pipe, O_CLOEXEC) != 0) {
    outcome.message = std::string("cannot start the MPI launcher: ") + std::strerror(errno);
    return outcome;
  }
  if (::pipe2(err_pipe, O_CLOEXEC) != 0) {
    ::close(out_pipe[0]);
    ::close(out_pipe[1]);
    outcome.message = std::string("cannot start the MPI launcher: ") + std::strerror(errno);
    return outcome;
  }
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);  // its own process group: a stuck run is killed whole
    // contactd blocks SIGTERM/SIGINT in its threads and ignores SIGPIPE; the child starts with neither.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::signal(SIGPIPE, SIG_DFL);
    ::dup2(out_pipe[1], 1);
    ::dup2(err_pipe[1], 2);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, 0);
    ::execvp(argv[0], argv.data());
    const char* what = "cannot run the MPI launcher: exec failed\n";
    (void)!::write(2, what, std::strlen(what));
    ::_exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  if (pid < 0) {
    ::close(out_pipe[0]);
    ::close(err_pipe[0]);
    outcome.message = std::string("cannot start the MPI launcher: ") + std::strerror(errno);
    return outcome;
  }
  ::setpgid(pid, pid);

  std::string line, err;
  nlohmann::json result;
  bool out_open = true, err_open = true, asked = false, killed = false, broken = false;
  std::chrono::steady_clock::time_point asked_at;
  auto take_line = [&]() {
    if (line.empty()) return;
    nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    line.clear();
    if (!j.is_object() || !j.contains("type")) {
      broken = true;
      return;
    }
    const std::string type = j.value("type", "");
    j.erase("type");
    if (type == "iteration") {
      // The iterations done so far, also for a run that ends without its result object.
      if (j.contains("iteration") && j["iteration"].is_number_integer()) outcome.iterations = j["iteration"].get<int>();
      on_iteration(j);
    }
    if (type == "result") result = std::move(j);
  };
  char buffer[65536];
  while (out_open || err_open) {
    if (cancel.cancelled() && !asked) {
      ::kill(pid, SIGUSR1);  // mpirun forwards it to the ranks (a direct child takes it itself)
      asked = true;
      asked_at = std::chrono::steady_clock::now();
    }
    if (asked && !killed &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - asked_at).count() > settings.kill_after_seconds) {
      ::kill(-pid, SIGKILL);
      killed = true;
    }
    pollfd fds[2] = {{out_open ? out_pipe[0] : -1, POLLIN, 0}, {err_open ? err_pipe[0] : -1, POLLIN, 0}};
    if (::poll(fds, 2, 200) < 0 && errno != EINTR) break;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = ::read(fds[i].fd, buffer, sizeof buffer);
      if (n <= 0) {
        if (n < 0 && errno == EINTR) continue;
        (i == 0 ? out_open : err_open) = false;
        continue;
      }
      if (i == 1) {
        err.append(buffer, static_cast<size_t>(n));
        if (err.size() > 2 * kStderrTail) err.erase(0, err.size() - kStderrTail);
        continue;
      }
      for (ssize_t k = 0; k < n; ++k) {
        if (buffer[k] == '\n') {
          take_line();
        } else if (line.size() < kMaxLine) {
          line.push_back(buffer[k]);
        } else {
          broken = true;
        }
      }
    }
  }
  take_line();
  ::close(out_pipe[0]);
  ::close(err_pipe[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  outcome.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (result.is_object()) {
    outcome.stop_reason = stop_reason_of(result.value("stop_reason", "error"));
    outcome.message = result.value("message", "");
    outcome.iterations = result.value("iterations", 0);
    outcome.converged = result.value("converged", false);
    outcome.wall_seconds = result.value("wall_seconds", outcome.wall_seconds);
    outcome.result_written = result.value("result_written", false);
    if (result.contains("steps") && result["steps"].is_array()) outcome.steps = result["steps"];
    return outcome;
  }
  std::ostringstream os;
  os << "the MPI run ended without a result (";
  if (WIFEXITED(status))
    os << "exit code " << WEXITSTATUS(status);
  else if (WIFSIGNALED(status))
    os << "killed by signal " << WTERMSIG(status);
  os << (broken ? ", unreadable progress" : "") << ")";
  const std::string words = last_lines(err, 3);
  if (!words.empty()) os << ": " << words;
  outcome.stop_reason = asked ? contact::StopReason::cancelled : contact::StopReason::error;
  outcome.message = os.str();
  return outcome;
}

}  // namespace contactd

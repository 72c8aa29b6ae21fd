// contactd: the contact solver as a long-running HTTP service.
//   contactd [--host H] [--port P] [--data-dir D] [--workers N] ...   (every flag also has a CONTACTD_* variable)
// With no configuration it serves http://127.0.0.1:8080 and keeps its jobs in ./contactd-data.
// SIGTERM or SIGINT: graceful shutdown (docs/server.md, "Shutdown"), exit status 0.
#include "common/log.hpp"
#include "http_server.hpp"
#include "jobs/body_budget.hpp"
#include "jobs/job_queue.hpp"
#include "metrics/metrics.hpp"
#include "store/crash_marker.hpp"
#include "store/job_store.hpp"

#include "contact/solve.hpp"

#include <CLI/CLI.hpp>

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

namespace {

// The flags bind directly to the settings they set (their defaults are the structs' own).
struct Config {
  std::string data_dir = "./contactd-data";
  std::string allowed_hosts;  // parsed into http.allowed_hosts
  std::string mpi_launcher;   // split into queue.mpi.launcher
  contactd::QueueSettings queue = [] {
    contactd::QueueSettings q;
    q.workers = 0;  // the number of cores
    q.mpi.max_ranks = 4;
    return q;
  }();
  contactd::HttpSettings http;
};

// The flags, in groups. Every flag has an environment variable; a flag given on the command line wins.

// Where it listens and keeps its jobs.
void add_service_flags(CLI::App& app, Config& c) {
  app.add_option("--host", c.http.host, "address to listen on")->envname("CONTACTD_HOST")->capture_default_str();
  app.add_option("--port", c.http.port, "TCP port (0: any free port, printed at start-up)")
      ->envname("CONTACTD_PORT")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--data-dir", c.data_dir, "job store directory (created if missing)")
      ->envname("CONTACTD_DATA_DIR")
      ->capture_default_str();
}

// How many jobs, and how large.
void add_job_limit_flags(CLI::App& app, Config& c) {
  app.add_option("--workers", c.queue.workers, "jobs solved at once (0: one per core)")
      ->envname("CONTACTD_WORKERS")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--small-job-workers", c.queue.small_workers,
                 "more workers that take only small jobs, so that a job of seconds never waits behind long ones")
      ->envname("CONTACTD_SMALL_JOB_WORKERS")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  app.add_option("--small-job-dofs", c.queue.small_job_dofs,
                 "a job is small with at most this many unknowns times load steps (one process, no adaptivity, at "
                 "most 16 bodies)")
      ->envname("CONTACTD_SMALL_JOB_DOFS")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--small-job-seconds", c.queue.small_job_seconds,
                 "a run on the small-job lane longer than this is stopped and queued again for a general worker")
      ->envname("CONTACTD_SMALL_JOB_SECONDS")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-queued", c.queue.max_queued, "queued jobs beyond which submissions get 503")
      ->envname("CONTACTD_MAX_QUEUED")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--max-dofs", c.queue.max_dofs, "largest job accepted, in degrees of freedom over all bodies")
      ->envname("CONTACTD_MAX_DOFS")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-bodies", c.queue.max_bodies, "most bodies a job may have (the command line takes 16384)")
      ->envname("CONTACTD_MAX_BODIES")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--max-contacts", c.queue.max_contacts,
                 "most contact pairs a job may have (the command line takes 65536)")
      ->envname("CONTACTD_MAX_CONTACTS")
      ->check(CLI::Range(1, 4000000))
      ->capture_default_str();
  app.add_option("--max-load-steps", c.queue.max_load_steps, "most load steps a job may have")
      ->envname("CONTACTD_MAX_LOAD_STEPS")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--max-result-bytes", c.queue.max_result_bytes,
                 "largest result a job may write, estimated before it runs from its meshes' nodes and the steps it "
                 "keeps (the disk a job's result takes; its steps are written as they are solved)")
      ->envname("CONTACTD_MAX_RESULT_BYTES")
      ->check(CLI::Range(1e6, 1e15))
      ->capture_default_str();
  app.add_option("--max-validation-seconds", c.queue.max_validation_seconds,
                 "longest a request's validation of a job may take (400 beyond, naming the time)")
      ->envname("CONTACTD_MAX_VALIDATION_SECONDS")
      ->check(CLI::Range(0.001, 3600.0))
      ->capture_default_str();
  app.add_option("--max-interface-bytes", c.queue.max_interface_bytes,
                 "most memory a job's interface problem (method interface_newton: dense blocks over each body's "
                 "contact unknowns) may take, estimated before it runs from its contact edges' nodes")
      ->envname("CONTACTD_MAX_INTERFACE_BYTES")
      ->check(CLI::Range(1e6, 1e15))
      ->capture_default_str();
}

// Jobs on MPI ranks (docs/parallel.md).
void add_mpi_flags(CLI::App& app, Config& c) {
  app.add_option("--mpi-launcher", c.mpi_launcher,
                 "run jobs with parallel.ranks > 1 through this launcher, {ranks} replaced, e.g. 'mpirun -n {ranks}' "
                 "(docs/parallel.md; empty: every job runs in this process)")
      ->envname("CONTACTD_MPI_LAUNCHER");
  app.add_option("--max-ranks", c.queue.mpi.max_ranks, "largest parallel.ranks accepted (with --mpi-launcher)")
      ->envname("CONTACTD_MAX_RANKS")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  app.add_option("--solver-binary", c.queue.mpi.solver,
                 "the contact-solve that MPI jobs run (default: the one next to contactd)")
      ->envname("CONTACTD_SOLVER_BINARY");
}

// How long a job may run, what it keeps, and how long it is kept.
void add_job_lifetime_flags(CLI::App& app, Config& c) {
  app.add_option("--time-limit-seconds", c.queue.time_limit_seconds, "wall-time limit per run (0: none)")
      ->envname("CONTACTD_TIME_LIMIT_SECONDS")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--max-attempts", c.queue.max_attempts,
                 "runs cut short by the server dying after which a job ends FAILED (interrupted)")
      ->envname("CONTACTD_MAX_ATTEMPTS")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--max-event-log-bytes", c.queue.max_event_log_bytes,
                 "size of a job's event log beyond which iteration events are not recorded")
      ->envname("CONTACTD_MAX_EVENT_LOG_BYTES")
      ->check(CLI::Range(std::uint64_t{64} << 10, std::uint64_t{1} << 40))
      ->capture_default_str();
  app.add_option("--retention-seconds", c.queue.retention_seconds,
                 "finished jobs older than this are deleted (0: kept)")
      ->envname("CONTACTD_RETENTION_SECONDS")
      ->check(CLI::Range(0.0, 1e10))
      ->capture_default_str();
  app.add_option("--retention-bytes", c.queue.retention_bytes,
                 "finished jobs beyond this total size are deleted, oldest first (0: no limit)")
      ->envname("CONTACTD_RETENTION_BYTES")
      ->capture_default_str();
}

// Who may ask: the token, the Host allow-list, the access log.
void add_access_flags(CLI::App& app, Config& c) {
  app.add_option("--token", c.http.token, "bearer token every /v1 request must carry (prefer the variable)")
      ->envname("CONTACTD_TOKEN");
  app.add_option("--allowed-hosts", c.allowed_hosts,
                 "host names the Host header may give, comma-separated ('*': any; default: localhost, 127.0.0.1, "
                 "[::1] and --host)")
      ->envname("CONTACTD_ALLOWED_HOSTS");
  app.add_flag("--access-log", c.http.access_log, "log every request to stderr")->envname("CONTACTD_ACCESS_LOG");
}

// Progress streams and the threads that serve them.
void add_stream_flags(CLI::App& app, Config& c) {
  app.add_option("--heartbeat-seconds", c.http.heartbeat_seconds, "progress-stream heartbeat period")
      ->envname("CONTACTD_HEARTBEAT_SECONDS")
      ->check(CLI::Range(1, 3600))
      ->capture_default_str();
  app.add_option("--max-streams", c.http.max_streams, "concurrent progress streams (503 beyond)")
      ->envname("CONTACTD_MAX_STREAMS")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--http-threads", c.http.http_threads, "HTTP connection threads (0: max-streams + 32)")
      ->envname("CONTACTD_HTTP_THREADS")
      ->check(CLI::Range(0, 20000))
      ->capture_default_str();
}

// Connections and request heads (the connection gate).
void add_connection_flags(CLI::App& app, Config& c) {
  app.add_option("--max-connections", c.http.max_connections, "open connections in total (503 beyond)")
      ->envname("CONTACTD_MAX_CONNECTIONS")
      ->check(CLI::Range(8, 100000))
      ->capture_default_str();
  app.add_option("--max-connections-per-client", c.http.max_connections_per_client,
                 "open connections per client address (503 beyond; 0: no limit)")
      ->envname("CONTACTD_MAX_CONNECTIONS_PER_CLIENT")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  app.add_option("--listen-backlog", c.http.listen_backlog, "connections the kernel queues before they are accepted")
      ->envname("CONTACTD_LISTEN_BACKLOG")
      ->check(CLI::Range(16, 65535))
      ->capture_default_str();
  app.add_option("--request-head-timeout-seconds", c.http.head_timeout_seconds,
                 "a request's line and headers must arrive within this (408 beyond)")
      ->envname("CONTACTD_REQUEST_HEAD_TIMEOUT_SECONDS")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--idle-timeout-seconds", c.http.idle_timeout_seconds,
                 "a kept-alive connection must start its next request within this")
      ->envname("CONTACTD_IDLE_TIMEOUT_SECONDS")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--request-body-timeout-seconds", c.http.body_timeout_seconds,
                 "a request's body must arrive within this (408 beyond)")
      ->envname("CONTACTD_REQUEST_BODY_TIMEOUT_SECONDS")
      ->check(CLI::Range(1.0, 3600.0))
      ->capture_default_str();
  app.add_option("--max-header-bytes", c.http.max_header_bytes, "size of a request's line and headers (431 beyond)")
      ->envname("CONTACTD_MAX_HEADER_BYTES")
      ->check(CLI::Range(1024, 1 << 20))
      ->capture_default_str();
  app.add_option("--max-header-fields", c.http.max_header_fields, "header fields in a request (431 beyond)")
      ->envname("CONTACTD_MAX_HEADER_FIELDS")
      ->check(CLI::Range(8, 1000))
      ->capture_default_str();
}

// Request bodies: their size, and how many are read and validated at once.
void add_request_body_flags(CLI::App& app, Config& c) {
  app.add_option("--max-request-bytes", c.http.max_request_bytes, "largest request body accepted (413 beyond)")
      ->envname("CONTACTD_MAX_REQUEST_BYTES")
      ->check(CLI::Range(1024, 1 << 30))
      ->capture_default_str();
  app.add_option("--max-large-bodies", c.http.max_large_bodies,
                 "request bodies over 256 KiB read and validated at once (others wait, then 503)")
      ->envname("CONTACTD_MAX_LARGE_BODIES")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--max-validations", c.http.max_validations, "jobs validated at once (0: one per core, at least 2)")
      ->envname("CONTACTD_MAX_VALIDATIONS")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
}

void add_flags(CLI::App& app, Config& c) {
  add_service_flags(app, c);
  add_job_limit_flags(app, c);
  add_mpi_flags(app, c);
  add_job_lifetime_flags(app, c);
  add_access_flags(app, c);
  add_stream_flags(app, c);
  add_connection_flags(app, c);
  add_request_body_flags(app, c);
}

// From here on, what any library prints on standard output (CHOLMOD's warnings, for one) goes to the log as
// "solver output: ..." lines instead of the server's stdout (a detached thread forwards it).
void capture_stdout() {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) return;
  std::fflush(stdout);
  if (::dup2(pipe_fds[1], STDOUT_FILENO) < 0) {
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    return;
  }
  ::close(pipe_fds[1]);
  std::thread([fd = pipe_fds[0]] {
    std::string pending;
    char buffer[4096];
    while (true) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      pending.append(buffer, static_cast<std::size_t>(n));
      std::size_t newline;
      while ((newline = pending.find('\n')) != std::string::npos) {
        const std::string line = pending.substr(0, newline);
        pending.erase(0, newline + 1);
        if (!line.empty()) contactd::log_line("solver output: " + line.substr(0, 1000));
      }
      if (pending.size() > 4096) {
        contactd::log_line("solver output: " + pending.substr(0, 1000));
        pending.clear();
      }
    }
  }).detach();
}

// The contact-solve that MPI jobs run: next to contactd (an installation, the Docker image), or one level up (the
// build tree: build/server/); else the one on the PATH.
std::string default_solver_binary(const char* argv0) {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto dir = (ec ? std::filesystem::path(argv0) : self).parent_path();
  for (const auto& candidate : {dir / "contact-solve", dir.parent_path() / "contact-solve"})
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate.string();
  return "contact-solve";
}

// The settings the flags give in another form, or leave to the machine.
void complete_settings(Config& config, const char* argv0) {
  if (config.queue.workers == 0)
    config.queue.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  config.http.allowed_hosts = contactd::parse_host_list(config.allowed_hosts);
  config.queue.mpi.launcher = contactd::split_launcher(config.mpi_launcher);
  if (config.queue.mpi.solver.empty()) config.queue.mpi.solver = default_solver_binary(argv0);
  // Retention is checked a few times per retention period (at most every 10 s).
  config.queue.janitor_interval_seconds =
      config.queue.retention_seconds > 0 ? std::min(10.0, std::max(0.2, config.queue.retention_seconds / 4)) : 10.0;
}

// Signals: blocked in every thread (the mask is inherited) and taken by one sigwait thread, which starts the
// shutdown outside any signal handler. SIGPIPE is ignored: a vanished client is a failed write, not a death.
sigset_t block_shutdown_signals() {
  ::signal(SIGPIPE, SIG_IGN);
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signals;
}

// 1. Refuse new jobs; /readyz says 503. 2. Running jobs stop at their next iteration and are stored back as
// QUEUED (their streams get that state event). 3. Streams close. 4. The listener stops. The exit status.
int shut_down(contactd::HttpServer& server, contactd::JobQueue& queue, std::thread& listener) {
  server.begin_shutdown();
  const bool workers_stopped = queue.shutdown(std::chrono::seconds(5));
  server.close_streams();
  server.wait_for_streams(std::chrono::seconds(2));
  if (!workers_stopped) {
    // A solve that does not reach its next iteration in time (a long factorisation): its state on disk says
    // RUNNING, so the next start runs it again. Exit without waiting for it.
    contactd::log_line("a worker did not stop in time; exiting anyway (its job runs again at the next start)");
    std::fflush(stdout);
    std::_Exit(0);
  }
  server.stop();
  listener.join();
  if (!contact::wait_for_background_work(10)) {  // a factorisation a cancel left running (contact/solve.hpp)
    contactd::log_line("stopped (a cancelled job's factorisation still runs: exiting without it)");
    std::fflush(nullptr);
    std::_Exit(0);
  }
  contactd::log_line("stopped");
  // Every job's state and events are on disk (committed and fsync'ed as they changed): nothing is left to do, and
  // the process ends here, without the libraries' exit handlers. HDF5's (H5_term_library) flushes the files it
  // still holds: a result write that failed for "no space left" leaves one in it, and that flush died of SIGSEGV
  // at every stop after a full disk.
  std::fflush(nullptr);
  std::_Exit(0);
}

// Serves until SIGTERM or SIGINT, then shuts down; the exit status. Throws what start-up cannot survive.
int serve(const Config& config, const sigset_t& signals) {
  using namespace contactd;
  JobStore store(config.data_dir);
  install_crash_marker(store.jobs_dir());
  Metrics metrics;
  BodyBudget budget(config.http.max_large_bodies, BodyBudget::validation_slots(config.http.max_validations), 256 * 1024,
                    std::chrono::seconds(10));
  JobQueue queue(store, metrics, budget, config.queue);
  HttpServer server(config.http, queue, store, metrics, budget);

  std::string error;
  const int port = server.bind(error);
  if (port < 0) {
    log_line("cannot listen on " + config.http.host + ":" + std::to_string(config.http.port) + ": " + error);
    return 1;
  }
  // Serve at once (the /v1 routes answer 503 "starting" and /readyz 503 until the store is read back).
  std::thread listener([&server] { server.listen(); });
  try {
    queue.recover();
    queue.start();
  } catch (...) {
    server.stop();
    listener.join();
    throw;
  }
  server.set_ready();
  std::printf("contactd %s listening on http://%s:%d (data dir %s, %d workers + %d for small jobs%s)\n",
              contact::solver_version(), config.http.host.c_str(), port, config.data_dir.c_str(), config.queue.workers,
              config.queue.small_workers, config.http.token.empty() ? "" : ", bearer token required");
  std::fflush(stdout);
  capture_stdout();

  int received = 0;
  sigwait(&signals, &received);
  log_line(std::string("received ") + (received == SIGTERM ? "SIGTERM" : "SIGINT") + ": shutting down");
  return shut_down(server, queue, listener);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"contactd: the contact solver as an HTTP service (docs/server.md)"};
  app.set_version_flag("--version", std::string("contactd ") + contact::solver_version());
  Config config;
  add_flags(app, config);
  CLI11_PARSE(app, argc, argv);
  complete_settings(config, argv[0]);
  contactd::BodyBudget::configure_allocator();
  const sigset_t signals = block_shutdown_signals();
  try {
    return serve(config, signals);
  } catch (const std::exception& e) {
    contactd::log_line(std::string("fatal: ") + e.what());
    return 1;
  }
}

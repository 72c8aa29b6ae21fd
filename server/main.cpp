// contactd: the contact solver as a long-running HTTP service.
//   contactd [--host H] [--port P] [--data-dir D] [--workers N] ...   (every flag also has a CONTACTD_* variable)
// With no configuration it serves http://127.0.0.1:8080 and keeps its jobs in ./contactd-data.
// SIGTERM or SIGINT: graceful shutdown (docs/server.md, "Shutdown"), exit status 0.
#include "http_server.hpp"
#include "job_queue.hpp"
#include "job_store.hpp"
#include "metrics.hpp"
#include "util.hpp"

#include "job/job.hpp"
#include "solve.hpp"

#include <CLI/CLI.hpp>

#include <pthread.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace {

struct Config {
  std::string host = "127.0.0.1";
  int port = 8080;
  std::string data_dir = "./contactd-data";
  int workers = 0;  // 0 = the number of cores
  std::size_t max_queued = 100;
  std::size_t max_request_bytes = 8u << 20;
  long max_dofs = contact::job::Limits{}.max_dofs;
  double time_limit_seconds = 0.0;
  std::string token;
  int heartbeat_seconds = 15;
  int max_streams = 64;
  int http_threads = 0;
  bool access_log = false;
};

// Every flag has an environment variable; a flag given on the command line wins.
void add_flags(CLI::App& app, Config& c) {
  app.add_option("--host", c.host, "address to listen on")->envname("CONTACTD_HOST")->capture_default_str();
  app.add_option("--port", c.port, "TCP port (0: any free port, printed at start-up)")
      ->envname("CONTACTD_PORT")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--data-dir", c.data_dir, "job store directory (created if missing)")
      ->envname("CONTACTD_DATA_DIR")
      ->capture_default_str();
  app.add_option("--workers", c.workers, "jobs solved at once (0: one per core)")
      ->envname("CONTACTD_WORKERS")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--max-queued", c.max_queued, "queued jobs beyond which submissions get 503")
      ->envname("CONTACTD_MAX_QUEUED")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--max-request-bytes", c.max_request_bytes, "largest request body accepted (413 beyond)")
      ->envname("CONTACTD_MAX_REQUEST_BYTES")
      ->check(CLI::Range(1024, 1 << 30))
      ->capture_default_str();
  app.add_option("--max-dofs", c.max_dofs, "largest job accepted, in degrees of freedom over all bodies")
      ->envname("CONTACTD_MAX_DOFS")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--time-limit-seconds", c.time_limit_seconds, "wall-time limit per run (0: none)")
      ->envname("CONTACTD_TIME_LIMIT_SECONDS")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--token", c.token, "bearer token every /v1 request must carry (prefer the variable)")
      ->envname("CONTACTD_TOKEN");
  app.add_option("--heartbeat-seconds", c.heartbeat_seconds, "progress-stream heartbeat period")
      ->envname("CONTACTD_HEARTBEAT_SECONDS")
      ->check(CLI::Range(1, 3600))
      ->capture_default_str();
  app.add_option("--max-streams", c.max_streams, "concurrent progress streams (503 beyond)")
      ->envname("CONTACTD_MAX_STREAMS")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--http-threads", c.http_threads, "HTTP connection threads (0: max-streams + 32)")
      ->envname("CONTACTD_HTTP_THREADS")
      ->check(CLI::Range(0, 20000))
      ->capture_default_str();
  app.add_flag("--access-log", c.access_log, "log every request to stderr")->envname("CONTACTD_ACCESS_LOG");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"contactd: the contact solver as an HTTP service (docs/server.md)"};
  Config config;
  add_flags(app, config);
  CLI11_PARSE(app, argc, argv);
  if (config.workers == 0) config.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  // Signals: blocked in every thread (the mask is inherited) and taken by one sigwait thread, which starts the
  // shutdown outside any signal handler. SIGPIPE is ignored: a vanished client is a failed write, not a death.
  ::signal(SIGPIPE, SIG_IGN);
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  using namespace contactd;
  try {
    JobStore store(config.data_dir);
    Metrics metrics;
    QueueSettings queue_settings;
    queue_settings.workers = config.workers;
    queue_settings.max_queued = config.max_queued;
    queue_settings.max_dofs = config.max_dofs;
    queue_settings.time_limit_seconds = config.time_limit_seconds;
    JobQueue queue(store, metrics, queue_settings);

    HttpSettings http;
    http.host = config.host;
    http.port = config.port;
    http.max_request_bytes = config.max_request_bytes;
    http.token = config.token;
    http.heartbeat_seconds = config.heartbeat_seconds;
    http.max_streams = config.max_streams;
    http.http_threads = config.http_threads;
    http.access_log = config.access_log;
    HttpServer server(http, queue, store, metrics);

    const int port = server.bind();
    if (port < 0) {
      log_line("cannot listen on " + config.host + ":" + std::to_string(config.port));
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
    std::printf("contactd %s listening on http://%s:%d (data dir %s, %d workers%s)\n", contact::solver_version(),
                config.host.c_str(), port, config.data_dir.c_str(), config.workers,
                config.token.empty() ? "" : ", bearer token required");
    std::fflush(stdout);

    int received = 0;
    sigwait(&signals, &received);
    log_line(std::string("received ") + (received == SIGTERM ? "SIGTERM" : "SIGINT") + ": shutting down");

    // 1. Refuse new jobs; /readyz says 503. 2. Running jobs stop at their next iteration and are stored back as
    // QUEUED (their streams get that state event). 3. Streams close. 4. The listener stops.
    server.begin_shutdown();
    const bool workers_stopped = queue.shutdown(std::chrono::seconds(5));
    server.close_streams();
    server.wait_for_streams(std::chrono::seconds(2));
    if (!workers_stopped) {
      // A solve that does not reach its next iteration in time (a long factorisation): its state on disk says
      // RUNNING, so the next start runs it again. Exit without waiting for it.
      log_line("a worker did not stop in time; exiting anyway (its job runs again at the next start)");
      std::fflush(stdout);
      std::_Exit(0);
    }
    server.stop();
    listener.join();
    log_line("stopped");
    return 0;
  } catch (const std::exception& e) {
    log_line(std::string("fatal: ") + e.what());
    return 1;
  }
}

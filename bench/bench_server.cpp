// bench_server: what contactd costs on top of the solver. Starts the real contactd (the one built next to this
// program) on a free loopback port with a temporary data directory and prints three tables:
//  1. server overhead per small job: submit -> `end` event as seen by a client, minus the solver's own time
//     (the end event's solve_seconds), over sequential flat_patch jobs;
//  2. event latency with 100 concurrent stream subscribers: the time from an event's creation (its `time` field)
//     to its arrival at each subscriber, for every iteration event of a job of ~2000 iterations;
//  3. requests per second on GET /v1/jobs/{id} with keep-alive clients.
// Never fails: it prints what it measured. Options: --jobs N (default 40), --subscribers N (default 100),
// --seconds S per throughput run (default 3).
#include <httplib.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace {

using Clock = std::chrono::steady_clock;

double now_unix() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

// "2024-05-01T12:00:00.123456Z" -> seconds since the epoch (UTC).
double parse_iso(const std::string& t) {
  std::tm tm{};
  if (t.size() < 20) return 0;
  tm.tm_year = std::stoi(t.substr(0, 4)) - 1900;
  tm.tm_mon = std::stoi(t.substr(5, 2)) - 1;
  tm.tm_mday = std::stoi(t.substr(8, 2));
  tm.tm_hour = std::stoi(t.substr(11, 2));
  tm.tm_min = std::stoi(t.substr(14, 2));
  tm.tm_sec = std::stoi(t.substr(17, 2));
  double fraction = 0;
  if (t.size() > 20 && t[19] == '.') fraction = std::stod("0" + t.substr(19, t.size() - 20));
  return static_cast<double>(timegm(&tm)) + fraction;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Contactd {
  pid_t pid = -1;
  int port = 0;
  std::string data_dir, log;

  bool start(const std::vector<std::string>& extra, const std::string& root = "/tmp") {
    std::string dir_template = root + "/contactd-bench-XXXXXX";
    if (!mkdtemp(dir_template.data())) return false;
    data_dir = dir_template;
    log = data_dir + ".log";
    std::vector<std::string> args = {CONTACTD_PATH, "--host", "127.0.0.1", "--port", "0", "--data-dir", data_dir};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) return false;
    for (int i = 0; i < 400 && port == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
      const std::string text = read_text(log);
      const auto at = text.find("listening on http://127.0.0.1:");
      if (at != std::string::npos) port = std::atoi(text.c_str() + at + std::strlen("listening on http://127.0.0.1:"));
    }
    return port > 0;
  }

  void stop() {
    if (pid > 0) {
      kill(pid, SIGTERM);
      int status = 0;
      waitpid(pid, &status, 0);
      pid = -1;
    }
    std::error_code ec;
    std::filesystem::remove_all(data_dir, ec);
    std::filesystem::remove(log, ec);
  }
};

nlohmann::json job_from(const std::string& example) {
  return nlohmann::json::parse(read_text(std::string(CONTACT_SOURCE_DIR) + "/api/examples/" + example));
}

std::string submit(httplib::Client& client, const nlohmann::json& job) {
  auto r = client.Post("/v1/jobs", job.dump(), "application/json");
  if (!r || r->status != 202) return "";
  return nlohmann::json::parse(r->body)["id"].get<std::string>();
}

// Reads a job's NDJSON stream until `end`; calls on_event(line, arrival unix time) for each event.
template <class F>
void stream(int port, const std::string& id, F on_event) {
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(60, 0);
  client.set_tcp_nodelay(true);
  std::string buffer;
  bool ended = false;
  client.Get(("/v1/jobs/" + id + "/events").c_str(), httplib::Headers{{"Accept", "application/x-ndjson"}},
             [&](const char* data, std::size_t n) {
               const double arrival = now_unix();
               buffer.append(data, n);
               std::size_t newline;
               while ((newline = buffer.find('\n')) != std::string::npos) {
                 const std::string line = buffer.substr(0, newline);
                 buffer.erase(0, newline + 1);
                 if (line.empty()) continue;  // heartbeat
                 on_event(line, arrival);
                 if (line.find("\"type\":\"end\"") != std::string::npos) ended = true;
               }
               return !ended;
             });
}

void print_row(const char* what, const char* unit, double p50, double p90, double max, const std::string& note) {
  std::printf("| %-52s | %-4s | %9.3f | %9.3f | %9.3f | %s\n", what, unit, p50, p90, max, note.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  int jobs = 40, subscribers = 100;
  double seconds = 3.0;
  for (int i = 1; i + 1 < argc; ++i) {
    if (!std::strcmp(argv[i], "--jobs"))
      jobs = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--subscribers"))
      subscribers = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--seconds"))
      seconds = std::atof(argv[++i]);
  }
  std::printf("bench_server: contactd %s, %u cores\n\n", CONTACTD_PATH, std::thread::hardware_concurrency());
  std::printf("| %-52s | %-4s | %9s | %9s | %9s | %s\n", "measure", "unit", "median", "p90", "max", "note");
  std::printf("|%s|%s|%s|%s|%s|%s\n", std::string(54, '-').c_str(), std::string(6, '-').c_str(),
              std::string(11, '-').c_str(), std::string(11, '-').c_str(), std::string(11, '-').c_str(), "------");

  // --- 1. overhead per small job, with the data directory on disk and (if there is one) on tmpfs ------------
  // On tmpfs fsync costs nothing: the difference between the two is what durability costs on this disk.
  for (const char* root_dir : {"/dev/shm", "/tmp"}) {
    const std::string root = root_dir;
    if (!std::filesystem::is_directory(root)) continue;
    Contactd server;
    if (!server.start({"--workers", "1"}, root)) {
      std::printf("could not start contactd (log: %s)\n", server.log.c_str());
      server.stop();
      return 0;
    }
    httplib::Client client("127.0.0.1", server.port);
    client.set_tcp_nodelay(true);
    const nlohmann::json job = job_from("flat_patch.json");
    std::vector<double> total_ms, solve_ms, overhead_ms;
    for (int k = 0; k < jobs; ++k) {
      const auto t0 = Clock::now();
      const std::string id = submit(client, job);
      if (id.empty()) continue;
      double solve = 0;
      stream(server.port, id, [&](const std::string& line, double) {
        if (line.find("\"type\":\"end\"") != std::string::npos)
          solve = nlohmann::json::parse(line).value("solve_seconds", 0.0);
      });
      const double total = std::chrono::duration<double>(Clock::now() - t0).count();
      total_ms.push_back(total * 1e3);
      solve_ms.push_back(solve * 1e3);
      overhead_ms.push_back((total - solve) * 1e3);
    }
    const std::string where = "data dir on " + root + (root == "/dev/shm" ? " (tmpfs)" : "");
    print_row(("submit -> end, total; " + where).c_str(), "ms", percentile(total_ms, 0.5), percentile(total_ms, 0.9),
              percentile(total_ms, 1.0), std::to_string(total_ms.size()) + " flat_patch jobs, one after another");
    print_row("  of which the solver (end.solve_seconds)", "ms", percentile(solve_ms, 0.5), percentile(solve_ms, 0.9),
              percentile(solve_ms, 1.0), "");
    print_row("  server overhead per small job", "ms", percentile(overhead_ms, 0.5), percentile(overhead_ms, 0.9),
              percentile(overhead_ms, 1.0), "HTTP, validation, store, queue, events, result file");
    if (root == "/dev/shm") {
      server.stop();
      continue;
    }

    // --- 3. GET /v1/jobs/{id} throughput (same server) ------------------------------------------------------
    const std::string id = submit(client, job);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    for (int threads : {1, 4}) {
      std::atomic<long> count{0};
      std::atomic<bool> stop{false};
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t)
        pool.emplace_back([&] {
          httplib::Client c("127.0.0.1", server.port);
          c.set_keep_alive(true);
          c.set_tcp_nodelay(true);
          while (!stop) {
            auto r = c.Get(("/v1/jobs/" + id).c_str());
            if (r && r->status == 200) ++count;
          }
        });
      const auto t0 = Clock::now();
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
      stop = true;
      for (auto& t : pool) t.join();
      const double rate = static_cast<double>(count.load()) / std::chrono::duration<double>(Clock::now() - t0).count();
      const std::string what =
          "GET /v1/jobs/{id}, " + std::to_string(threads) + " keep-alive client" + (threads > 1 ? "s" : "");
      std::printf("| %-52s | %-4s | %9.0f | %9s | %9s | %s\n", what.c_str(), "1/s", rate, "", "",
                  "requests per second (client on the same 2-core machine)");
    }
    server.stop();
  }

  // --- 4. a small job's latency while long jobs hold every general worker ---------------------------------------
  // Two long jobs on two general workers; flat patches submitted one after another: with the small-job lane they
  // run at once, without it (--small-job-workers 0) each waits for a long job to end (here: 3 s each).
  {
    std::vector<double> p50(2);
    for (int lane = 1; lane >= 0; --lane) {
      Contactd server;
      if (!server.start({"--workers", "2", "--small-job-workers", std::to_string(lane)})) {
        std::printf("could not start contactd\n");
        server.stop();
        return 0;
      }
      httplib::Client client("127.0.0.1", server.port);
      nlohmann::json blocker = job_from("seed_layers.json");  // 33k unknowns: a general worker's job
      blocker["solver"]["criterion"] = "residual";
      blocker["solver"]["tolerance"] = 1e-300;
      blocker["solver"]["max_iterations"] = 100000;
      blocker["solver"]["gamma"] = 0.002;
      for (auto& b : blocker["bodies"]) b["mesh"]["block"]["ny"] = 256;
      std::vector<std::string> blockers = {submit(client, blocker), submit(client, blocker)};
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      std::vector<double> latency_ms;
      const nlohmann::json small = job_from("flat_patch.json");
      const int rounds = lane ? 10 : 2;
      for (int k = 0; k < rounds; ++k) {
        const auto t0 = Clock::now();
        const std::string id = submit(client, small);
        if (id.empty()) continue;
        if (!lane) {  // the long jobs end after 3 s so that the flat patch gets a worker at all
          std::this_thread::sleep_for(std::chrono::seconds(3));
          for (const auto& b : blockers) client.Post(("/v1/jobs/" + b + "/cancel").c_str(), "", "application/json");
        }
        stream(server.port, id, [](const std::string&, double) {});
        latency_ms.push_back(std::chrono::duration<double>(Clock::now() - t0).count() * 1e3);
        if (!lane) blockers = {submit(client, blocker), submit(client, blocker)};
        if (!lane) std::this_thread::sleep_for(std::chrono::milliseconds(500));
      }
      for (const auto& b : blockers) client.Post(("/v1/jobs/" + b + "/cancel").c_str(), "", "application/json");
      p50[lane] = percentile(latency_ms, 0.5);
      const std::string what = std::string("small job submit -> end, two long jobs running, ") +
                               (lane ? "small-job lane" : "no lane");
      print_row(what.c_str(), "ms", percentile(latency_ms, 0.5), percentile(latency_ms, 0.9),
                percentile(latency_ms, 1.0),
                std::to_string(latency_ms.size()) + " flat_patch jobs" +
                    (lane ? "" : " (each waits until a long job is cancelled after 3 s)"));
      server.stop();
    }
    char ratio[64];
    std::snprintf(ratio, sizeof ratio, "%.0fx", p50[0] / std::max(1e-9, p50[1]));
    std::printf("| %-52s | %-4s | %9s | %9s | %9s | %s\n", "  no lane / lane (median)", "", ratio, "", "",
                "same run");
  }

  // --- 2. event latency with many subscribers ---------------------------------------------------------------
  {
    Contactd server;
    if (!server.start({"--workers", "1", "--max-streams", std::to_string(subscribers + 8)})) {
      std::printf("could not start contactd\n");
      server.stop();
      return 0;
    }
    httplib::Client client("127.0.0.1", server.port);
    // A blocker holds the only worker while the subscribers connect, so every event of the measured job is live.
    nlohmann::json blocker = job_from("seed_layers.json");
    blocker["solver"]["criterion"] = "residual";
    blocker["solver"]["tolerance"] = 1e-300;
    blocker["solver"]["max_iterations"] = 100000;  // the documented maximum (docs/job-format.md, "Limits"); cancelled below
    blocker["solver"]["gamma"] = 0.002;
    for (auto& b : blocker["bodies"]) b["mesh"]["block"]["ny"] = 256;
    const std::string blocker_id = submit(client, blocker);
    nlohmann::json measured = blocker;
    measured["solver"]["max_iterations"] = 2000;
    const std::string id = submit(client, measured);
    std::mutex mutex;
    std::vector<double> latency_ms;
    std::atomic<int> connected{0};
    std::vector<std::thread> pool;
    for (int s = 0; s < subscribers; ++s)
      pool.emplace_back([&] {
        std::vector<double> mine;
        bool counted = false;
        stream(server.port, id, [&](const std::string& line, double arrival) {
          if (!counted) {
            counted = true;
            ++connected;
          }
          if (line.find("\"type\":\"iteration\"") == std::string::npos) return;
          const auto at = line.find("\"time\":\"");
          if (at == std::string::npos) return;
          mine.push_back((arrival - parse_iso(line.substr(at + 8, 27))) * 1e3);
        });
        std::lock_guard<std::mutex> lock(mutex);
        latency_ms.insert(latency_ms.end(), mine.begin(), mine.end());
      });
    for (int i = 0; i < 400 && connected < subscribers; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
    const auto t0 = Clock::now();
    client.Post(("/v1/jobs/" + blocker_id + "/cancel").c_str(), "", "application/json");
    for (auto& t : pool) t.join();
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    const std::string note = std::to_string(subscribers) + " subscribers x " +
                             std::to_string(latency_ms.size() / std::max(1, subscribers)) + " iteration events in " +
                             std::to_string(wall).substr(0, 4) + " s";
    char p99[48];
    std::snprintf(p99, sizeof p99, "; p99 %.3f ms", percentile(latency_ms, 0.99));
    const std::string what = "event latency, " + std::to_string(subscribers) + " concurrent subscribers";
    print_row(what.c_str(), "ms", percentile(latency_ms, 0.5), percentile(latency_ms, 0.9), percentile(latency_ms, 1.0),
              note + p99);
    server.stop();
  }
  return 0;
}

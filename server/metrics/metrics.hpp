// Counters for /metrics, rendered in the Prometheus text format 0.0.4. Counters are updated from any thread;
// the gauges of jobs by state and the queue length are sampled from the JobQueue when rendering.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace contactd {

struct JobCounts {
  std::array<std::int64_t, 5> by_state{};  // indexed by JobState
  std::int64_t queue_length = 0;           // QUEUED jobs waiting for a worker
};

class Metrics {
 public:
  void job_submitted() { ++jobs_submitted_; }
  void iteration_done() { ++iterations_; }
  void solve_finished(double seconds);
  void http_response(int status);
  void stream_opened() { ++stream_clients_; }
  void stream_closed() { --stream_clients_; }
  std::int64_t stream_clients() const { return stream_clients_.load(); }

  // What is sampled from the queue, the store and the transport when rendering.
  struct Gauges {
    JobCounts jobs;
    int workers = 0, workers_busy = 0, abandoned_work = 0;
    std::int64_t damaged_jobs = 0, stuck_jobs = 0;
    std::int64_t jobs_expired_total = 0, events_dropped_total = 0;
    bool disk_reserve_used = false;
    std::int64_t connections = 0;
  };
  std::string render(const Gauges& gauges) const;

 private:
  std::atomic<std::int64_t> jobs_submitted_{0};
  std::atomic<std::int64_t> iterations_{0};
  std::atomic<std::int64_t> stream_clients_{0};
  mutable std::mutex mutex_;
  double solve_seconds_ = 0.0;
  std::map<int, std::int64_t> responses_;  // by HTTP status code
};

}  // namespace contactd

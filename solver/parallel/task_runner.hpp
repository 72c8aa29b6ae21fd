// "Run these N independent tasks": the one interface through which the DDM runs its per-body work, threads of
// one process (ThreadTaskRunner, here) or MPI ranks that each own some bodies (solver/mpi/mpi_runner.hpp).
#pragma once

#include "body_share.hpp"

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace contact::parallel {

class TaskRunner {
 public:
  virtual ~TaskRunner() = default;
  // Calls task(i) for i = 0..n-1, possibly concurrently, and returns when all have finished. The first
  // exception thrown by a task is rethrown here after every task has finished.
  virtual void run(size_t n, const std::function<void(size_t)>& task) = 0;

  // Per-body work: task(a) for every body a in `bodies`, on the process that owns a. On return every process
  // holds every task's outputs: a distributed runner moves them with `share` (one process: nothing moves). A
  // task that throws on any process makes run_bodies throw the same message on every process.
  virtual void run_bodies(const std::vector<size_t>& bodies, const std::function<void(size_t)>& task,
                          const BodyShare& share);
  void run_bodies(size_t n_bodies, const std::function<void(size_t)>& task, const BodyShare& share);

  // How many tasks of one run() this process runs at once (its threads).
  virtual unsigned concurrency() const { return 1; }

  // Whether this process owns body a (holds its matrices, runs its tasks).
  virtual bool owns(size_t /*body*/) const { return true; }
  // Whether other processes take part (bodies they own have no matrices here).
  virtual bool distributed() const { return false; }
  // The process that reports progress and writes results.
  virtual bool is_root() const { return true; }

  // Adds `values` over all processes, in place (one process: nothing to do). The iterative interface solver's
  // one collective per iteration: each process applies its own bodies' blocks, then the sums meet. A distributed
  // runner also carries the cancel requests with it and returns true when any process asked to stop (the same
  // answer on every process); without one, false.
  virtual bool sum(double* values, size_t count) {
    (void)values;
    (void)count;
    return false;
  }
};

// A fixed pool of worker threads (the calling thread works too). threads <= 1 runs everything inline.
class ThreadTaskRunner final : public TaskRunner {
 public:
  explicit ThreadTaskRunner(unsigned threads);
  ~ThreadTaskRunner() override;
  ThreadTaskRunner(const ThreadTaskRunner&) = delete;
  ThreadTaskRunner& operator=(const ThreadTaskRunner&) = delete;
  void run(size_t n, const std::function<void(size_t)>& task) override;
  unsigned threads() const { return static_cast<unsigned>(workers_.size()) + 1; }
  unsigned concurrency() const override { return threads(); }

 private:
  void work_loop();
  void drain();  // takes tasks of the current batch until none is left (labelled as the batch's caller)

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(size_t)>* task_ = nullptr;
  size_t next_ = 0, count_ = 0, finished_ = 0;
  std::string label_;  // the caller's work label (contact/work_label.hpp), which its tasks carry
  unsigned long generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

// Threads for n independent bodies: `requested` if > 0, else min(n, hardware threads).
unsigned choose_threads(int requested, size_t n_tasks);

}  // namespace contact::parallel

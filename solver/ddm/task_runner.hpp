// "Run these N independent tasks": the one interface through which the DDM runs its per-body work, so that
// threads serve today and other executors (MPI ranks) can serve later without touching the DDM code.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace contact::ddm {

class TaskRunner {
 public:
  virtual ~TaskRunner() = default;
  // Calls task(i) for i = 0..n-1, possibly concurrently, and returns when all have finished. The first
  // exception thrown by a task is rethrown here after every task has finished.
  virtual void run(size_t n, const std::function<void(size_t)>& task) = 0;
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

 private:
  void work_loop();
  void drain();  // takes tasks of the current batch until none is left

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(size_t)>* task_ = nullptr;
  size_t next_ = 0, count_ = 0, finished_ = 0;
  unsigned long generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

// Threads for n independent bodies: `requested` if > 0, else min(n, hardware threads).
unsigned choose_threads(int requested, size_t n_tasks);

}  // namespace contact::ddm

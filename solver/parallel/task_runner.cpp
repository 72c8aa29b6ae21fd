#include "task_runner.hpp"

#include "contact/work_label.hpp"

#include <algorithm>

namespace contact::parallel {

ThreadTaskRunner::ThreadTaskRunner(unsigned threads) {
  for (unsigned i = 1; i < threads; ++i) workers_.emplace_back([this] { work_loop(); });
}

ThreadTaskRunner::~ThreadTaskRunner() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadTaskRunner::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  // A worker does the batch's work under its caller's label, so that a crash in a body's task names the job.
  const contact::WorkLabelScope label(label_);
  while (task_ && next_ < count_) {
    const size_t i = next_++;
    const auto* task = task_;
    lock.unlock();
    try {
      (*task)(i);
    } catch (...) {
      std::lock_guard<std::mutex> g(mutex_);
      if (!error_) error_ = std::current_exception();
    }
    lock.lock();
    if (++finished_ == count_) done_.notify_all();
  }
}

void ThreadTaskRunner::work_loop() {
  unsigned long seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    drain();
  }
}

void TaskRunner::run_bodies(const std::vector<size_t>& bodies, const std::function<void(size_t)>& task,
                            const BodyShare& /*share*/) {
  run(bodies.size(), [&](size_t i) { task(bodies[i]); });
}

void TaskRunner::run_bodies(size_t n_bodies, const std::function<void(size_t)>& task, const BodyShare& share) {
  std::vector<size_t> all(n_bodies);
  for (size_t a = 0; a < n_bodies; ++a) all[a] = a;
  run_bodies(all, task, share);
}

void ThreadTaskRunner::run(size_t n, const std::function<void(size_t)>& task) {
  if (n == 0) return;
  if (workers_.empty() || n == 1) {
    for (size_t i = 0; i < n; ++i) task(i);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    task_ = &task;
    label_ = contact::work_label();
    next_ = 0;
    count_ = n;
    finished_ = 0;
    error_ = nullptr;
    ++generation_;
  }
  wake_.notify_all();
  drain();
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return finished_ == count_; });
    task_ = nullptr;
    error = error_;
  }
  if (error) std::rethrow_exception(error);
}

unsigned choose_threads(int requested, size_t n_tasks) {
  if (requested > 0) return static_cast<unsigned>(requested);
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::max<size_t>(1, std::min<size_t>(n_tasks, hw)));
}

}  // namespace contact::parallel

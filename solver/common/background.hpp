// Work that a cancel may leave behind: a step that cannot be interrupted from outside (CHOLMOD's factorisation
// has no interrupt hook) runs on a thread of its own while the caller waits and watches the cancel request; on a
// cancel the caller returns at once (within one poll interval) and the thread finishes alone, then frees what it
// made. So a cancel takes effect within a second even inside a factorisation of seconds, at the price of the
// abandoned work's CPU time and memory until it ends.
//
// The work must own everything it touches (capture copies or shared pointers, never references to the caller's
// state: the caller may be gone when it ends). Programs that may exit while such work runs call
// wait_for_background_work() first (contact/background_work.hpp says what a program should do).
#pragma once

#include "contact/work_label.hpp"

#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

namespace contact {

namespace detail {
void background_started();
void background_finished(bool abandoned = false);
void background_abandoned();  // the caller left; background_finished(true) follows
}  // namespace detail

// Runs work() and returns its result; with a `cancelled` test, runs it on its own thread and returns nullptr as
// soon as cancelled() says so (checked every `poll`), leaving the thread to finish and discard its result.
// Exceptions of the work reach the caller (unless it was abandoned).
template <class T>
std::unique_ptr<T> run_unless_cancelled(std::function<std::unique_ptr<T>()> work,
                                        const std::function<bool()>& cancelled,
                                        std::chrono::milliseconds poll = std::chrono::milliseconds(20)) {
  if (!cancelled) return work();
  if (cancelled()) return nullptr;
  struct State {
    std::mutex mutex;
    std::condition_variable done_cv;
    bool done = false, abandoned = false;
    std::unique_ptr<T> result;
    std::exception_ptr error;
  };
  auto state = std::make_shared<State>();
  detail::background_started();
  try {
    std::thread([state, work = std::move(work), label = std::string(work_label())]() mutable {
      const WorkLabelScope labelled(label);  // a crash in the work names the caller's job
      std::unique_ptr<T> result;
      std::exception_ptr error;
      try {
        result = work();
      } catch (...) {
        error = std::current_exception();
      }
      work = nullptr;  // the inputs it owned
      std::unique_lock<std::mutex> lock(state->mutex);
      if (!state->abandoned) {  // the caller takes the result: the work counts as finished now
        state->result = std::move(result);
        state->error = error;
        detail::background_finished();
        state->done = true;
        lock.unlock();
        state->done_cv.notify_all();
        return;
      }
      lock.unlock();
      result.reset();  // an abandoned result is freed before the work counts as finished
      detail::background_finished(/*abandoned=*/true);
    }).detach();
  } catch (...) {  // no thread could be started
    detail::background_finished();
    throw;
  }
  std::unique_lock<std::mutex> lock(state->mutex);
  while (!state->done_cv.wait_for(lock, poll, [&] { return state->done; }))
    if (cancelled()) {
      state->abandoned = true;
      detail::background_abandoned();
      return nullptr;
    }
  if (state->error) std::rethrow_exception(state->error);
  return std::move(state->result);
}

}  // namespace contact

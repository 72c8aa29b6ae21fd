#include "background.hpp"

#include "contact/background_work.hpp"

namespace contact {

namespace {

struct Registry {
  std::mutex mutex;
  std::condition_variable idle;
  int running = 0;
  int abandoned = 0;  // of `running`, those whose caller left (a cancel)
};

Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: a detached thread may finish during the exit
  return *r;
}

}  // namespace

namespace detail {

void background_started() {
  std::lock_guard<std::mutex> lock(registry().mutex);
  ++registry().running;
}

void background_finished(bool abandoned) {
  Registry& r = registry();
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    --r.running;
    if (abandoned) --r.abandoned;
  }
  r.idle.notify_all();
}

void background_abandoned() {
  std::lock_guard<std::mutex> lock(registry().mutex);
  ++registry().abandoned;
}

}  // namespace detail

bool background_work_running() {
  std::lock_guard<std::mutex> lock(registry().mutex);
  return registry().running > 0;
}

int abandoned_background_work() {
  std::lock_guard<std::mutex> lock(registry().mutex);
  return registry().abandoned;
}

bool wait_for_background_work(double seconds) {
  Registry& r = registry();
  std::unique_lock<std::mutex> lock(r.mutex);
  return r.idle.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return r.running == 0; });
}

}  // namespace contact

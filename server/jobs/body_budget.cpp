#include "jobs/body_budget.hpp"

#include <malloc.h>

#include <algorithm>
#include <thread>

namespace contactd {

namespace {

// Large bodies leave one validation slot to small ones (one slot configured: a second is added for them).
std::size_t large_validation_slots(std::size_t slots) { return std::max<std::size_t>(1, slots - 1); }

}  // namespace

BodyBudget::BodyBudget(std::size_t large_slots, std::size_t validation_slots, std::size_t large_bytes,
                       std::chrono::milliseconds wait)
    : large_slots_(large_slots),
      validation_slots_(std::max(validation_slots, large_validation_slots(validation_slots) + 1)),
      large_validation_slots_(large_validation_slots(validation_slots)),
      large_bytes_(large_bytes),
      wait_(wait) {}

std::size_t BodyBudget::validation_slots(std::size_t configured) {
  if (configured > 0) return configured;
  return std::max<std::size_t>(2, std::thread::hardware_concurrency());
}

BodyBudget::Slot& BodyBudget::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    release();
    budget_ = other.budget_;
    kind_ = other.kind_;
    other.budget_ = nullptr;
  }
  return *this;
}

void BodyBudget::Slot::release() {
  if (budget_) budget_->release(kind_);
  budget_ = nullptr;
}

bool BodyBudget::free_locked(Kind kind) const {
  switch (kind) {
    case Kind::body:
      return large_in_use_ < large_slots_;
    case Kind::validation:
      return validation_in_use_ < validation_slots_;
    case Kind::large_validation:
      return validation_in_use_ < validation_slots_ && large_validation_in_use_ < large_validation_slots_;
  }
  return false;
}

void BodyBudget::take_locked(Kind kind) {
  if (kind == Kind::body) {
    ++large_in_use_;
    return;
  }
  ++validation_in_use_;
  if (kind == Kind::large_validation) ++large_validation_in_use_;
}

BodyBudget::Slot BodyBudget::for_body(bool chunked, std::uint64_t announced, bool& granted) {
  granted = true;
  if (!chunked && announced <= large_bytes_) return Slot();
  std::unique_lock<std::mutex> lock(mutex_);
  granted = freed_.wait_for(lock, wait_, [&] { return free_locked(Kind::body); });
  if (!granted) return Slot();
  take_locked(Kind::body);
  return Slot(this, Kind::body);
}

BodyBudget::Slot BodyBudget::for_validation(std::size_t bytes) {
  const Kind kind = bytes > large_bytes_ ? Kind::large_validation : Kind::validation;
  std::unique_lock<std::mutex> lock(mutex_);
  if (!freed_.wait_for(lock, wait_, [&] { return free_locked(kind); })) return Slot();
  take_locked(kind);
  return Slot(this, kind);
}

BodyBudget::Slot BodyBudget::for_validation_until(std::size_t bytes, const std::function<bool()>& give_up) {
  const Kind kind = bytes > large_bytes_ ? Kind::large_validation : Kind::validation;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!free_locked(kind)) {
    if (give_up()) return Slot();
    freed_.wait_for(lock, std::chrono::milliseconds(100));
  }
  take_locked(kind);
  return Slot(this, kind);
}

void BodyBudget::release(Kind kind) {
  bool idle = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (kind == Kind::body) {
      --large_in_use_;
    } else {
      --validation_in_use_;
      if (kind == Kind::large_validation) --large_validation_in_use_;
    }
    idle = large_in_use_ == 0 && validation_in_use_ == 0;
  }
  freed_.notify_all();
  // What the bodies, parsed documents and meshes used is free now: give it back to the system rather than keep
  // it in the allocator's arenas (one per thread that allocated, up to 8 per core).
  if (idle) ::malloc_trim(0);
}

void BodyBudget::configure_allocator() {
  // Blocks of 256 KiB and more (bodies, JSON strings, meshes) get their own mapping, returned when freed. glibc
  // would otherwise raise this threshold after the first large free and keep such blocks in its heaps.
  ::mallopt(M_MMAP_THRESHOLD, 256 * 1024);
}

}  // namespace contactd

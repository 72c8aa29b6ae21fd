#include "body_budget.hpp"

#include <malloc.h>

namespace contactd {

BodyBudget::BodyBudget(std::size_t large_slots, std::size_t validation_slots, std::size_t large_bytes,
                       std::chrono::milliseconds wait)
    : large_slots_(large_slots), validation_slots_(validation_slots), large_bytes_(large_bytes), wait_(wait) {}

BodyBudget::Slot& BodyBudget::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    release();
    budget_ = other.budget_;
    large_ = other.large_;
    other.budget_ = nullptr;
  }
  return *this;
}

void BodyBudget::Slot::release() {
  if (budget_) budget_->release(large_);
  budget_ = nullptr;
}

bool BodyBudget::acquire(std::size_t& in_use, std::size_t slots) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!freed_.wait_for(lock, wait_, [&] { return in_use < slots; })) return false;
  ++in_use;
  return true;
}

BodyBudget::Slot BodyBudget::for_body(bool chunked, std::uint64_t announced, bool& granted) {
  granted = true;
  if (!chunked && announced <= large_bytes_) return Slot();
  granted = acquire(large_in_use_, large_slots_);
  return granted ? Slot(this, true) : Slot();
}

BodyBudget::Slot BodyBudget::for_validation() {
  return acquire(validation_in_use_, validation_slots_) ? Slot(this, false) : Slot();
}

void BodyBudget::release(bool large) {
  bool idle = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    --(large ? large_in_use_ : validation_in_use_);
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

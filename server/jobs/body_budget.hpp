// Bounds on what job bodies cost while they are read and validated, so that many concurrent large requests cannot
// take the server's memory (64 bodies of 7 MB took it from 27 MB to 3.7 GB, never returned) or every CPU:
//   - a body over `large_bytes` (or chunked, length unknown) is read only with one of `large_slots`;
//   - parsing and validating a job (any size: a small job can describe a large mesh) needs one of
//     `validation_slots`. Validation costs time in proportion to the body (a Gmsh mesh of 8 MB takes about a
//     second): bodies over `large_bytes` take at most validation_slots - 1 of them (at least 1), so that a
//     small job always finds a slot of its own while large ones validate (with one slot configured, a second
//     one is kept for small bodies). The workers parse a job again before they run it, under the same slots;
// a request waits at most `wait` for a slot, then gets 503 (problem type busy) with Retry-After. When the last
// large body or validation is done, the memory freed is returned to the system (malloc_trim). configure_allocator()
// makes glibc return large blocks at once (a fixed mmap threshold) instead of keeping them in its arenas.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <cstddef>
#include <cstdint>
#include <mutex>

namespace contactd {

class BodyBudget {
 public:
  BodyBudget(std::size_t large_slots, std::size_t validation_slots, std::size_t large_bytes,
             std::chrono::milliseconds wait);

  enum class Kind { body, validation, large_validation };

  // Held while a slot is in use; releasing the last one in use trims the heap.
  class Slot {
   public:
    Slot() = default;
    Slot(BodyBudget* budget, Kind kind) : budget_(budget), kind_(kind) {}
    Slot(Slot&& other) noexcept : budget_(other.budget_), kind_(other.kind_) { other.budget_ = nullptr; }
    Slot& operator=(Slot&& other) noexcept;
    ~Slot() { release(); }
    explicit operator bool() const { return budget_ != nullptr; }
    void release();

   private:
    BodyBudget* budget_ = nullptr;
    Kind kind_ = Kind::body;
  };

  // A slot for reading a body of `announced` bytes (nullopt: chunked). An empty Slot that is "granted" is
  // returned for a small body (no slot needed); `granted` false means wait expired: answer 503.
  Slot for_body(bool chunked, std::uint64_t announced, bool& granted);
  // A slot for parsing and validating a body of `bytes`; empty (falsy) when the wait expired.
  Slot for_validation(std::size_t bytes);
  // The same for a worker: waits until a slot is free or give_up() (polled every 100 ms) says true (empty).
  Slot for_validation_until(std::size_t bytes, const std::function<bool()>& give_up);

  // --max-validations: 0 means one per core, at least 2.
  static std::size_t validation_slots(std::size_t configured);

  std::size_t large_bytes() const { return large_bytes_; }

  // mallopt: large blocks are mmap'ed and unmapped when freed (not kept in the arenas). Call once at start-up.
  static void configure_allocator();

 private:
  bool free_locked(Kind kind) const;
  void take_locked(Kind kind);
  void release(Kind kind);

  const std::size_t large_slots_, validation_slots_, large_validation_slots_, large_bytes_;
  const std::chrono::milliseconds wait_;
  std::mutex mutex_;
  std::condition_variable freed_;
  std::size_t large_in_use_ = 0, validation_in_use_ = 0, large_validation_in_use_ = 0;
};

}  // namespace contactd

// The per-body work of the DDM on MPI ranks (OpenMPI): each rank owns some bodies (parallel/ownership.hpp), assembles
// and factorises only those, and runs their tasks with its own threads; after every batch of per-body tasks the
// outputs (BodyShare) go to every rank with one MPI_Allgatherv. Everything else - the contact discretisation,
// the small interface problem, the active set, the stopping tests - runs on every rank on the same data, so all
// ranks take the same decisions and meet at the same collectives (docs/parallel.md).
//
// Failures: a task that throws on one rank is reported in that exchange, and every rank throws the message of
// the lowest-numbered failing body. Cancellation: a rank's request (a signal) travels with the next exchange and
// sets the agreed token on every rank at the same point.
#pragma once

#include "parallel/task_runner.hpp"
#include "contact/result.hpp"

#include <mpi.h>

#include <atomic>
#include <cstdint>
#include <vector>

namespace contact::mpi {

class MpiTaskRunner final : public parallel::TaskRunner {
 public:
  // owner[a]: the rank of body a (the same vector on every rank). threads: this rank's threads for its bodies.
  MpiTaskRunner(MPI_Comm comm, std::vector<int> owner, unsigned threads);

  void run(size_t n, const std::function<void(size_t)>& task) override { local_.run(n, task); }
  void run_bodies(const std::vector<size_t>& bodies, const std::function<void(size_t)>& task,
                  const parallel::BodyShare& share) override;
  using parallel::TaskRunner::run_bodies;
  unsigned concurrency() const override { return local_.concurrency(); }
  bool owns(size_t body) const override { return owner_.at(body) == rank_; }
  bool distributed() const override { return size_ > 1; }
  bool is_root() const override { return rank_ == 0; }
  bool sum(double* values, size_t count) override;

  // request: this rank's wish to stop (set by a signal handler); agreed: the token solve() reads.
  void watch_cancel(const std::atomic<bool>* request, CancelToken* agreed) {
    request_ = request;
    agreed_ = agreed;
  }

  int rank() const { return rank_; }
  int size() const { return size_; }
  const std::vector<int>& owner() const { return owner_; }
  // What this rank sent and received so far: exchanges, bytes of task outputs sent (its own bodies) and received.
  std::int64_t exchanges() const { return exchanges_; }
  std::int64_t bytes_sent() const { return bytes_sent_; }
  std::int64_t bytes_received() const { return bytes_received_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::vector<int> owner_;
  parallel::ThreadTaskRunner local_;
  const std::atomic<bool>* request_ = nullptr;
  CancelToken* agreed_ = nullptr;
  std::int64_t exchanges_ = 0, bytes_sent_ = 0, bytes_received_ = 0;
  long fail_body_ = -1;
};

}  // namespace contact::mpi

// The processes of one contact-solve run: a single process (threads), or the ranks of `mpirun -n N` when the
// program is built with MPI and started by mpirun (docs/parallel.md). Every rank parses the same job and runs the
// same solve; rank 0 reads the job file, prints and writes the result, and all ranks exit with rank 0's code.
#pragma once

#include "ddm/task_runner.hpp"
#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <atomic>
#include <memory>
#include <string>

namespace contact::cli {

class Session {
 public:
  Session(int* argc, char*** argv);  // MPI_Init when started by mpirun (an OpenMPI/PMIx environment)
  ~Session();                        // MPI_Finalize
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }

  // Rank 0's value on every rank.
  std::string broadcast(const std::string& text) const;
  int broadcast(int value) const;

  // The executor of the per-body work: threads, or this rank's share of the bodies (balanced by dofs). A cancel
  // request (a signal on any rank) reaches `agreed` on every rank at the same point of the solve.
  std::unique_ptr<ddm::TaskRunner> runner(const Problem& problem, const std::atomic<bool>* request,
                                          CancelToken* agreed) const;
  // "bodies per rank: 0: a, b; 1: c" (empty for one process).
  std::string placement(const Problem& problem) const;
  // After the solve, on every rank (a collective): "N exchanges, X bytes moved between the ranks" (empty for one).
  std::string traffic(const ddm::TaskRunner& runner) const;

 private:
  int rank_ = 0, size_ = 1;
  bool mpi_ = false;
};

}  // namespace contact::cli

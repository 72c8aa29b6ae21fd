// The processes of one run of a program (the command line): a single process (threads), or the ranks of
// `mpirun -n N` when the library is built with MPI and the program started by mpirun (docs/parallel.md). Every
// rank parses the same job and runs the same solve; rank 0 reads the job file, prints and writes the result, and
// all ranks exit with rank 0's code. How the bodies are placed on the ranks and exchanged stays inside the library
// (the contact_session target).
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <atomic>
#include <memory>
#include <string>

namespace contact {

namespace parallel {
class TaskRunner;
}

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

  // solve() on this session's processes: threads, or this rank's share of the bodies (balanced by dofs). A cancel
  // request (a signal on any rank, `request`) reaches `agreed` on every rank at the same point of the solve.
  Result solve(const Problem& problem, Observer& observer, const std::atomic<bool>* request, CancelToken* agreed);
  // "rank 0: 2 bodies, 1000 dofs; rank 1: ..." (empty for one process).
  std::string placement(const Problem& problem) const;
  // After solve(), on every rank (a collective): "N exchanges, X bytes moved between the ranks" (empty for one).
  std::string traffic() const;

 private:
  int rank_ = 0, size_ = 1;
  bool mpi_ = false;
  std::unique_ptr<parallel::TaskRunner> runner_;  // the last solve's
};

}  // namespace contact

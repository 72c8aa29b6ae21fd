#include "contact/session.hpp"

#include "contact/solve.hpp"
#include "parallel/ownership.hpp"
#include "parallel/task_runner.hpp"

#include <cstdlib>
#include <sstream>

#ifdef CONTACT_WITH_MPI
#include "mpi/mpi_runner.hpp"
#endif

namespace contact {

namespace {

bool started_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

}  // namespace

Session::Session(int* argc, char*** argv) {
#ifdef CONTACT_WITH_MPI
  if (!started_by_mpirun()) return;
  int provided = 0;
  // Only the main thread calls MPI (the exchanges); the rank's worker threads never do.
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#else
  (void)argc;
  (void)argv;
#endif
}

Session::~Session() {
  runner_.reset();  // (an MPI runner before MPI_Finalize)
#ifdef CONTACT_WITH_MPI
  if (mpi_) MPI_Finalize();
#endif
}

std::string Session::broadcast(const std::string& text) const {
#ifdef CONTACT_WITH_MPI
  if (!mpi_) return text;
  long long n = static_cast<long long>(text.size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string out = root() ? text : std::string(static_cast<size_t>(n), '\0');
  // In pieces of at most 1 GiB (MPI counts are int).
  for (long long at = 0; at < n; at += (1LL << 30)) {
    const int piece = static_cast<int>(std::min<long long>(n - at, 1LL << 30));
    MPI_Bcast(out.data() + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD);
  }
  return out;
#else
  return text;
#endif
}

int Session::broadcast(int value) const {
#ifdef CONTACT_WITH_MPI
  if (mpi_) MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
#endif
  return value;
}

namespace {

std::unique_ptr<parallel::TaskRunner> make_runner(const Problem& problem, bool mpi, int rank, int size,
                                                  const std::atomic<bool>* request, CancelToken* agreed) {
#ifdef CONTACT_WITH_MPI
  if (mpi && size > 1) {
    const std::vector<int> owner = parallel::assign_bodies(problem, size);
    size_t mine = 0;
    for (int r : owner) mine += r == rank ? 1 : 0;
    auto runner = std::make_unique<mpi::MpiTaskRunner>(
        MPI_COMM_WORLD, owner, parallel::choose_threads(problem.solver.threads, std::max<size_t>(mine, 1)));
    runner->watch_cancel(request, agreed);
    return runner;
  }
#endif
  (void)mpi, (void)rank, (void)size, (void)request, (void)agreed;
  return std::make_unique<parallel::ThreadTaskRunner>(
      parallel::choose_threads(problem.solver.threads, problem.bodies.size()));
}

}  // namespace

Result Session::solve(const Problem& problem, Observer& observer, const std::atomic<bool>* request,
                      CancelToken* agreed) {
  runner_ = make_runner(problem, mpi_, rank_, size_, request, agreed);
  return contact::solve(problem, observer, *agreed, *runner_);
}

std::string Session::placement(const Problem& problem) const {
  if (size_ <= 1) return "";
  const std::vector<int> owner = parallel::assign_bodies(problem, size_);
  std::ostringstream os;
  for (int r = 0; r < size_; ++r) {
    os << (r ? "; " : "") << "rank " << r << ":";
    long dofs = 0;
    int count = 0;
    for (size_t a = 0; a < owner.size(); ++a)
      if (owner[a] == r) {
        dofs += 2L * problem.bodies[a].mesh.num_nodes();
        ++count;
      }
    os << " " << count << " bodies, " << dofs << " dofs";
  }
  return os.str();
}

std::string Session::traffic() const {
#ifdef CONTACT_WITH_MPI
  const auto* r = dynamic_cast<const mpi::MpiTaskRunner*>(runner_.get());
  if (!r) return "";
  // Every rank's message goes to the size - 1 others.
  long long sent = r->bytes_sent(), total = 0;
  MPI_Allreduce(&sent, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  std::ostringstream os;
  os << r->exchanges() << " exchanges, " << total * (size_ - 1) << " bytes moved between the ranks";
  return os.str();
#else
  return "";
#endif
}

}  // namespace contact

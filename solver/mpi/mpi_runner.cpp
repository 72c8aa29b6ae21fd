#include "mpi_runner.hpp"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <map>
#include <new>
#include <stdexcept>
#include <string>

namespace contact::mpi {

MpiTaskRunner::MpiTaskRunner(MPI_Comm comm, std::vector<int> owner, unsigned threads)
    : comm_(comm), owner_(std::move(owner)), local_(threads) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  // A test hook (docs/parallel.md, "Failures"): the first task of this body throws on its owner.
  if (const char* v = std::getenv("CONTACT_MPI_FAIL_BODY")) fail_body_ = std::strtol(v, nullptr, 10);
  for (int r : owner_)
    if (r < 0 || r >= size_)
      throw std::invalid_argument("MpiTaskRunner: a body's owner is not a rank of the communicator");
}

namespace {

// This rank's own bodies and, per body, whether its task failed and why.
struct OwnOutcome {
  std::vector<size_t> bodies;
  std::vector<std::string> failure;
  std::vector<char> failed;
};

// This rank's message: its cancel request, then per own body its outcome and packed outputs (a body whose outputs
// fail to pack counts as failed). Every failure is also recorded in `errors`, by body.
std::vector<char> pack_message(bool cancel_requested, OwnOutcome& own, const parallel::BodyShare& share,
                               std::map<size_t, std::string>& errors) {
  std::vector<char> out;
  parallel::Packer put(out);
  put.put(static_cast<std::int64_t>(cancel_requested ? 1 : 0));
  put.put(static_cast<std::int64_t>(own.bodies.size()));
  for (size_t i = 0; i < own.bodies.size(); ++i) {
    std::vector<char> payload;
    if (!own.failed[i] && share.pack) {
      parallel::Packer p(payload);
      try {
        share.pack(own.bodies[i], p);
      } catch (const std::exception& e) {
        own.failure[i] = e.what();
        own.failed[i] = 1;
      }
    }
    put.put(static_cast<std::int64_t>(own.bodies[i]));
    put.put(static_cast<std::int64_t>(own.failed[i]));
    if (own.failed[i]) {
      put.put(own.failure[i]);
      errors[own.bodies[i]] = own.failure[i];
      continue;
    }
    put.put(static_cast<std::int64_t>(payload.size()));
    out.insert(out.end(), payload.begin(), payload.end());
  }
  return out;
}

// Every rank's message, gathered on every rank: rank r's bytes are all[displs[r], displs[r] + sizes[r]).
struct Gathered {
  std::vector<char> all;
  std::vector<std::int64_t> sizes;
  std::vector<int> displs;
};

// Sizes first (every rank learns every size, so all agree when the total is too large for one call), then the
// messages in one MPI_Allgatherv.
Gathered all_gather(MPI_Comm comm, int ranks, const std::vector<char>& out) {
  Gathered g;
  std::int64_t size = static_cast<std::int64_t>(out.size());
  g.sizes.resize(static_cast<size_t>(ranks));
  MPI_Allgather(&size, 1, MPI_INT64_T, g.sizes.data(), 1, MPI_INT64_T, comm);
  std::int64_t total = 0;
  std::vector<int> counts(static_cast<size_t>(ranks));
  g.displs.resize(static_cast<size_t>(ranks));
  for (int r = 0; r < ranks; ++r) {
    g.displs[static_cast<size_t>(r)] = static_cast<int>(std::min<std::int64_t>(total, INT_MAX));
    counts[static_cast<size_t>(r)] = static_cast<int>(std::min<std::int64_t>(g.sizes[static_cast<size_t>(r)], INT_MAX));
    total += g.sizes[static_cast<size_t>(r)];
  }
  if (total > INT_MAX)
    throw std::runtime_error("one exchange between the MPI ranks would move " + std::to_string(total) +
                             " bytes, more than MPI_Allgatherv takes (2 GiB): use more, smaller bodies");
  g.all.resize(static_cast<size_t>(total));
  MPI_Allgatherv(out.data(), static_cast<int>(out.size()), MPI_CHAR, g.all.data(), counts.data(), g.displs.data(),
                 MPI_CHAR, comm);
  return g;
}

// Reads every rank's message: the other ranks' failures into `errors`, their bodies' outputs through
// share.unpack (a body that fails to unpack is an error too). Returns whether some rank asked to cancel.
bool unpack_messages(const Gathered& g, int rank, const parallel::BodyShare& share,
                     std::map<size_t, std::string>& errors) {
  bool cancel = false;
  for (size_t r = 0; r < g.sizes.size(); ++r) {
    parallel::Unpacker in(g.all.data() + g.displs[r], static_cast<size_t>(g.sizes[r]));
    // Read whatever the flags before said: every message starts with its flag, and a flag left unread would be
    // taken for the message's entry count (its bodies' outputs lost, or read from the wrong bytes).
    const bool asked = in.get_int() != 0;
    cancel = cancel || asked;
    const std::int64_t entries = in.get_int();
    for (std::int64_t e = 0; e < entries; ++e) {
      const auto body = static_cast<size_t>(in.get_int());
      const bool body_failed = in.get_int() != 0;
      if (body_failed) {
        std::string message = in.get_string();
        if (static_cast<int>(r) != rank) errors[body] = std::move(message);
        continue;
      }
      parallel::Unpacker payload = in.take(static_cast<size_t>(in.get_int()));
      if (static_cast<int>(r) == rank || !share.unpack || errors.count(body)) continue;
      try {
        share.unpack(body, payload);
        if (!payload.done()) throw std::runtime_error("body data from another process has unread bytes");
      } catch (const std::exception& ex) {
        errors[body] = std::string("rank ") + std::to_string(rank) + ": cannot take the outputs of body " +
                       std::to_string(body) + " from rank " + std::to_string(r) + ": " + ex.what();
      }
    }
  }
  return cancel;
}

}  // namespace

void MpiTaskRunner::run_bodies(const std::vector<size_t>& bodies, const std::function<void(size_t)>& task,
                               const parallel::BodyShare& share) {
  // This rank's tasks, each failure kept with its body (a failing rank must still meet the others below).
  OwnOutcome own;
  for (size_t a : bodies)
    if (owns(a)) own.bodies.push_back(a);
  own.failure.resize(own.bodies.size());
  own.failed.assign(own.bodies.size(), 0);
  local_.run(own.bodies.size(), [&](size_t i) {
    try {
      if (static_cast<long>(own.bodies[i]) == fail_body_)
        throw std::runtime_error("rank " + std::to_string(rank_) + ": body " + std::to_string(own.bodies[i]) +
                                 ": failure injected by CONTACT_MPI_FAIL_BODY");
      task(own.bodies[i]);
    } catch (const std::bad_alloc&) {
      own.failure[i] = "out of memory";
      own.failed[i] = 1;
    } catch (const std::exception& e) {
      own.failure[i] = e.what();
      own.failed[i] = 1;
    }
  });
  std::map<size_t, std::string> errors;  // by body: every rank picks the same (lowest) one
  const std::vector<char> out = pack_message(request_ && request_->load(), own, share, errors);
  const Gathered gathered = all_gather(comm_, size_, out);
  ++exchanges_;
  const auto size = static_cast<std::int64_t>(out.size());
  bytes_sent_ += size;
  bytes_received_ += static_cast<std::int64_t>(gathered.all.size()) - size;
  const bool cancel = unpack_messages(gathered, rank_, share, errors);
  if (cancel && agreed_) agreed_->cancel();
  if (!errors.empty()) throw std::runtime_error(errors.begin()->second);
}

bool MpiTaskRunner::sum(double* values, size_t count) {
  // One MPI_Allreduce with this rank's cancel request as an extra entry: every rank sees the same total, so all
  // take the same decision and stop at the same iteration.
  std::vector<double> buffer(values, values + count);
  buffer.push_back(request_ && request_->load() ? 1.0 : 0.0);
  if (buffer.size() > static_cast<size_t>(INT_MAX)) throw std::runtime_error("MpiTaskRunner::sum: too many values");
  MPI_Allreduce(MPI_IN_PLACE, buffer.data(), static_cast<int>(buffer.size()), MPI_DOUBLE, MPI_SUM, comm_);
  std::copy(buffer.begin(), buffer.end() - 1, values);
  const bool stop = buffer.back() > 0;
  if (stop && agreed_) agreed_->cancel();
  return stop;
}

}  // namespace contact::mpi

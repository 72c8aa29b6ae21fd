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
    if (r < 0 || r >= size_) throw std::invalid_argument("MpiTaskRunner: a body's owner is not a rank of the communicator");
}

void MpiTaskRunner::run_bodies(const std::vector<size_t>& bodies, const std::function<void(size_t)>& task,
                               const ddm::BodyShare& share) {
  std::vector<size_t> mine;
  for (size_t a : bodies)
    if (owns(a)) mine.push_back(a);
  // This rank's tasks, each failure kept with its body (a failing rank must still meet the others below).
  std::vector<std::string> failure(mine.size());
  std::vector<char> failed(mine.size(), 0);
  local_.run(mine.size(), [&](size_t i) {
    try {
      if (static_cast<long>(mine[i]) == fail_body_)
        throw std::runtime_error("rank " + std::to_string(rank_) + ": body " + std::to_string(mine[i]) +
                                 ": failure injected by CONTACT_MPI_FAIL_BODY");
      task(mine[i]);
    } catch (const std::bad_alloc&) {
      failure[i] = "out of memory";
      failed[i] = 1;
    } catch (const std::exception& e) {
      failure[i] = e.what();
      failed[i] = 1;
    }
  });

  // This rank's message: its cancel request, then per own body its outcome and packed outputs.
  std::vector<char> out;
  ddm::Packer put(out);
  put.put(static_cast<std::int64_t>(request_ && request_->load() ? 1 : 0));
  put.put(static_cast<std::int64_t>(mine.size()));
  std::map<size_t, std::string> errors;  // by body: every rank picks the same (lowest) one
  for (size_t i = 0; i < mine.size(); ++i) {
    std::vector<char> payload;
    if (!failed[i] && share.pack) {
      ddm::Packer p(payload);
      try {
        share.pack(mine[i], p);
      } catch (const std::exception& e) {
        failure[i] = e.what();
        failed[i] = 1;
      }
    }
    put.put(static_cast<std::int64_t>(mine[i]));
    put.put(static_cast<std::int64_t>(failed[i]));
    if (failed[i]) {
      put.put(failure[i]);
      errors[mine[i]] = failure[i];
      continue;
    }
    put.put(static_cast<std::int64_t>(payload.size()));
    out.insert(out.end(), payload.begin(), payload.end());
  }

  // Sizes first (every rank learns every size, so all agree when the total is too large for one call).
  std::int64_t size = static_cast<std::int64_t>(out.size());
  std::vector<std::int64_t> sizes(static_cast<size_t>(size_));
  MPI_Allgather(&size, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, comm_);
  std::int64_t total = 0;
  std::vector<int> counts(static_cast<size_t>(size_)), displs(static_cast<size_t>(size_));
  for (int r = 0; r < size_; ++r) {
    displs[static_cast<size_t>(r)] = static_cast<int>(std::min<std::int64_t>(total, INT_MAX));
    counts[static_cast<size_t>(r)] = static_cast<int>(std::min<std::int64_t>(sizes[static_cast<size_t>(r)], INT_MAX));
    total += sizes[static_cast<size_t>(r)];
  }
  if (total > INT_MAX)
    throw std::runtime_error("one exchange between the MPI ranks would move " + std::to_string(total) +
                             " bytes, more than MPI_Allgatherv takes (2 GiB): use more, smaller bodies");
  std::vector<char> all(static_cast<size_t>(total));
  MPI_Allgatherv(out.data(), static_cast<int>(out.size()), MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR,
                 comm_);
  ++exchanges_;
  bytes_sent_ += size;
  bytes_received_ += total - size;

  bool cancel = false;
  for (int r = 0; r < size_; ++r) {
    ddm::Unpacker in(all.data() + displs[static_cast<size_t>(r)], static_cast<size_t>(sizes[static_cast<size_t>(r)]));
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
        if (r != rank_) errors[body] = std::move(message);
        continue;
      }
      ddm::Unpacker payload = in.take(static_cast<size_t>(in.get_int()));
      if (r == rank_ || !share.unpack || errors.count(body)) continue;
      try {
        share.unpack(body, payload);
        if (!payload.done()) throw std::runtime_error("body data from another process has unread bytes");
      } catch (const std::exception& ex) {
        errors[body] = std::string("rank ") + std::to_string(rank_) + ": cannot take the outputs of body " +
                       std::to_string(body) + " from rank " + std::to_string(r) + ": " + ex.what();
      }
    }
  }
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

#include "store/job_store.hpp"

#include "common/job_id.hpp"
#include "common/log.hpp"

#include "contact/files.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace contactd {

namespace {
constexpr const char* kDeletedPrefix = ".deleted-";
constexpr std::size_t kReserveBytes = 1u << 20;
const char kHdf5Signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};

bool is_link(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
}

// Takes <data>/.lock with flock(): held until the process exits (the kernel drops it even after kill -9).
int lock_data_dir(const std::string& data_dir) {
  const std::string path = data_dir + "/.lock";
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open the lock file '" + path + "': " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int code = errno;
    char pid[32] = "";
    const ssize_t n = ::pread(fd, pid, sizeof pid - 1, 0);
    std::string holder = n > 0 ? std::string(pid, static_cast<std::size_t>(n)) : std::string();
    holder.erase(std::remove_if(holder.begin(), holder.end(), [](char c) { return c < '0' || c > '9'; }), holder.end());
    ::close(fd);
    if (code == EWOULDBLOCK)
      throw std::runtime_error("the data directory '" + data_dir + "' is in use by another contactd" +
                               (holder.empty() ? std::string() : " (pid " + holder + ")") +
                               "; give each server its own --data-dir");
    throw std::runtime_error("cannot lock '" + path + "': " + std::strerror(code));
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size()))
    log_line("store: cannot write the pid into " + path);
  return fd;
}

}  // namespace

JobStore::JobStore(const std::string& data_dir)
    : data_dir_(data_dir), jobs_dir_(data_dir + "/jobs"), reserve_path_(data_dir + "/.reserve") {
  std::error_code ec;
  fs::create_directories(jobs_dir_, ec);
  if (ec) throw std::runtime_error("cannot create the data directory '" + jobs_dir_ + "': " + ec.message());
  lock_fd_ = lock_data_dir(data_dir_);
  if (!restore_reserve()) {
    reserve_used_ = true;  // as good as used: readiness says the disk is (nearly) full
    log_line("store: cannot set the disk reserve aside in " + data_dir_ + " (less than 2 MiB free?)");
  }
}

JobStore::~JobStore() {
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::string JobStore::job_dir(const std::string& id) const {
  if (!is_job_id(id)) throw std::invalid_argument("not a job id");  // never a path from the outside world
  return jobs_dir_ + "/" + id;
}

void JobStore::create(const JobRecord& record, const std::string& body) {
  const std::string dir = job_dir(record.id);
  std::error_code ec;
  if (!fs::create_directory(dir, ec) || ec)
    throw std::runtime_error("cannot create '" + dir + "': " + (ec ? ec.message() : std::string("it exists")));
  try {
    // Every file fsync'ed, then their directory and its parent once: durable before the 202 goes out.
    std::vector<std::string> files = {job_path(record.id), state_path(record.id)};
    contact::write_file_atomically(job_path(record.id), body, false);
    if (!record.idempotency_key.empty()) {
      // Kept apart from state.json, so that the key is remembered even if state.json is damaged later.
      contact::write_file_atomically(key_path(record.id), record.idempotency_key, false);
      files.push_back(key_path(record.id));
    }
    contact::write_file_atomically(state_path(record.id), to_state_json(record).dump(2) + "\n", false);
    for (const std::string& file : files) contact::sync_file(file);
    contact::sync_directory(dir);
    contact::sync_directory(jobs_dir_);
  } catch (...) {
    fs::remove_all(dir, ec);
    throw;
  }
}

void JobStore::save_state(const JobRecord& record, bool durable) {
  const std::string text = to_state_json(record).dump(2) + "\n";
  try {
    contact::write_file_atomically(state_path(record.id), text, durable);
  } catch (const contact::FileError& e) {
    if ((e.code() != ENOSPC && e.code() != EDQUOT) || !release_reserve()) throw;
    log_line("store: the disk is full; the reserve was used to store the state of job " + record.id);
    contact::write_file_atomically(state_path(record.id), text, durable);
  }
}

bool JobStore::release_reserve() {
  if (::unlink(reserve_path_.c_str()) != 0) return false;
  reserve_used_ = true;
  return true;
}

bool JobStore::restore_reserve() {
  struct stat st {};
  if (::lstat(reserve_path_.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
      static_cast<std::size_t>(st.st_size) >= kReserveBytes) {
    reserve_used_ = false;
    return true;
  }
  // Only with room to spare: taking back the last free megabyte would leave the disk as full as before.
  struct statvfs fs {};
  if (::statvfs(data_dir_.c_str(), &fs) == 0 &&
      static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize < 2ull * kReserveBytes)
    return false;
  const std::string tmp = reserve_path_ + ".tmp";
  ::unlink(tmp.c_str());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return false;
  // Written, not only allocated: some file systems (tmpfs, overlays) would not hold the blocks otherwise.
  const std::string zeros(64 * 1024, '\0');
  bool ok = true;
  for (std::size_t done = 0; ok && done < kReserveBytes; done += zeros.size())
    ok = ::write(fd, zeros.data(), zeros.size()) == static_cast<ssize_t>(zeros.size());
  ok = ok && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok || ::rename(tmp.c_str(), reserve_path_.c_str()) != 0) {
    ::unlink(tmp.c_str());
    return false;
  }
  reserve_used_ = false;
  return true;
}

std::string JobStore::read_job(const std::string& id) const { return contact::read_whole_file(job_path(id)); }

void JobStore::remove_result(const std::string& id) {
  for (const std::string& path : {result_path(id), xmf_path(id), pairs_path(id)}) {
    ::unlink(path.c_str());  // a link is removed, never what it points to
    ::unlink((path + ".tmp").c_str());
  }
}

void JobStore::save_pairs(const std::string& id, const std::string& text) {
  contact::write_file_atomically(pairs_path(id), text, /*durable=*/false);
}

std::optional<std::string> JobStore::read_pairs(const std::string& id) const {
  const std::string path = pairs_path(id);
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  try {
    return contact::read_whole_file(path);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::optional<std::string> JobStore::check_result(const JobRecord& record) const {
  const std::string path = result_path(record.id);
  if (is_link(path)) return "result.hdf is a symbolic link";
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return "result.hdf cannot be opened: " + std::string(std::strerror(errno));
  struct stat st {};
  char head[8] = {};
  const bool stat_ok = ::fstat(fd, &st) == 0;
  const ssize_t n = ::pread(fd, head, sizeof head, 0);
  ::close(fd);
  if (!stat_ok || !S_ISREG(st.st_mode)) return "result.hdf is not a regular file";
  if (record.result_bytes > 0 && st.st_size != record.result_bytes)
    return "result.hdf has " + std::to_string(st.st_size) + " bytes, not the " + std::to_string(record.result_bytes) +
           " written";
  if (n != static_cast<ssize_t>(sizeof head) || std::memcmp(head, kHdf5Signature, sizeof head) != 0)
    return "result.hdf does not start with the HDF5 signature";
  if (is_link(xmf_path(record.id))) return "result.xmf is a symbolic link";
  return std::nullopt;
}

int JobStore::open_result(const std::string& id, bool sidecar) const {
  const std::string path = sidecar ? xmf_path(id) : result_path(id);
  return ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
}

std::int64_t JobStore::disk_usage(const std::string& id) const {
  std::int64_t total = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(job_dir(id), ec)) {
    struct stat st {};
    if (::lstat(entry.path().c_str(), &st) == 0) total += static_cast<std::int64_t>(st.st_size);
  }
  return total;
}

std::int64_t JobStore::free_bytes() const {
  struct statvfs fs {};
  if (::statvfs(data_dir_.c_str(), &fs) != 0) return -1;
  return static_cast<std::int64_t>(static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize);
}

JobStore::Contents JobStore::load_all() {
  Contents contents;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(jobs_dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kDeletedPrefix, 0) == 0) {  // a deletion interrupted by a crash: finish it
      fs::remove_all(entry.path(), ec);
      continue;
    }
    if (!is_job_id(name)) {
      log_line("store: ignoring '" + entry.path().string() + "' (not a job directory)");
      continue;
    }
    if (entry.is_symlink(ec) || !entry.is_directory(ec)) {
      contents.damaged.push_back({name, "the job directory is a symbolic link or not a directory", ""});
      continue;
    }
    // Temporary files are writes a crash interrupted; the file they were to replace is intact.
    for (const auto& file : fs::directory_iterator(entry.path(), ec)) {
      const std::string file_name = file.path().filename().string();
      if (file_name.size() > 4 && file_name.compare(file_name.size() - 4, 4, ".tmp") == 0) {
        log_line("store: removing the interrupted write '" + file.path().string() + "'");
        ::unlink(file.path().c_str());
      }
    }
    if (!is_link(state_path(name)) && !fs::exists(state_path(name), ec)) {
      // Crashed between creating the directory and writing state.json: the submission was never acknowledged.
      log_line("store: removing the unacknowledged submission " + name);
      fs::remove_all(entry.path(), ec);
      continue;
    }
    try {
      JobRecord record = from_state_json(nlohmann::json::parse(contact::read_whole_file(state_path(name))));
      if (record.id != name) throw std::runtime_error("its id is '" + record.id + "'");
      if (is_link(job_path(name)) || !fs::exists(job_path(name), ec)) throw std::runtime_error("job.json is missing");
      if (record.result_available && !is_link(result_path(name)) && !fs::exists(result_path(name), ec))
        record.result_available = false;
      contents.jobs.push_back(std::move(record));
    } catch (const std::exception& e) {
      Damaged damaged{name, std::string("state.json cannot be read: ") + e.what(), ""};
      try {
        damaged.idempotency_key = contact::read_whole_file(key_path(name));
      } catch (const std::exception&) {
      }
      log_line("store: job " + name + " is damaged (" + damaged.problem + "); its files are left as they are");
      contents.damaged.push_back(std::move(damaged));
    }
  }
  std::sort(contents.jobs.begin(), contents.jobs.end(), [](const JobRecord& a, const JobRecord& b) {
    return a.created_us != b.created_us ? a.created_us < b.created_us : a.id < b.id;
  });
  return contents;
}

void JobStore::remove(const std::string& id) {
  const std::string dir = job_dir(id);
  const std::string doomed = jobs_dir_ + "/" + kDeletedPrefix + id;
  std::error_code ec;
  fs::rename(dir, doomed, ec);
  if (ec) throw std::runtime_error("cannot remove '" + dir + "': " + ec.message());
  contact::sync_directory(jobs_dir_);
  fs::remove_all(doomed, ec);
  if (ec) log_line("store: cannot finish removing '" + doomed + "': " + ec.message());
}

bool JobStore::writable() const {
  // Create, write and unlink a small file (no fsync: a readiness probe must stay cheap).
  const std::string probe = data_dir_ + "/.readyz-probe";
  ::unlink(probe.c_str());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  const bool wrote = ::write(fd, "ok\n", 3) == 3;
  ::close(fd);
  ::unlink(probe.c_str());
  return wrote;
}

}  // namespace contactd

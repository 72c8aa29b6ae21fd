#include "job_store.hpp"

#include "util.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace contactd {

namespace {
constexpr const char* kDeletedPrefix = ".deleted-";
}

JobStore::JobStore(const std::string& data_dir) : data_dir_(data_dir), jobs_dir_(data_dir + "/jobs") {
  std::error_code ec;
  fs::create_directories(jobs_dir_, ec);
  if (ec) throw std::runtime_error("cannot create the data directory '" + jobs_dir_ + "': " + ec.message());
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
    // Both files fsync'ed, then their directory and its parent once: durable before the 202 goes out.
    write_file_atomically(job_path(record.id), body, false);
    write_file_atomically(state_path(record.id), to_state_json(record).dump(2) + "\n", false);
    for (const std::string& file : {job_path(record.id), state_path(record.id)}) sync_file(file);
    sync_directory(dir);
    sync_directory(jobs_dir_);
  } catch (...) {
    fs::remove_all(dir, ec);
    throw;
  }
}

void JobStore::save_state(const JobRecord& record, bool durable) {
  write_file_atomically(state_path(record.id), to_state_json(record).dump(2) + "\n", durable);
}

std::string JobStore::read_job(const std::string& id) const { return read_whole_file(job_path(id)); }

void JobStore::remove_result(const std::string& id) {
  std::error_code ec;
  for (const std::string& path : {result_path(id), xmf_path(id)}) {
    fs::remove(path, ec);
    fs::remove(path + ".tmp", ec);
  }
}

std::vector<JobRecord> JobStore::load_all() {
  std::vector<JobRecord> records;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(jobs_dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kDeletedPrefix, 0) == 0) {  // a deletion interrupted by a crash: finish it
      fs::remove_all(entry.path(), ec);
      continue;
    }
    if (!is_job_id(name) || !entry.is_directory(ec)) {
      log_line("store: ignoring '" + entry.path().string() + "' (not a job directory)");
      continue;
    }
    // Temporary files are writes a crash interrupted; the file they were to replace is intact.
    for (const auto& file : fs::directory_iterator(entry.path(), ec)) {
      const std::string file_name = file.path().filename().string();
      if (file_name.size() > 4 && file_name.compare(file_name.size() - 4, 4, ".tmp") == 0) {
        log_line("store: removing the interrupted write '" + file.path().string() + "'");
        fs::remove(file.path(), ec);
      }
    }
    if (!fs::exists(state_path(name), ec)) {
      // Crashed between creating the directory and writing state.json: the submission was never acknowledged.
      log_line("store: removing the unacknowledged submission " + name);
      fs::remove_all(entry.path(), ec);
      continue;
    }
    try {
      JobRecord record = from_state_json(nlohmann::json::parse(read_whole_file(state_path(name))));
      if (record.id != name) throw std::runtime_error("its id is '" + record.id + "'");
      if (!fs::exists(job_path(name), ec)) throw std::runtime_error("job.json is missing");
      if (record.result_available && !fs::exists(result_path(name), ec)) record.result_available = false;
      records.push_back(std::move(record));
    } catch (const std::exception& e) {
      log_line("store: skipping job " + name + ": cannot read its state.json (" + e.what() + ")");
    }
  }
  std::sort(records.begin(), records.end(), [](const JobRecord& a, const JobRecord& b) {
    return a.created_us != b.created_us ? a.created_us < b.created_us : a.id < b.id;
  });
  return records;
}

void JobStore::remove(const std::string& id) {
  const std::string dir = job_dir(id);
  const std::string doomed = jobs_dir_ + "/" + kDeletedPrefix + id;
  std::error_code ec;
  fs::rename(dir, doomed, ec);
  if (ec) throw std::runtime_error("cannot remove '" + dir + "': " + ec.message());
  sync_directory(jobs_dir_);
  fs::remove_all(doomed, ec);
  if (ec) log_line("store: cannot finish removing '" + doomed + "': " + ec.message());
}

bool JobStore::writable() const {
  // Create, write and unlink a small file (no fsync: a readiness probe must stay cheap).
  const std::string probe = data_dir_ + "/.readyz-probe";
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  const bool wrote = ::write(fd, "ok\n", 3) == 3;
  ::close(fd);
  ::unlink(probe.c_str());
  return wrote;
}

}  // namespace contactd

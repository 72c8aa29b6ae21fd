// The jobs on disk. Layout (docs/server.md, "Data directory"):
//   <data>/.lock                    held with flock() while a server uses the directory (its pid inside)
//   <data>/.reserve                 1 MiB kept free for state changes when the disk fills up
//   <data>/jobs/<id>/job.json       the job as submitted (bytes unchanged)
//   <data>/jobs/<id>/idempotency.key  the submission's Idempotency-Key, when it had one
//   <data>/jobs/<id>/state.json     JobRecord (to_state_json), rewritten on every state change
//   <data>/jobs/<id>/events.ndjson  the progress events, append-only (EventLog)
//   <data>/jobs/<id>/result.hdf     the HDF5 result, and result.xmf its XDMF sidecar
//   <data>/jobs/<id>/pairs.json     the last iteration's detail of every pair (GET /v1/jobs/{id}/pairs)
//   <data>/jobs/<id>/crashed        the fatal signal its solve took, until the next start reads it (crash_marker.hpp)
// Every rewrite goes to "<file>.tmp", is fsync'ed and renamed over the file. Ids are checked with is_job_id()
// before they become paths; no file is opened through a symbolic link. Thread safety: the methods touch only the
// files of the job they are given, so calls for different jobs may run concurrently; the JobQueue serialises the
// writes of one job.
#pragma once

#include "store/job_record.hpp"

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace contactd {

class JobStore {
 public:
  // Creates <data_dir>/jobs if missing, takes the directory's lock and sets the disk reserve aside. Throws
  // std::runtime_error if any of that fails (another server holds the lock: its pid is in the message).
  explicit JobStore(const std::string& data_dir);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  const std::string& data_dir() const { return data_dir_; }
  const std::string& jobs_dir() const { return jobs_dir_; }
  std::string job_dir(const std::string& id) const;
  std::string job_path(const std::string& id) const { return job_dir(id) + "/job.json"; }
  std::string key_path(const std::string& id) const { return job_dir(id) + "/idempotency.key"; }
  std::string state_path(const std::string& id) const { return job_dir(id) + "/state.json"; }
  std::string events_path(const std::string& id) const { return job_dir(id) + "/events.ndjson"; }
  std::string result_path(const std::string& id) const { return job_dir(id) + "/result.hdf"; }
  std::string xmf_path(const std::string& id) const { return job_dir(id) + "/result.xmf"; }
  std::string pairs_path(const std::string& id) const { return job_dir(id) + "/pairs.json"; }

  // A new job's directory with job.json, state.json (and idempotency.key). Throws (the directory is removed).
  void create(const JobRecord& record, const std::string& body);

  // Rewrites state.json (atomically; `durable`: fsync'ed too). When the disk is full, the reserve is given up
  // and the write tried once more. Throws FileError.
  void save_state(const JobRecord& record, bool durable = true);

  // job.json as submitted. Throws FileError.
  std::string read_job(const std::string& id) const;

  // Removes result.hdf, result.xmf and pairs.json (and their temporary files) of a job about to run again.
  void remove_result(const std::string& id);

  // pairs.json: written atomically (not fsync'ed: it only serves GET /v1/jobs/{id}/pairs); read as its text, or
  // nullopt when there is none (or it is not a regular file). Throws FileError on a failed write.
  void save_pairs(const std::string& id, const std::string& text);
  std::optional<std::string> read_pairs(const std::string& id) const;

  // What is wrong with a finished job's result file, or nullopt: a symbolic link, not the size recorded, or not
  // starting with the HDF5 signature.
  std::optional<std::string> check_result(const JobRecord& record) const;
  // Opens result.hdf or result.xmf for reading (never through a link); -1 if it cannot.
  int open_result(const std::string& id, bool sidecar) const;
  // The bytes the job's directory holds (its files' sizes).
  std::int64_t disk_usage(const std::string& id) const;
  // The bytes the data directory's file system has free for this process (statvfs's f_bavail); -1 when it cannot
  // be asked. The reserve is not counted: it is not free.
  std::int64_t free_bytes() const;

  struct Damaged {
    std::string id;
    std::string problem;          // what was found, for /readyz and the log
    std::string idempotency_key;  // from idempotency.key, when the submission had one
  };
  struct Contents {
    std::vector<JobRecord> jobs;  // oldest first
    std::vector<Damaged> damaged;
  };
  // Every job found on disk. Removes what a crash left behind: temporary files, directories of submissions that
  // were never acknowledged (no state.json) and of interrupted deletions. A job whose state.json cannot be read,
  // or whose directory or files are links, is reported in `damaged` and left alone (never deleted).
  Contents load_all();

  // Deletes a job's directory: renamed out of the way first (atomic), then removed.
  void remove(const std::string& id);

  // Whether a file can be created in the data directory now (readiness).
  bool writable() const;
  // The reserve was given up to store a state change on a full disk (readiness says so until it is back).
  bool reserve_used() const { return reserve_used_.load(); }
  // Sets the reserve aside again if there is room for it and as much again; true if it is in place.
  bool restore_reserve();

 private:
  bool release_reserve();

  std::string data_dir_;
  std::string jobs_dir_;
  std::string reserve_path_;
  int lock_fd_ = -1;
  std::atomic<bool> reserve_used_{false};
};

}  // namespace contactd

// The jobs on disk. Layout (docs/server.md, "Data directory"):
//   <data>/jobs/<id>/job.json       the job as submitted (bytes unchanged)
//   <data>/jobs/<id>/state.json     JobRecord (to_state_json), rewritten on every state change
//   <data>/jobs/<id>/events.ndjson  the progress events, append-only (EventLog)
//   <data>/jobs/<id>/result.hdf     the HDF5 result, and result.xmf its XDMF sidecar
// Every rewrite goes to "<file>.tmp", is fsync'ed and renamed over the file. Ids are checked with is_job_id()
// before they become paths. Thread safety: the methods touch only the files of the job they are given, so
// calls for different jobs may run concurrently; the JobQueue serialises the writes of one job.
#pragma once

#include "job.hpp"

#include <string>
#include <vector>

namespace contactd {

class JobStore {
 public:
  // Creates <data_dir>/jobs if missing. Throws std::runtime_error if that fails.
  explicit JobStore(const std::string& data_dir);

  const std::string& data_dir() const { return data_dir_; }
  std::string job_dir(const std::string& id) const;
  std::string job_path(const std::string& id) const { return job_dir(id) + "/job.json"; }
  std::string state_path(const std::string& id) const { return job_dir(id) + "/state.json"; }
  std::string events_path(const std::string& id) const { return job_dir(id) + "/events.ndjson"; }
  std::string result_path(const std::string& id) const { return job_dir(id) + "/result.hdf"; }
  std::string xmf_path(const std::string& id) const { return job_dir(id) + "/result.xmf"; }

  // A new job's directory with job.json and state.json. Throws std::runtime_error (the directory is removed).
  void create(const JobRecord& record, const std::string& body);

  // Rewrites state.json (atomically; `durable`: fsync'ed too). Throws std::runtime_error.
  void save_state(const JobRecord& record, bool durable = true);

  // job.json as submitted. Throws std::runtime_error.
  std::string read_job(const std::string& id) const;

  // Removes result.hdf and result.xmf (and their temporary files) of a job about to run again.
  void remove_result(const std::string& id);

  // Every job found on disk, oldest first. Removes what a crash left behind: temporary files, directories of
  // submissions that were never acknowledged (no state.json) and of interrupted deletions. A directory whose
  // state.json cannot be read is logged and left alone (never deleted).
  std::vector<JobRecord> load_all();

  // Deletes a job's directory: renamed out of the way first (atomic), then removed.
  void remove(const std::string& id);

  // Whether a file can be created in the data directory now (readiness).
  bool writable() const;

 private:
  std::string data_dir_;
  std::string jobs_dir_;
};

}  // namespace contactd

// A job solved by MPI ranks (docs/parallel.md, "Through contactd"): contactd starts its MPI launcher with
// contact-solve as a child process, reads the child's progress (`--progress ndjson`: one JSON object per
// iteration, then a "result" object), and asks it to stop with SIGUSR1, which mpirun forwards to every rank, so
// that a cancelled, timed-out or interrupted job stops at the ranks' next exchange and still writes its result.
// The child writes the result file and its sidecar itself (rank 0), under the names the store serves.
#pragma once

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace contactd {

struct MpiSettings {
  std::vector<std::string> launcher;  // argv before the solver, "{ranks}" replaced; empty: no MPI jobs
  int max_ranks = 1;                  // largest parallel.ranks accepted
  std::string solver;                 // the contact-solve binary
  double kill_after_seconds = 30.0;   // after a stop request, the child's process group is killed
};

// Splits "mpirun --oversubscribe -n {ranks}" at spaces (no shell, no quoting).
std::vector<std::string> split_launcher(const std::string& text);

struct MpiOutcome {
  contact::StopReason stop_reason = contact::StopReason::error;
  std::string message;
  int iterations = 0;
  bool converged = false;
  double wall_seconds = 0.0;
  bool result_written = false;
  nlohmann::json steps = nlohmann::json::array();     // step events, as the child reported them
  nlohmann::json warnings = nlohmann::json::array();  // the model checks' warnings, as the child reported them
  nlohmann::json collapse;  // the collapse analysis's answer or a failed step's verdict (contact::io::collapse_json)
};

using ProgressLine = std::function<void(const std::string& type, const nlohmann::json& line)>;

// Runs `launcher... solver job_file -o result_path --progress ndjson --job-id job_id --max-dofs max_dofs
// --no-mesh-files` (a job of the server reads no files: its Gmsh meshes come as "data") and
// waits for it; on_progress receives every progress line's type ("iteration", "adaptive_step") and object
// (without "type"). Never throws for the child's failures (a launcher
// that cannot start, a rank that dies): they come back as stop_reason error with the child's last words.
MpiOutcome run_mpi_job(const MpiSettings& settings, int ranks, const std::string& job_file,
                       const std::string& result_path, const std::string& job_id, long max_dofs,
                       const ProgressLine& on_progress, const contact::CancelToken& cancel);

}  // namespace contactd

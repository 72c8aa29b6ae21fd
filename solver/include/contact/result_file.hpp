// The HDF5 result file: writer, XDMF sidecar, and a reader for tests and tools.
//
// The layout (groups, dataset shapes, dtypes, units, sign conventions) is specified in docs/results-format.md;
// change both together and bump kFormatVersion on any incompatible change.
//
// Thread safety: the functions may be called from several threads at once on different files (Debian's
// libhdf5 is built thread-safe; HDF5 serialises the calls internally).
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace contact::io {

inline constexpr const char* kFormatName = "contact-ddm-result";
inline constexpr int kFormatVersion =
    3;  // 2: mortar contact (per-node multipliers, contact surfaces); 3: contact tables

struct WriteInfo {
  std::string job_id;   // "" for the CLI
  std::string created;  // ISO 8601 UTC ("2024-05-01T12:00:00Z"); filled with the current time if empty
  std::string host;     // filled with the machine's host name if empty
};

// Writes `result` of `problem` to `path` (name it *.hdf: ParaView 5.11 finds no reader for *.h5).
// The file is written to "<path>.tmp", synced, then renamed over `path`, so a crash or an error never leaves a
// partial file under the final name; on error the temporary file is removed.
// Throws std::runtime_error naming the path and the failed step (HDF5's own message appended), and also when
// `result` is inconsistent (a field whose row count is neither the mesh's nor 0, a history row with another
// number of bodies or pairs, a body or pair name that cannot be an HDF5 link name).
void write_result(const std::string& path, const Problem& problem, const Result& result, const WriteInfo& info = {});

// Writes the XDMF 3 sidecar describing every step of `result` as a time series (Time = step index), each step a
// spatial collection of one grid per body. Data items reference "<hdf_file_name>:/steps/<k>/bodies/<name>/...",
// so `hdf_file_name` should be the result file's name relative to the sidecar's directory (normally the bare
// file name: both are written side by side). Same temporary-file-then-rename discipline and errors as above.
void write_xdmf(const std::string& xmf_path, const std::string& hdf_file_name, const Result& result);

// The result file and its XDMF sidecar written as the run goes: handed to solve() as the observer's StepSink
// (Observer::step_sink), it writes each step's fields (/steps/<k>) when the solver reaches it, so that a job
// that keeps every step holds one step in memory (two while one is written, below), not all (solve() then returns the
// last step only, Result::streamed_steps); finish() writes the rest when the run ends. The file is built under
// "<path>.tmp" and renamed over `path` by finish() only: a crash, an error or abandon() (and destruction before finish)
// never leave a partial file under the final name. Not thread safe: one run feeds it, from one thread.
//
// A step is written on a thread of the stream's own while the run goes on to the next step (the HDF5 calls are
// serialised by the library): on a wall of thousands of bricks a step's 200,000 small datasets take seconds,
// as long as a load step's solve. One write at a time: take() first waits for the previous one, so at most one
// step besides the run's current one is in memory; finish(), abandon(), steps_taken() and the destructor wait for
// the write in flight.
class ResultStream : public StepSink {
 public:
  // `hdf_name_in_xmf`: the result file as the sidecar names it (normally its bare file name).
  ResultStream(std::string path, std::string xmf_path, std::string hdf_name_in_xmf);
  ~ResultStream() override;
  ResultStream(const ResultStream&) = delete;
  ResultStream& operator=(const ResultStream&) = delete;

  // Writes the step as /steps/<the number taken before>. A failure (a full disk) is kept, the partial file
  // removed, and finish() throws it; later steps are ignored.
  void take(const Step& step) override;
  // Writes what the steps do not (root attributes, input, provenance, histories, the final step's copy for
  // ParaView) and the sidecar, and puts both in place. `result` is the run's (its streamed_steps the steps taken
  // here); with none taken, the whole of `result` is written as write_result and write_xdmf do. Throws
  // std::runtime_error naming the file, also for an error take() met.
  void finish(const Problem& problem, const Result& result, const WriteInfo& info = {});
  // No result after all (nothing held, the run refused): the partial file is removed.
  void abandon();
  std::size_t steps_taken() {
    wait();
    return taken_;
  }

 private:
  struct Open;
  void wait();                         // for the write in flight
  void write_taken(const Step& step);  // on the writer thread (or here when no thread can be started)
  std::thread writer_;
  std::string path_, xmf_path_, xmf_hdf_name_;
  std::unique_ptr<Open> open_;
  std::size_t taken_ = 0;
  std::string error_;
  bool finished_ = false;
};

// The sidecar's conventional name next to a result file: "x.hdf" -> "x.xmf" (other names get ".xmf" appended).
std::string xdmf_path_for(const std::string& hdf_path);

// About how many bytes the result file of a job takes (its steps are streamed to it, ResultStream, so this bounds
// the disk, not the memory): `kept_steps` steps' fields (and the final step's copy for ParaView, /VTKHDF) over `nodes`
// mesh nodes, `bodies` bodies and `pairs` contact pairs. Measured (format version 2): 270-280 bytes a node and step on
// two 40 x 40 to 80 x 80 blocks, and some 25 kB a body and step in metadata and small datasets (a 22 x 22 brick wall,
// 496 bodies: 30 MB for 2 steps). A pair (format version 3, the contact tables) is 770 bytes a step on the 64 x 64
// wall, and its columns of the iteration history 2 kB over the run's 32 iterations: 2 kB a pair and step keeps
// the estimate above the file (160 MB for 2 steps of 4,129 bodies and 12,192 pairs; 5 kB a pair in version 2).
// Job admission compares it with Limits::max_result_bytes.
double estimated_result_bytes(double nodes, double bodies, double pairs, double kept_steps);
// The other way round: the nodes, summed over up to `kept_steps` kept steps, that keep the result within `bytes`
// (the final step's copy counted as large as all of them; 0 when even the metadata does not fit).
double kept_nodes_within(double bytes, double bodies, double pairs, double kept_steps);

// ---------------------------------------------------------------------------------------------------------
// What read_result returns: the file's contents in the solver's own types where one exists.

struct Provenance {
  std::string solver_version, compiler, build_type, host, method, enforcement;
  std::string interface_solver;           // "direct" or "iterative" (interface_newton), else ""
  std::int64_t interface_iterations = 0;  // the iterative interface solver's MPRGP iterations
  double gamma = 0.0;
  double setup_seconds = 0.0, factorization_seconds = 0.0, wall_seconds = 0.0;
  std::vector<std::string> pair_names;  // of the final step
  std::vector<double> theta;            // penalty parameter per pair, final step
};

// /history/iterations: one row per IterationReport. Matrices are n_iterations x n_bodies or x n_pairs.
struct IterationHistory {
  std::vector<std::string> body_names, pair_names;
  std::vector<int> iteration, update, active_nodes_total, active_set_changes;
  std::vector<std::string> measure;  // per row: "fixed_point", "complementarity" or "gradient"
  std::vector<double> paper_criterion, fixed_point_residual, complementarity, elapsed_seconds;
  Eigen::MatrixXi elements, dofs, elements_refined;
  Eigen::MatrixXd force, max_pressure, extent_begin, extent_end, theta, max_penetration;
  Eigen::MatrixXi active_nodes, changed_nodes;
};

// /history/steps: one row per adaptive step. dofs = 2 x nodes (see the format document).
struct StepHistory {
  std::vector<std::string> body_names, pair_names;
  std::vector<int> step, iteration;
  std::vector<double> load_factor;
  std::vector<int> converged;      // 1 or 0 per step (older files: absent, every step converged)
  std::vector<double> multiplier;  // a collapse analysis's multiplier per step (0 before it; older files: empty)
  Eigen::MatrixXi elements, dofs;
  Eigen::MatrixXd force, contact_begin, contact_end;  // S x P
  Eigen::MatrixXd tangential_force;                   // S x P (0 for frictionless pairs; empty in older files)
};

// How a string attribute is stored (VTKHDF's Type must be fixed-length with size == its text length).
struct StringStorage {
  bool fixed_length = false;
  std::size_t size = 0;  // bytes, fixed-length only
  std::string padding;   // "nullpad", "nullterm" or "spacepad" (fixed-length only)
};

// /VTKHDF as stored (one partition per body, then one per contact pair, of the final step). `present` is false
// when the file has no steps.
struct VtkHdf {
  bool present = false;
  std::vector<std::int64_t> version;
  std::string type;
  StringStorage type_storage;
  std::vector<std::int64_t> number_of_points, number_of_cells, number_of_connectivity_ids;
  Eigen::MatrixXd points;  // sum(number_of_points) x 3
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::map<std::string, Eigen::MatrixXd> point_data, cell_data;  // rows = points / cells, columns = components
};

struct ResultFile {
  // root attributes
  std::string format;
  int format_version = 0;
  std::string solver_version, job_id, job_name, created;
  double wall_seconds = 0.0;
  bool converged = false;
  std::string stop_reason, message;
  int iterations = 0;
  std::string method;
  // /input
  std::string job_json, normalized_json;
  std::vector<Warning> warnings;  // /warnings: the model checks' (empty in a file written before them)
  CollapseResult collapse;        // /collapse: a collapse analysis's answer (analysed false without one)
  Provenance provenance;
  IterationHistory history;
  StepHistory step_history;
  // /steps/<k>; Step::index = its row in /history/steps (k when every step is kept). Meshes carry nodes, cells
  // and level only (no edge sets).
  std::vector<Step> steps;
  VtkHdf vtkhdf;
};

// Reads a file written by write_result. Throws std::runtime_error naming the path and what is missing or
// malformed (a file of another format or of a newer format version is refused).
ResultFile read_result(const std::string& path);

}  // namespace contact::io

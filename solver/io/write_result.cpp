// write_result: Result -> HDF5 file in the layout of docs/results-format.md.
#include "contact/result_file.hpp"

#include "contact/version.hpp"
#include "contact/utc_time.hpp"
#include "contact/work_label.hpp"
#include "view_layout.hpp"
#include "file_util.hpp"
#include "xdmf_series.hpp"
#include "contact/files.hpp"
#include "h5.hpp"
#include "h5_eigen.hpp"
#include "result_layout.hpp"
#include "collapse_group.hpp"
#include "contact_tables.hpp"
#include "vtkhdf.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <memory>
#include <new>
#include <system_error>
#include <type_traits>

namespace contact::io {

namespace {

using h5::Handle;
using h5::write_column;
using h5::write_matrix;

const char* compiler_name() {
#if defined(__clang__)
  return "clang " __clang_version__;
#elif defined(__GNUC__)
  return "GCC " __VERSION__;
#else
  return "unknown compiler";
#endif
}

const char* build_type() {
#if defined(CONTACT_BUILD_TYPE)
  return CONTACT_BUILD_TYPE;
#elif defined(NDEBUG)
  return "optimised (NDEBUG)";
#else
  return "debug (assertions on)";
#endif
}

std::string rows_text(Eigen::Index n) { return std::to_string(static_cast<long long>(n)); }

// Group names come from user-chosen body and pair names: they must be usable as one HDF5 link name.
void check_link_name(const std::string& kind, const std::string& name) {
  if (name.empty() || name == "." || name.find('/') != std::string::npos)
    throw std::runtime_error(kind + " name '" + name + "' cannot name an HDF5 group (empty, '.' or contains '/')");
}

// A per-node or per-cell field has the mesh's row count, or 0 rows when the solver did not produce it.
void check_rows(const std::string& what, Eigen::Index rows, Eigen::Index expected) {
  if (rows != expected && rows != 0)
    throw std::runtime_error(what + " has " + rows_text(rows) + " rows, expected " + rows_text(expected) + " (or 0)");
}

// ---- root, input, provenance --------------------------------------------------------------------------

// One attribute of result_layout.hpp's lists, as the list says it is stored.
struct AttributeWriter {
  hid_t obj;
  void operator()(const AttributeColumn& a, const std::string& v) const { h5::write_attribute(obj, a.name, v); }
  void operator()(const AttributeColumn& a, bool v) const { h5::write_attribute<std::int32_t>(obj, a.name, v ? 1 : 0); }
  void operator()(const AttributeColumn& a, int v) const { h5::write_attribute<std::int32_t>(obj, a.name, v); }
  void operator()(const AttributeColumn& a, std::int64_t v) const { h5::write_attribute<std::int64_t>(obj, a.name, v); }
  void operator()(const AttributeColumn& a, double v) const { h5::write_attribute<double>(obj, a.name, v); }
};

void write_root_attributes(hid_t file, const Problem& problem, const Result& result, const WriteInfo& info) {
  ResultFile root;
  root.format = kFormatName;
  root.format_version = kFormatVersion;
  root.solver_version = solver_version();
  root.job_id = info.job_id;
  root.job_name = problem.name;
  root.created = info.created;
  root.wall_seconds = result.wall_seconds;
  root.converged = result.converged;
  root.stop_reason = to_string(result.stop_reason);
  root.message = result.message;
  root.iterations = result.iterations;
  root.method = result.method;
  root_attributes(root, AttributeWriter{file});
}

std::string dump_json(const nlohmann::json& j) {
  // Replace invalid UTF-8 rather than throw: the document is a record, not an input.
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void write_input(hid_t file, const Problem& problem) {
  Handle input = h5::create_group(file, "input");
  h5::write_string_dataset(input, "job", dump_json(problem.submitted));
  h5::write_string_dataset(input, "normalized", dump_json(problem.normalized));
}

// What the model checks found, before and after the solve (Result::warnings): two string datasets of one row each.
void write_warnings(hid_t file, const Result& result) {
  Handle group = h5::create_group(file, "warnings");
  std::vector<std::string> pointers, messages;
  for (const auto& w : result.warnings) {
    pointers.push_back(w.pointer);
    messages.push_back(w.message);
  }
  h5::write_strings_dataset(group, "pointer", pointers);
  h5::write_strings_dataset(group, "message", messages);
}

void write_provenance(hid_t file, const Result& result, const WriteInfo& info) {
  Handle prov = h5::create_group(file, "provenance");
  Provenance p;
  p.solver_version = solver_version();
  p.compiler = compiler_name();
  p.build_type = build_type();
  p.host = info.host;
  p.method = result.method;
  p.enforcement = result.enforcement;
  p.interface_solver = result.interface_solver;
  p.interface_iterations = result.interface_iterations;
  p.gamma = result.gamma;
  p.setup_seconds = result.setup_seconds;
  p.factorization_seconds = result.factorization_seconds;
  p.wall_seconds = result.wall_seconds;
  provenance_attributes(p, AttributeWriter{prov});
  std::vector<std::string> names;
  std::vector<double> theta;
  if (!result.steps.empty()) {
    for (const auto& pair : result.steps.back().pairs) {
      names.push_back(pair.name);
      theta.push_back(pair.theta);
    }
  }
  h5::write_strings_dataset(prov, "pair_names", names);
  h5::write_vector(prov, "theta", theta);
}

// ---- history ------------------------------------------------------------------------------------------

// One dataset of a history table (result_layout.hpp), as the table says it is stored.
struct ColumnWriter {
  hid_t group;
  void operator()(const HistoryColumn& c, const std::vector<int>& v) const {
    if (c.stored == HistoryColumn::Stored::int8)
      h5::write_vector(group, c.name, std::vector<std::int8_t>(v.begin(), v.end()));
    else
      h5::write_vector(group, c.name, v);
  }
  void operator()(const HistoryColumn& c, const std::vector<double>& v) const { h5::write_vector(group, c.name, v); }
  void operator()(const HistoryColumn& c, const std::vector<std::string>& v) const {
    h5::write_strings_dataset(group, c.name, v);
  }
  void operator()(const HistoryColumn& c, const Eigen::MatrixXi& m) const { write_matrix(group, c.name, m); }
  void operator()(const HistoryColumn& c, const Eigen::MatrixXd& m) const { write_matrix(group, c.name, m); }
};

// The iteration rows as the columns of /history/iterations.
IterationHistory iteration_table(const Problem& problem, const std::vector<IterationReport>& rows) {
  IterationHistory h;
  // Columns are named by the first row (or by the problem when there is no row).
  if (!rows.empty()) {
    for (const auto& b : rows.front().bodies) h.body_names.push_back(b.name);
    for (const auto& p : rows.front().pairs) h.pair_names.push_back(p.name);
  } else {
    for (const auto& b : problem.bodies) h.body_names.push_back(b.name);
    for (const auto& c : problem.contacts) h.pair_names.push_back(c.name);
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  const auto nb = static_cast<Eigen::Index>(h.body_names.size());
  const auto np = static_cast<Eigen::Index>(h.pair_names.size());
  for (Eigen::MatrixXi* m : {&h.elements, &h.dofs, &h.elements_refined}) m->resize(n, nb);
  for (Eigen::MatrixXi* m : {&h.active_nodes, &h.changed_nodes}) m->resize(n, np);
  for (Eigen::MatrixXd* m : {&h.force, &h.max_pressure, &h.extent_begin, &h.extent_end, &h.theta, &h.max_penetration})
    m->resize(n, np);
  for (Eigen::Index i = 0; i < n; ++i) {
    const IterationReport& r = rows[static_cast<size_t>(i)];
    if (static_cast<Eigen::Index>(r.bodies.size()) != nb || static_cast<Eigen::Index>(r.pairs.size()) != np)
      throw std::runtime_error("history row " + rows_text(i) + " (iteration " + std::to_string(r.iteration) + ") has " +
                               std::to_string(r.bodies.size()) + " bodies and " + std::to_string(r.pairs.size()) +
                               " pairs; the first row has " + rows_text(nb) + " and " + rows_text(np));
    h.iteration.push_back(r.iteration);
    h.measure.push_back(to_string(r.measure));
    h.update.push_back(r.update);
    h.active_nodes_total.push_back(r.active_nodes);
    h.active_set_changes.push_back(r.active_set_changes);
    h.paper_criterion.push_back(r.paper_criterion);
    h.fixed_point_residual.push_back(r.fixed_point_residual);
    h.complementarity.push_back(r.complementarity);
    h.elapsed_seconds.push_back(r.elapsed_seconds);
    for (Eigen::Index b = 0; b < nb; ++b) {
      const BodyReport& body = r.bodies[static_cast<size_t>(b)];
      h.elements(i, b) = body.elements;
      h.dofs(i, b) = body.dofs;
      h.elements_refined(i, b) = body.elements_refined;
    }
    for (Eigen::Index p = 0; p < np; ++p) {
      const PairReport& pair = r.pairs[static_cast<size_t>(p)];
      h.force(i, p) = pair.force;
      h.max_pressure(i, p) = pair.max_pressure;
      h.extent_begin(i, p) = pair.extent_begin;
      h.extent_end(i, p) = pair.extent_end;
      h.active_nodes(i, p) = pair.active_nodes;
      h.changed_nodes(i, p) = pair.changed_nodes;
      h.theta(i, p) = pair.theta;
      h.max_penetration(i, p) = pair.max_penetration;
    }
  }
  return h;
}

void write_iteration_history(hid_t history, const Problem& problem, const Result& result) {
  Handle g = h5::create_group(history, "iterations");
  const IterationHistory h = iteration_table(problem, result.history);
  h5::write_attribute(g, "body_names", h.body_names);
  h5::write_attribute(g, "pair_names", h.pair_names);
  iteration_columns(h, ColumnWriter{g});
}

std::vector<std::string> body_names_of(const Step& s) {
  std::vector<std::string> names;
  for (const auto& b : s.bodies) names.push_back(b.name);
  return names;
}

std::vector<std::string> pair_names_of(const Step& s) {
  std::vector<std::string> names;
  for (const auto& p : s.pairs) names.push_back(p.name);
  return names;
}

// Every step's scalars: Result::step_history, or (a Result built without it) the steps' own.
std::vector<StepSummary> step_rows(const Result& result) {
  if (!result.step_history.empty()) return result.step_history;
  std::vector<StepSummary> rows;
  for (const Step& s : result.steps) rows.push_back(summarize(s));
  return rows;
}

// The step rows as the columns of /history/steps.
StepHistory step_table(const std::vector<StepSummary>& rows) {
  StepHistory h;
  if (!rows.empty()) {
    h.body_names = rows.front().body_names;
    h.pair_names = rows.front().pair_names;
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  const auto nb = static_cast<Eigen::Index>(h.body_names.size());
  const auto np = static_cast<Eigen::Index>(h.pair_names.size());
  h.elements.resize(n, nb);
  h.dofs.resize(n, nb);
  for (Eigen::MatrixXd* m : {&h.force, &h.contact_begin, &h.contact_end, &h.tangential_force}) m->resize(n, np);
  for (Eigen::Index k = 0; k < n; ++k) {
    const StepSummary& s = rows[static_cast<size_t>(k)];
    if (s.body_names != h.body_names)
      throw std::runtime_error("step " + rows_text(k) + " does not have the bodies of step 0 in the same order");
    if (s.pair_names != h.pair_names)
      throw std::runtime_error("step " + rows_text(k) + " does not have the pairs of step 0 in the same order");
    h.step.push_back(static_cast<int>(k));
    h.iteration.push_back(s.iteration);
    h.load_factor.push_back(s.load_factor);
    h.multiplier.push_back(s.multiplier);
    h.converged.push_back(s.converged ? 1 : 0);
    for (Eigen::Index b = 0; b < nb; ++b) {
      h.elements(k, b) = s.elements[static_cast<size_t>(b)];
      h.dofs(k, b) = 2 * s.nodes[static_cast<size_t>(b)];
    }
    for (Eigen::Index p = 0; p < np; ++p) {
      h.force(k, p) = s.force[static_cast<size_t>(p)];
      h.tangential_force(k, p) = s.tangential_force[static_cast<size_t>(p)];  // 0 for a frictionless pair
      h.contact_begin(k, p) = s.contact_begin[static_cast<size_t>(p)];
      h.contact_end(k, p) = s.contact_end[static_cast<size_t>(p)];
    }
  }
  return h;
}

void write_step_history(hid_t history, const std::vector<StepSummary>& rows) {
  Handle g = h5::create_group(history, "steps");
  const StepHistory h = step_table(rows);
  h5::write_attribute(g, "body_names", h.body_names);
  h5::write_attribute(g, "pair_names", h.pair_names);
  step_columns(h, ColumnWriter{g});
}

// ---- steps --------------------------------------------------------------------------------------------

void write_body(hid_t bodies, const BodyField& b, const std::string& where) {
  check_link_name("body", b.name);
  const mesh::Mesh& m = b.mesh;
  const Eigen::Index n = m.num_nodes();
  const Eigen::Index c = m.num_cells();
  const std::string at = where + " body '" + b.name + "': ";
  using Per = BodyFieldColumn::Per;
  body_fields(b, [&](const BodyFieldColumn& f, const auto& v) {
    if (!(f.optional && v.size() == 0)) check_rows(at + f.name, v.rows(), f.per == Per::node ? n : c);
  });
  check_rows(at + "mesh level", static_cast<Eigen::Index>(m.level.size()), c);

  Handle g = h5::create_group(bodies, b.name);
  Eigen::MatrixX2d points(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) points.row(i) = m.nodes[static_cast<size_t>(i)].transpose();
  // cells: 4 node indices per row, -1 in the last column of a triangle; cell_types: VTK's type per cell. An
  // all-quadrilateral mesh also has them as `quads` (a second name of the same dataset, as in format version 2
  // before triangles); a mesh with triangles has `xdmf_topology` for the sidecar's Mixed topology instead.
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 4> cells(c, 4);
  std::vector<std::uint8_t> types(static_cast<size_t>(c));
  std::vector<std::int64_t> mixed;
  std::vector<std::int32_t> level(static_cast<size_t>(c), 0);
  for (Eigen::Index e = 0; e < c; ++e) {
    const mesh::Cell& cell = m.cells[static_cast<size_t>(e)];
    for (int j = 0; j < 4; ++j) cells(e, j) = j < cell.size() ? cell[static_cast<size_t>(j)] : -1;
    types[static_cast<size_t>(e)] = vtk_cell_type(cell);
    mixed.push_back(xdmf_cell_type(cell));
    mixed.insert(mixed.end(), cell.begin(), cell.end());
    if (!m.level.empty()) level[static_cast<size_t>(e)] = m.level[static_cast<size_t>(e)];
  }
  write_matrix(g, "points", points);
  write_matrix(g, "cells", cells);
  h5::write_vector(g, "cell_types", types);
  if (m.has_triangles())
    h5::write_vector(g, "xdmf_topology", mixed);
  else
    h5::hard_link(g, "cells", "quads");
  h5::write_vector(g, "level", level);
  body_fields(b, [&](const BodyFieldColumn& f, const auto& v) {
    if (f.optional && v.size() == 0) return;
    if constexpr (std::decay_t<decltype(v)>::ColsAtCompileTime == 1)
      write_column(g, f.name, v);
    else
      write_matrix(g, f.name, v);
  });
  write_matrix(g, "stress_cell_tensor", stress_tensor(b.stress_cell));  // the sidecar's (view_layout.hpp)
  write_matrix(g, "stress_node_tensor", stress_tensor(b.stress_node));
  h5::write_attribute_array<double>(g, "reaction_total", {b.reaction_total.x(), b.reaction_total.y()});
  if (!b.support_reactions.empty()) {
    std::vector<std::string> names;
    Eigen::MatrixX2d sums(static_cast<Eigen::Index>(b.support_reactions.size()), 2);
    for (size_t i = 0; i < b.support_reactions.size(); ++i) {
      names.push_back(b.support_reactions[i].where);
      sums.row(static_cast<Eigen::Index>(i)) = b.support_reactions[i].force.transpose();
    }
    write_matrix(g, "support_reactions", sums);
    h5::write_attribute(g, "support_names", names);
  }
  if (!b.free_motions.empty()) {
    h5::write_attribute(g, "free_motions", b.free_motions);
    h5::write_attribute_array<double>(g, "rigid_center", {b.rigid_center.x(), b.rigid_center.y()});
    h5::write_attribute_array<double>(g, "rigid_motion", {b.rigid_motion.x(), b.rigid_motion.y(), b.rigid_motion.z()});
  }
}

// One step's fields as /steps/<k>; `row` is its row in /history/steps.
void write_step(hid_t steps, const Step& s, size_t k, size_t row) {
  const std::string where = "step " + std::to_string(k);
  Handle g = h5::create_group(steps, std::to_string(k));
  h5::write_attribute<std::int32_t>(g, "step", static_cast<std::int32_t>(row));
  h5::write_attribute<std::int32_t>(g, "iteration", s.iteration);
  h5::write_attribute<double>(g, "load_factor", s.load_factor);
  h5::write_attribute<double>(g, "multiplier", s.multiplier);
  h5::write_attribute<std::int8_t>(g, "converged", s.converged ? 1 : 0);
  h5::write_attribute(g, "body_names", body_names_of(s));
  h5::write_attribute(g, "pair_names", pair_names_of(s));
  Handle bodies = h5::create_group(g, "bodies");
  for (const auto& b : s.bodies) write_body(bodies, b, where);
  write_contact_tables(g, s, where);
}

void check_kept_steps(std::size_t kept, std::size_t history_rows) {
  if (kept > history_rows)
    throw std::runtime_error(std::to_string(kept) + " steps kept, more than the " + std::to_string(history_rows) +
                             " rows of the step history");
}

// The steps whose fields were kept: every step, or the last ones (output.steps "last": one). Each group's `step`
// is its row in /history/steps.
void write_steps(hid_t file, const Result& result, std::size_t history_rows) {
  Handle steps = h5::create_group(file, "steps");
  h5::write_attribute<std::int32_t>(steps, "count", static_cast<std::int32_t>(result.steps.size()));
  check_kept_steps(result.steps.size(), history_rows);
  for (size_t k = 0; k < result.steps.size(); ++k)
    write_step(steps, result.steps[k], k, history_rows - result.steps.size() + k);
}

// Everything but /steps: the root's attributes, the job, the provenance, both histories, the final step's copy
// for ParaView.
void write_all_but_steps(hid_t file, const Problem& problem, const Result& result, const WriteInfo& info,
                         const std::vector<StepSummary>& rows) {
  write_root_attributes(file, problem, result, info);
  write_input(file, problem);
  write_warnings(file, result);
  write_collapse(file, result.collapse);
  write_provenance(file, result, info);
  {
    Handle history = h5::create_group(file, "history");
    write_iteration_history(history, problem, result);
    write_step_history(history, rows);
  }
  if (!result.steps.empty()) write_vtkhdf(file, result.steps.back());
}

WriteInfo filled(const WriteInfo& info) {
  WriteInfo out = info;
  if (out.created.empty()) out.created = iso8601_utc(now_unix_us(), TimePrecision::seconds);
  if (out.host.empty()) out.host = detail::host_name();
  return out;
}

}  // namespace

void write_result(const std::string& path, const Problem& problem, const Result& result, const WriteInfo& info) {
  const WriteInfo with = filled(info);
  detail::write_atomically(path, "result file", [&](const std::string& tmp) {
    h5::QuietErrors quiet;
    Handle file = h5::create_file(tmp);
    const std::vector<StepSummary> rows = step_rows(result);
    write_steps(file, result, rows.size());
    write_all_but_steps(file, problem, result, with, rows);
    file.close("close the file");
  });
}

// ---- the result file written as the run goes ------------------------------------------------------------

// The file being written (destroyed in reverse: the handles are closed before the unfinished file is removed).
struct ResultStream::Open {
  PendingFile pending;
  Handle file, steps;
  detail::XdmfSeries xdmf;
  Open(const std::string& path, const std::string& hdf_name_in_xmf) : pending(path), xdmf(hdf_name_in_xmf) {}
};

ResultStream::ResultStream(std::string path, std::string xmf_path, std::string hdf_name_in_xmf)
    : path_(std::move(path)), xmf_path_(std::move(xmf_path)), xmf_hdf_name_(std::move(hdf_name_in_xmf)) {}

ResultStream::~ResultStream() { wait(); }  // then an unfinished file is removed (PendingFile)

void ResultStream::wait() {
  if (writer_.joinable()) writer_.join();
}

void ResultStream::take(const Step& step) {
  wait();
  if (!error_.empty() || finished_) return;  // already failed: the error is thrown by finish
  // The writer's own copy: the run moves on (and replaces its step) while the copy is written.
  std::shared_ptr<const Step> copy;
  try {
    copy = std::make_shared<const Step>(step);
  } catch (const std::bad_alloc&) {  // no memory for a copy: write the run's step here, as before the thread
    write_taken(step);
    return;
  }
  try {
    writer_ = std::thread([this, copy, label = std::string(work_label())] {
      const WorkLabelScope labelled(label);  // a crash in the write names the caller's job
      write_taken(*copy);
    });
  } catch (const std::system_error&) {  // no thread to be had: write it here
    write_taken(*copy);
  }
}

void ResultStream::write_taken(const Step& step) {
  try {
    h5::QuietErrors quiet;
    if (!open_) {
      open_ = std::make_unique<Open>(path_, xmf_hdf_name_);
      open_->file = h5::create_file(open_->pending.tmp());
      open_->steps = h5::create_group(open_->file, "steps");
    }
    write_step(open_->steps, step, taken_, taken_);
    open_->xdmf.add(step);
    ++taken_;
  } catch (const std::exception& e) {
    error_ = "cannot write result file '" + path_ + "': " + e.what();
    open_.reset();  // removes the partial file: the space it took may be what the disk lacks
  } catch (...) {
    error_ = "cannot write result file '" + path_ + "': an unknown error";
    open_.reset();
  }
}

void ResultStream::finish(const Problem& problem, const Result& result, const WriteInfo& info) {
  wait();
  if (finished_) throw std::runtime_error("result file '" + path_ + "' finished twice");
  finished_ = true;
  if (!error_.empty()) throw std::runtime_error(error_);
  if (taken_ == 0) {  // nothing streamed: the whole file at once
    write_result(path_, problem, result, info);
    write_xdmf(xmf_path_, xmf_hdf_name_, result);
    return;
  }
  if (static_cast<std::size_t>(result.streamed_steps) != taken_)
    throw std::runtime_error("result file '" + path_ + "': " + std::to_string(taken_) +
                             " steps written, the run says " + std::to_string(result.streamed_steps));
  try {
    h5::QuietErrors quiet;
    const std::vector<StepSummary> rows = step_rows(result);
    check_kept_steps(taken_, rows.size());
    h5::write_attribute<std::int32_t>(open_->steps, "count", static_cast<std::int32_t>(taken_));
    write_all_but_steps(open_->file, problem, result, filled(info), rows);
    open_->steps = Handle();
    open_->file.close("close the file");
    open_->pending.commit(true);
  } catch (const std::exception& e) {
    open_.reset();
    throw std::runtime_error("cannot write result file '" + path_ + "': " + e.what());
  }
  const std::unique_ptr<Open> done = std::move(open_);
  done->xdmf.write(xmf_path_);
}

void ResultStream::abandon() {
  wait();
  finished_ = true;
  open_.reset();
}

}  // namespace contact::io

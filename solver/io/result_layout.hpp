// The result file's two history tables, declared once (docs/results-format.md, "/history/iterations" and
// "/history/steps"): write_result.cpp and read_result.cpp walk these lists, in this order (the order in which the
// datasets are created), and tests/unit/test_io.cpp compares them, name, shape and type, with the format document's
// tables. A column added here is written, read and checked against the document; nowhere else names it.
#pragma once

#include "contact/result_file.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace contact::io {

struct HistoryColumn {
  enum class Across { none, bodies, pairs };  // a 1-D dataset (one value a row), or one column a body or a pair
  enum class Stored { int32, int8, float64, text };
  const char* name;
  Across across;
  Stored stored;
  bool optional;  // absent in older files: read as empty
};

// visit(column, member) for every column of /history/iterations; History is IterationHistory or its const.
template <class History, class Visit>
void iteration_columns(History& h, Visit&& visit) {
  using A = HistoryColumn::Across;
  using S = HistoryColumn::Stored;
  visit(HistoryColumn{"iteration", A::none, S::int32, false}, h.iteration);
  visit(HistoryColumn{"update", A::none, S::int32, false}, h.update);
  visit(HistoryColumn{"measure", A::none, S::text, false}, h.measure);
  visit(HistoryColumn{"paper_criterion", A::none, S::float64, false}, h.paper_criterion);
  visit(HistoryColumn{"fixed_point_residual", A::none, S::float64, false}, h.fixed_point_residual);
  visit(HistoryColumn{"complementarity", A::none, S::float64, false}, h.complementarity);
  visit(HistoryColumn{"active_nodes_total", A::none, S::int32, false}, h.active_nodes_total);
  visit(HistoryColumn{"active_set_changes", A::none, S::int32, false}, h.active_set_changes);
  visit(HistoryColumn{"elapsed_seconds", A::none, S::float64, false}, h.elapsed_seconds);
  visit(HistoryColumn{"elements", A::bodies, S::int32, false}, h.elements);
  visit(HistoryColumn{"dofs", A::bodies, S::int32, false}, h.dofs);
  visit(HistoryColumn{"elements_refined", A::bodies, S::int32, false}, h.elements_refined);
  visit(HistoryColumn{"force", A::pairs, S::float64, false}, h.force);
  visit(HistoryColumn{"max_pressure", A::pairs, S::float64, false}, h.max_pressure);
  visit(HistoryColumn{"extent_begin", A::pairs, S::float64, false}, h.extent_begin);
  visit(HistoryColumn{"extent_end", A::pairs, S::float64, false}, h.extent_end);
  visit(HistoryColumn{"active_nodes", A::pairs, S::int32, false}, h.active_nodes);
  visit(HistoryColumn{"changed_nodes", A::pairs, S::int32, false}, h.changed_nodes);
  visit(HistoryColumn{"theta", A::pairs, S::float64, false}, h.theta);
  visit(HistoryColumn{"max_penetration", A::pairs, S::float64, false}, h.max_penetration);
}

// visit(column, member) for every column of /history/steps; History is StepHistory or its const.
template <class History, class Visit>
void step_columns(History& h, Visit&& visit) {
  using A = HistoryColumn::Across;
  using S = HistoryColumn::Stored;
  visit(HistoryColumn{"step", A::none, S::int32, false}, h.step);
  visit(HistoryColumn{"iteration", A::none, S::int32, false}, h.iteration);
  visit(HistoryColumn{"load_factor", A::none, S::float64, false}, h.load_factor);
  visit(HistoryColumn{"converged", A::none, S::int8, true}, h.converged);
  visit(HistoryColumn{"multiplier", A::none, S::float64, true}, h.multiplier);
  visit(HistoryColumn{"elements", A::bodies, S::int32, false}, h.elements);
  visit(HistoryColumn{"dofs", A::bodies, S::int32, false}, h.dofs);
  visit(HistoryColumn{"force", A::pairs, S::float64, false}, h.force);
  visit(HistoryColumn{"contact_begin", A::pairs, S::float64, false}, h.contact_begin);
  visit(HistoryColumn{"contact_end", A::pairs, S::float64, false}, h.contact_end);
  visit(HistoryColumn{"tangential_force", A::pairs, S::float64, true}, h.tangential_force);
}

// ---- the root's and /provenance's attributes --------------------------------------------------------------

// One scalar attribute (docs/results-format.md, "Root attributes" and "/provenance"); a bool member is stored as int32
// 0 or 1.
struct AttributeColumn {
  enum class Stored { text, int32, int64, float64 };
  const char* name;
  Stored stored;
  bool optional = false;  // absent in older files: the member keeps its default
};

// visit(attribute, member) for every root attribute; File is ResultFile or its const.
template <class File, class Visit>
void root_attributes(File& r, Visit&& visit) {
  using S = AttributeColumn::Stored;
  visit(AttributeColumn{"format", S::text}, r.format);
  visit(AttributeColumn{"format_version", S::int32}, r.format_version);
  visit(AttributeColumn{"solver_version", S::text}, r.solver_version);
  visit(AttributeColumn{"job_id", S::text}, r.job_id);
  visit(AttributeColumn{"name", S::text}, r.job_name);
  visit(AttributeColumn{"created", S::text}, r.created);
  visit(AttributeColumn{"wall_seconds", S::float64}, r.wall_seconds);
  visit(AttributeColumn{"converged", S::int32}, r.converged);
  visit(AttributeColumn{"stop_reason", S::text}, r.stop_reason);
  visit(AttributeColumn{"message", S::text}, r.message);
  visit(AttributeColumn{"iterations", S::int32}, r.iterations);
  visit(AttributeColumn{"method", S::text}, r.method);
}

// visit(attribute, member) for every attribute of /provenance; Prov is Provenance or its const. (Its datasets,
// pair_names and theta, are the final step's pairs'.)
template <class Prov, class Visit>
void provenance_attributes(Prov& p, Visit&& visit) {
  using S = AttributeColumn::Stored;
  visit(AttributeColumn{"solver_version", S::text}, p.solver_version);
  visit(AttributeColumn{"compiler", S::text}, p.compiler);
  visit(AttributeColumn{"build_type", S::text}, p.build_type);
  visit(AttributeColumn{"host", S::text}, p.host);
  visit(AttributeColumn{"method", S::text}, p.method);
  visit(AttributeColumn{"enforcement", S::text}, p.enforcement);
  visit(AttributeColumn{"interface_solver", S::text, true}, p.interface_solver);
  visit(AttributeColumn{"interface_iterations", S::int64, true}, p.interface_iterations);
  visit(AttributeColumn{"gamma", S::float64}, p.gamma);
  visit(AttributeColumn{"setup_seconds", S::float64}, p.setup_seconds);
  visit(AttributeColumn{"factorization_seconds", S::float64}, p.factorization_seconds);
  visit(AttributeColumn{"wall_seconds", S::float64}, p.wall_seconds);
}

// ---- /steps/<k>/bodies/<body> ------------------------------------------------------------------------------

// A body's fields (docs/results-format.md, "/steps/<k>/bodies/<body>/"): a value or a row of components per node or
// per cell, float64. The mesh (points, cells, cell_types, quads or xdmf_topology, level), the sidecar's stress
// tensors and the supports' sums are written from the mesh and these fields (write_result.cpp, write_body).
struct BodyFieldColumn {
  enum class Per { node, cell };
  const char* name;
  Per per;
  int components;  // 1: a (rows,) dataset
  bool optional;   // absent where the body has none (empty member)
};

// visit(column, member) for every field of a body; Body is BodyField or its const.
template <class Body, class Visit>
void body_fields(Body& b, Visit&& visit) {
  using P = BodyFieldColumn::Per;
  visit(BodyFieldColumn{"displacement", P::node, 2, false}, b.displacement);
  visit(BodyFieldColumn{"stress_cell", P::cell, 4, false}, b.stress_cell);
  visit(BodyFieldColumn{"stress_node", P::node, 4, false}, b.stress_node);
  visit(BodyFieldColumn{"von_mises", P::cell, 1, false}, b.von_mises_cell);
  visit(BodyFieldColumn{"indicator", P::cell, 1, true}, b.indicator_cell);
  visit(BodyFieldColumn{"reaction", P::node, 2, false}, b.reaction);
}

// ---- /steps/<k>/contacts ---------------------------------------------------------------------------------

// A step's contact pairs as tables (format version 3): every pair's slave nodes one after the other, the pairs'
// row offsets, every pair's scalars in one dataset each. Two-column quantities are row-major (N x 2), as stored.
struct ContactTables {
  // per pair: P rows (offsets: P + 1)
  std::vector<std::int64_t> offsets{0}, segment_offsets{0};
  std::vector<std::string> slave_body, slave_edge, master_body, master_edge, enforcement, friction;
  std::vector<double> theta, force, resultant, friction_coefficient, friction_bound, tangential_force;
  std::vector<double> centre_of_pressure, eccentricity, open_fraction, slip_fraction, friction_utilisation;  // joints
  // per slave node: N rows
  std::vector<std::int32_t> pair;
  std::vector<std::int64_t> node;
  std::vector<double> position, normal, arc_length, weight, gap, normal_gap, pressure, penetration;
  std::vector<std::int8_t> status, active, stick;
  std::vector<double> tangent, tangential_traction, slip;
  // per segment: L rows of two node rows
  std::vector<std::int64_t> segments;
};

struct ContactColumn {
  enum class Rows { pair_offsets, pairs, nodes, segments };  // P + 1, P, N or L rows
  const char* name;
  Rows rows;
  int width;              // 1: one value a row; 2: two columns
  bool optional = false;  // absent in older files of this version: read as empty (and then derived)
};

// visit(column, member) for every dataset of a contacts group; Tables is ContactTables or its const.
template <class Tables, class Visit>
void contact_columns(Tables& t, Visit&& visit) {
  using R = ContactColumn::Rows;
  visit(ContactColumn{"offsets", R::pair_offsets, 1}, t.offsets);
  visit(ContactColumn{"segment_offsets", R::pair_offsets, 1}, t.segment_offsets);
  visit(ContactColumn{"slave_body", R::pairs, 1}, t.slave_body);
  visit(ContactColumn{"slave_edge", R::pairs, 1}, t.slave_edge);
  visit(ContactColumn{"master_body", R::pairs, 1}, t.master_body);
  visit(ContactColumn{"master_edge", R::pairs, 1}, t.master_edge);
  visit(ContactColumn{"enforcement", R::pairs, 1}, t.enforcement);
  visit(ContactColumn{"friction", R::pairs, 1}, t.friction);
  visit(ContactColumn{"theta", R::pairs, 1}, t.theta);
  visit(ContactColumn{"force", R::pairs, 1}, t.force);
  visit(ContactColumn{"resultant", R::pairs, 2}, t.resultant);
  visit(ContactColumn{"friction_coefficient", R::pairs, 1}, t.friction_coefficient);
  visit(ContactColumn{"friction_bound", R::pairs, 1}, t.friction_bound);
  visit(ContactColumn{"tangential_force", R::pairs, 1}, t.tangential_force);
  visit(ContactColumn{"centre_of_pressure", R::pairs, 1, true}, t.centre_of_pressure);
  visit(ContactColumn{"eccentricity", R::pairs, 1, true}, t.eccentricity);
  visit(ContactColumn{"open_fraction", R::pairs, 1, true}, t.open_fraction);
  visit(ContactColumn{"slip_fraction", R::pairs, 1, true}, t.slip_fraction);
  visit(ContactColumn{"friction_utilisation", R::pairs, 1, true}, t.friction_utilisation);
  visit(ContactColumn{"pair", R::nodes, 1}, t.pair);
  visit(ContactColumn{"node", R::nodes, 1}, t.node);
  visit(ContactColumn{"position", R::nodes, 2}, t.position);
  visit(ContactColumn{"normal", R::nodes, 2}, t.normal);
  visit(ContactColumn{"arc_length", R::nodes, 1}, t.arc_length);
  visit(ContactColumn{"status", R::nodes, 1}, t.status);
  visit(ContactColumn{"weight", R::nodes, 1}, t.weight);
  visit(ContactColumn{"gap", R::nodes, 1}, t.gap);
  visit(ContactColumn{"normal_gap", R::nodes, 1}, t.normal_gap);
  visit(ContactColumn{"pressure", R::nodes, 1}, t.pressure);
  visit(ContactColumn{"penetration", R::nodes, 1}, t.penetration);
  visit(ContactColumn{"active", R::nodes, 1}, t.active);
  visit(ContactColumn{"tangent", R::nodes, 2}, t.tangent);
  visit(ContactColumn{"tangential_traction", R::nodes, 1}, t.tangential_traction);
  visit(ContactColumn{"slip", R::nodes, 1}, t.slip);
  visit(ContactColumn{"stick", R::nodes, 1}, t.stick);
  visit(ContactColumn{"segments", R::segments, 2}, t.segments);
}

}  // namespace contact::io

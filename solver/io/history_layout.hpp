// The result file's two history tables, declared once (docs/results-format.md, "/history/iterations" and
// "/history/steps"): write_result.cpp and read_result.cpp walk these lists, in this order (the order in which the
// datasets are created), and tests/test_io.cpp compares them, name, shape and type, with the format document's
// tables. A column added here is written, read and checked against the document; nowhere else names it.
#pragma once

#include "contact/result_file.hpp"

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
  visit(HistoryColumn{"elements", A::bodies, S::int32, false}, h.elements);
  visit(HistoryColumn{"dofs", A::bodies, S::int32, false}, h.dofs);
  visit(HistoryColumn{"force", A::pairs, S::float64, false}, h.force);
  visit(HistoryColumn{"contact_begin", A::pairs, S::float64, false}, h.contact_begin);
  visit(HistoryColumn{"contact_end", A::pairs, S::float64, false}, h.contact_end);
  visit(HistoryColumn{"tangential_force", A::pairs, S::float64, true}, h.tangential_force);
}

}  // namespace contact::io

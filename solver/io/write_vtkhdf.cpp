// write_vtkhdf: the final step as a VTKHDF 1.0 UnstructuredGrid (docs/results-format.md, "/VTKHDF").
//
// Partitions: every body (VTK_QUAD and VTK_TRIANGLE cells), then every contact pair (its slave polyline, VTK_LINE
// cells). The per-partition counts are NumberOf*, and Points, Connectivity, Offsets, Types and the data arrays are the
// partitions' arrays one after the other, with Connectivity holding partition-local point ids and each
// partition's Offsets starting at 0. VTKHDF 1.0 needs every array on every partition, so:
//  * a contact partition's points carry the slave body's displacement, stress and reaction at those nodes;
//  * body points carry pressure and gap NaN and active -1 (not a contact point); with friction pairs also
//    tangential_traction and slip (NaN off the friction pairs' points);
//  * contact cells carry NaN for the cell stresses, body_id -1 and their pair's index in pair_id (-1 on body
//    cells), so that a Threshold on pair_id >= 0 shows the contact surfaces alone.
#include "vtkhdf.hpp"

#include "view_layout.hpp"
#include "h5.hpp"
#include "h5_eigen.hpp"

#include <limits>

namespace contact::io {

namespace {

using h5::Handle;
using h5::with_zero_z;
using h5::write_column;
using h5::write_matrix;

const double nan = std::numeric_limits<double>::quiet_NaN();

// Which optional fields every body has (written only then) and which some body has (the indicator: NaN elsewhere).
struct Presence {
  bool displacement = true, stress_node = true, reaction = true, stress_cell = true, von_mises = true;
  bool indicator = false;
};

// The grid's arrays, all partitions one after the other, filled partition by partition.
struct Grid {
  std::vector<std::int64_t> n_points, n_cells, n_ids, connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::vector<std::int32_t> body_id, pair_id, level;
  Presence has;
  Eigen::MatrixX3d points, displacement, reaction;
  StressTensor stress_node, stress_cell;  // ParaView names these components
  Eigen::VectorXd von_mises, indicator;
  Eigen::VectorXd pressure, gap;
  // Friction (written when some pair has it): NaN off the friction pairs' points.
  Eigen::VectorXd tangential_traction, slip;
  bool any_friction = false;
  Eigen::Matrix<std::int8_t, Eigen::Dynamic, 1> active;
  Eigen::Index p0 = 0, c0 = 0;  // the next partition's first point and cell
};

// Counts every partition's points and cells, finds which fields are present and sizes the arrays.
Grid size_grid(const Step& last) {
  Grid g;
  Eigen::Index total_points = 0, total_cells = 0;
  for (const auto& b : last.bodies) {
    total_points += b.mesh.num_nodes();
    total_cells += b.mesh.num_cells();
    g.has.displacement = g.has.displacement && b.displacement.rows() > 0;
    g.has.stress_node = g.has.stress_node && b.stress_node.rows() > 0;
    g.has.reaction = g.has.reaction && b.reaction.rows() > 0;
    g.has.stress_cell = g.has.stress_cell && b.stress_cell.rows() > 0;
    g.has.von_mises = g.has.von_mises && b.von_mises_cell.rows() > 0;
    g.has.indicator = g.has.indicator || b.indicator_cell.rows() > 0;
  }
  for (const auto& p : last.pairs) {
    total_points += p.position.rows();
    total_cells += pair_segments(p.position.rows(), slave_is_closed(last, p)).rows();
  }
  g.points.resize(total_points, 3);
  g.displacement.resize(total_points, 3);
  g.reaction.resize(total_points, 3);
  g.stress_node.resize(total_points, 6);
  g.stress_cell.resize(total_cells, 6);
  g.von_mises.resize(total_cells);
  g.indicator.resize(total_cells);
  g.pressure = Eigen::VectorXd::Constant(total_points, nan);
  g.gap = g.pressure;
  g.tangential_traction = g.pressure;
  g.slip = g.pressure;
  g.active = Eigen::Matrix<std::int8_t, Eigen::Dynamic, 1>::Constant(total_points, -1);
  return g;
}

// One body's partition: its nodes and cells (quads, triangles) with their fields.
void append_body(Grid& g, const BodyField& b, size_t id) {
  const mesh::Mesh& m = b.mesh;
  const Eigen::Index n = m.num_nodes(), c = m.num_cells(), p0 = g.p0, c0 = g.c0;
  g.n_points.push_back(n);
  g.n_cells.push_back(c);
  for (Eigen::Index i = 0; i < n; ++i)
    g.points.row(p0 + i) << m.nodes[static_cast<size_t>(i)].x(), m.nodes[static_cast<size_t>(i)].y(), 0.0;
  g.offsets.push_back(0);
  std::int64_t ids = 0;
  for (Eigen::Index e = 0; e < c; ++e) {
    const mesh::Cell& cell = m.cells[static_cast<size_t>(e)];
    for (int node : cell) g.connectivity.push_back(node);
    ids += cell.size();
    g.offsets.push_back(ids);
    g.types.push_back(vtk_cell_type(cell));
    g.body_id.push_back(static_cast<std::int32_t>(id));
    g.pair_id.push_back(-1);
    g.level.push_back(m.level.empty() ? 0 : m.level[static_cast<size_t>(e)]);
  }
  g.n_ids.push_back(ids);
  if (g.has.displacement) g.displacement.middleRows(p0, n) = with_zero_z(b.displacement);
  if (g.has.reaction) g.reaction.middleRows(p0, n) = with_zero_z(b.reaction);
  if (g.has.stress_node) g.stress_node.middleRows(p0, n) = stress_tensor(b.stress_node);
  if (g.has.stress_cell) g.stress_cell.middleRows(c0, c) = stress_tensor(b.stress_cell);
  if (g.has.von_mises) g.von_mises.segment(c0, c) = b.von_mises_cell;
  if (g.has.indicator) {
    if (b.indicator_cell.rows() > 0)
      g.indicator.segment(c0, c) = b.indicator_cell;
    else
      g.indicator.segment(c0, c).setConstant(nan);
  }
  g.p0 += n;
  g.c0 += c;
}

// One pair's partition: its slave polyline (lines between consecutive points, and on a closed slave edge from the
// last back to the first), the contact fields at its points and the slave body's values at those nodes (`slave`:
// null if no body has the pair's slave name).
void append_pair(Grid& g, const PairField& p, size_t k, const BodyField* slave) {
  const bool closed = slave && slave->mesh.edge_set_closed(p.slave_edge);
  const auto segments = pair_segments(p.position.rows(), closed);
  const Eigen::Index n = p.position.rows(), c = segments.rows(), p0 = g.p0, c0 = g.c0;
  g.n_points.push_back(n);
  g.n_cells.push_back(c);
  g.n_ids.push_back(2 * c);
  g.offsets.push_back(0);
  for (Eigen::Index j = 0; j < c; ++j) {
    g.connectivity.push_back(segments(j, 0));
    g.connectivity.push_back(segments(j, 1));
    g.offsets.push_back(2 * (j + 1));
    g.types.push_back(kVtkLine);
    g.body_id.push_back(-1);
    g.pair_id.push_back(static_cast<std::int32_t>(k));
    g.level.push_back(0);
  }
  const BodyField* b = slave;
  for (Eigen::Index j = 0; j < n; ++j) {
    g.points.row(p0 + j) << p.position(j, 0), p.position(j, 1), 0.0;
    const bool known = b && p.node.size() == n && p.node[j] >= 0 && p.node[j] < b->mesh.num_nodes();
    const Eigen::Index node = known ? p.node[j] : 0;
    const Eigen::RowVector3d none3 = Eigen::RowVector3d::Constant(nan);
    g.displacement.row(p0 + j) = known && g.has.displacement
                                     ? Eigen::RowVector3d(b->displacement(node, 0), b->displacement(node, 1), 0.0)
                                     : none3;
    g.reaction.row(p0 + j) =
        known && g.has.reaction ? Eigen::RowVector3d(b->reaction(node, 0), b->reaction(node, 1), 0.0) : none3;
    if (known && g.has.stress_node)
      g.stress_node.row(p0 + j) = stress_tensor(b->stress_node.row(node)).row(0);
    else
      g.stress_node.row(p0 + j).setConstant(nan);
    g.pressure[p0 + j] = p.pressure[j];
    g.gap[p0 + j] = p.normal_gap[j];
    g.active[p0 + j] = static_cast<std::int8_t>(p.active[j]);
    if (p.friction != "none" && p.tangential_traction.size() == n) {
      g.any_friction = true;
      g.tangential_traction[p0 + j] = p.tangential_traction[j];
      g.slip[p0 + j] = p.slip[j];
    }
  }
  g.stress_cell.middleRows(c0, c).setConstant(nan);
  g.von_mises.segment(c0, c).setConstant(nan);
  g.indicator.segment(c0, c).setConstant(nan);
  g.p0 += n;
  g.c0 += c;
}

// The grid into the VTKHDF group: partition counts, topology, PointData, CellData.
void write_grid(hid_t v, const Grid& g) {
  h5::write_vector(v, "NumberOfPoints", g.n_points);
  h5::write_vector(v, "NumberOfCells", g.n_cells);
  h5::write_vector(v, "NumberOfConnectivityIds", g.n_ids);
  write_matrix(v, "Points", g.points);
  h5::write_vector(v, "Connectivity", g.connectivity);
  h5::write_vector(v, "Offsets", g.offsets);
  h5::write_vector(v, "Types", g.types);

  Handle pd = h5::create_group(v, "PointData");
  if (g.has.displacement) write_matrix(pd, "displacement", g.displacement);
  if (g.has.stress_node) write_matrix(pd, "stress", g.stress_node);
  if (g.has.reaction) write_matrix(pd, "reaction", g.reaction);
  write_column(pd, "pressure", g.pressure);
  write_column(pd, "gap", g.gap);
  write_column(pd, "active", g.active);
  if (g.any_friction) {
    write_column(pd, "tangential_traction", g.tangential_traction);
    write_column(pd, "slip", g.slip);
  }
  Handle cd = h5::create_group(v, "CellData");
  if (g.has.stress_cell) write_matrix(cd, "stress", g.stress_cell);
  if (g.has.von_mises) write_column(cd, "von_mises", g.von_mises);
  if (g.has.indicator) write_column(cd, "indicator", g.indicator);
  h5::write_vector(cd, "body_id", g.body_id);
  h5::write_vector(cd, "pair_id", g.pair_id);
  h5::write_vector(cd, "level", g.level);
}

}  // namespace

void write_vtkhdf(hid_t file, const Step& last) {
  Handle v = h5::create_group(file, "VTKHDF");
  h5::write_attribute_array<std::int64_t>(v, "Version", {1, 0});
  // ParaView 5.11 compares the whole stored string: 16 bytes, no terminator counted.
  h5::write_fixed_string_attribute(v, "Type", "UnstructuredGrid");
  Grid grid = size_grid(last);
  for (size_t id = 0; id < last.bodies.size(); ++id) append_body(grid, last.bodies[id], id);
  for (size_t k = 0; k < last.pairs.size(); ++k) {
    // The slave body (by name; the last of that name), for the values at the slave nodes.
    const BodyField* slave = nullptr;
    for (const auto& b : last.bodies)
      if (b.name == last.pairs[k].slave_body) slave = &b;
    append_pair(grid, last.pairs[k], k, slave);
  }
  write_grid(v, grid);
}

}  // namespace contact::io

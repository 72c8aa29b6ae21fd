// write_vtkhdf: the final step as a VTKHDF 1.0 UnstructuredGrid (docs/results-format.md, "/VTKHDF").
//
// Partitions: every body (VTK_QUAD and VTK_TRIANGLE cells), then every contact pair (its slave polyline, VTK_LINE cells). The
// per-partition counts are NumberOf*, and Points, Connectivity, Offsets, Types and the data arrays are the
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

}  // namespace

void write_vtkhdf(hid_t file, const Step& last) {
  Handle v = h5::create_group(file, "VTKHDF");
  h5::write_attribute_array<std::int64_t>(v, "Version", {1, 0});
  // ParaView 5.11 compares the whole stored string: 16 bytes, no terminator counted.
  h5::write_fixed_string_attribute(v, "Type", "UnstructuredGrid");
  const double nan = std::numeric_limits<double>::quiet_NaN();

  std::vector<std::int64_t> n_points, n_cells, n_ids, connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::vector<std::int32_t> body_id, pair_id, level;
  Eigen::Index total_points = 0, total_cells = 0;
  bool all_displacement = true, all_stress_node = true, all_reaction = true, all_stress_cell = true,
       all_von_mises = true, any_indicator = false;
  for (const auto& b : last.bodies) {
    total_points += b.mesh.num_nodes();
    total_cells += b.mesh.num_cells();
    all_displacement = all_displacement && b.displacement.rows() > 0;
    all_stress_node = all_stress_node && b.stress_node.rows() > 0;
    all_reaction = all_reaction && b.reaction.rows() > 0;
    all_stress_cell = all_stress_cell && b.stress_cell.rows() > 0;
    all_von_mises = all_von_mises && b.von_mises_cell.rows() > 0;
    any_indicator = any_indicator || b.indicator_cell.rows() > 0;
  }
  // The slave body of every pair (by name), for the values at the slave nodes.
  std::vector<const BodyField*> slave(last.pairs.size(), nullptr);
  for (size_t k = 0; k < last.pairs.size(); ++k) {
    for (const auto& b : last.bodies)
      if (b.name == last.pairs[k].slave_body) slave[k] = &b;
    const Eigen::Index n = last.pairs[k].position.rows();
    total_points += n;
    total_cells += std::max<Eigen::Index>(n - 1, 0);
  }

  Eigen::MatrixX3d points(total_points, 3), displacement(total_points, 3), reaction(total_points, 3);
  StressTensor stress_node(total_points, 6), stress_cell(total_cells, 6);  // ParaView names these components
  Eigen::VectorXd von_mises(total_cells), indicator(total_cells);
  Eigen::VectorXd pressure = Eigen::VectorXd::Constant(total_points, nan), gap = pressure;
  // Friction (written when some pair has it): NaN off the friction pairs' points.
  Eigen::VectorXd tangential_traction = pressure, slip = pressure;
  bool any_friction = false;
  Eigen::Matrix<std::int8_t, Eigen::Dynamic, 1> active = Eigen::Matrix<std::int8_t, Eigen::Dynamic, 1>::Constant(total_points, -1);
  Eigen::Index p0 = 0, c0 = 0;
  for (size_t id = 0; id < last.bodies.size(); ++id) {
    const BodyField& b = last.bodies[id];
    const mesh::Mesh& m = b.mesh;
    const Eigen::Index n = m.num_nodes(), c = m.num_cells();
    n_points.push_back(n);
    n_cells.push_back(c);
    for (Eigen::Index i = 0; i < n; ++i)
      points.row(p0 + i) << m.nodes[static_cast<size_t>(i)].x(), m.nodes[static_cast<size_t>(i)].y(), 0.0;
    offsets.push_back(0);
    std::int64_t ids = 0;
    for (Eigen::Index e = 0; e < c; ++e) {
      const mesh::Cell& cell = m.cells[static_cast<size_t>(e)];
      for (int node : cell) connectivity.push_back(node);
      ids += cell.size();
      offsets.push_back(ids);
      types.push_back(vtk_cell_type(cell));
      body_id.push_back(static_cast<std::int32_t>(id));
      pair_id.push_back(-1);
      level.push_back(m.level.empty() ? 0 : m.level[static_cast<size_t>(e)]);
    }
    n_ids.push_back(ids);
    if (all_displacement) displacement.middleRows(p0, n) = with_zero_z(b.displacement);
    if (all_reaction) reaction.middleRows(p0, n) = with_zero_z(b.reaction);
    if (all_stress_node) stress_node.middleRows(p0, n) = stress_tensor(b.stress_node);
    if (all_stress_cell) stress_cell.middleRows(c0, c) = stress_tensor(b.stress_cell);
    if (all_von_mises) von_mises.segment(c0, c) = b.von_mises_cell;
    if (any_indicator) {
      if (b.indicator_cell.rows() > 0)
        indicator.segment(c0, c) = b.indicator_cell;
      else
        indicator.segment(c0, c).setConstant(nan);
    }
    p0 += n;
    c0 += c;
  }
  for (size_t k = 0; k < last.pairs.size(); ++k) {
    const PairField& p = last.pairs[k];
    const Eigen::Index n = p.position.rows(), c = std::max<Eigen::Index>(n - 1, 0);
    n_points.push_back(n);
    n_cells.push_back(c);
    n_ids.push_back(2 * c);
    offsets.push_back(0);
    for (Eigen::Index j = 0; j < c; ++j) {
      connectivity.push_back(j);
      connectivity.push_back(j + 1);
      offsets.push_back(2 * (j + 1));
      types.push_back(kVtkLine);
      body_id.push_back(-1);
      pair_id.push_back(static_cast<std::int32_t>(k));
      level.push_back(0);
    }
    const BodyField* b = slave[k];
    for (Eigen::Index j = 0; j < n; ++j) {
      points.row(p0 + j) << p.position(j, 0), p.position(j, 1), 0.0;
      const bool known = b && p.node.size() == n && p.node[j] >= 0 && p.node[j] < b->mesh.num_nodes();
      const Eigen::Index node = known ? p.node[j] : 0;
      const Eigen::RowVector3d none3 = Eigen::RowVector3d::Constant(nan);
      displacement.row(p0 + j) = known && all_displacement ? Eigen::RowVector3d(b->displacement(node, 0), b->displacement(node, 1), 0.0) : none3;
      reaction.row(p0 + j) = known && all_reaction ? Eigen::RowVector3d(b->reaction(node, 0), b->reaction(node, 1), 0.0) : none3;
      if (known && all_stress_node)
        stress_node.row(p0 + j) = stress_tensor(b->stress_node.row(node)).row(0);
      else
        stress_node.row(p0 + j).setConstant(nan);
      pressure[p0 + j] = p.pressure[j];
      gap[p0 + j] = p.normal_gap[j];
      active[p0 + j] = static_cast<std::int8_t>(p.active[j]);
      if (p.friction != "none" && p.tangential_traction.size() == n) {
        any_friction = true;
        tangential_traction[p0 + j] = p.tangential_traction[j];
        slip[p0 + j] = p.slip[j];
      }
    }
    stress_cell.middleRows(c0, c).setConstant(nan);
    von_mises.segment(c0, c).setConstant(nan);
    indicator.segment(c0, c).setConstant(nan);
    p0 += n;
    c0 += c;
  }
  h5::write_vector(v, "NumberOfPoints", n_points);
  h5::write_vector(v, "NumberOfCells", n_cells);
  h5::write_vector(v, "NumberOfConnectivityIds", n_ids);
  write_matrix(v, "Points", points);
  h5::write_vector(v, "Connectivity", connectivity);
  h5::write_vector(v, "Offsets", offsets);
  h5::write_vector(v, "Types", types);

  Handle pd = h5::create_group(v, "PointData");
  if (all_displacement) write_matrix(pd, "displacement", displacement);
  if (all_stress_node) write_matrix(pd, "stress", stress_node);
  if (all_reaction) write_matrix(pd, "reaction", reaction);
  write_column(pd, "pressure", pressure);
  write_column(pd, "gap", gap);
  write_column(pd, "active", active);
  if (any_friction) {
    write_column(pd, "tangential_traction", tangential_traction);
    write_column(pd, "slip", slip);
  }
  Handle cd = h5::create_group(v, "CellData");
  if (all_stress_cell) write_matrix(cd, "stress", stress_cell);
  if (all_von_mises) write_column(cd, "von_mises", von_mises);
  if (any_indicator) write_column(cd, "indicator", indicator);
  h5::write_vector(cd, "body_id", body_id);
  h5::write_vector(cd, "pair_id", pair_id);
  h5::write_vector(cd, "level", level);
}

}  // namespace contact::io

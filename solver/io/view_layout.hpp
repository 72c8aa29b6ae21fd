// Internal to solver/io: how the viewers' formats (/VTKHDF and the XDMF sidecar) lay out cells and stresses.
#pragma once

#include "contact/mesh.hpp"
#include "contact/result.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace contact::io {

inline constexpr std::uint8_t kVtkLine = 3, kVtkTriangle = 5, kVtkQuad = 9;  // VTK's cell types
inline constexpr std::int64_t kXdmfTriangle = 4, kXdmfQuadrilateral = 5;     // XDMF's Mixed topology codes

inline std::uint8_t vtk_cell_type(const mesh::Cell& cell) { return cell.is_triangle() ? kVtkTriangle : kVtkQuad; }
inline std::int64_t xdmf_cell_type(const mesh::Cell& cell) {
  return cell.is_triangle() ? kXdmfTriangle : kXdmfQuadrilateral;
}

// Stresses (sxx, syy, sxy, szz) as VTK's symmetric tensor (xx, yy, zz, xy, yz, xz), the out-of-plane shears 0.
// ParaView 5.11 reads no component names from VTKHDF 1.0 or XDMF; it names the components of a 6-component
// array XX, YY, ZZ, XY, YZ, XZ (and of a 4-component one 0, 1, 2, 3), so this layout is what names them.
using StressTensor = Eigen::Matrix<double, Eigen::Dynamic, 6>;
inline StressTensor stress_tensor(const Eigen::MatrixX4d& s) {
  StressTensor t = StressTensor::Zero(s.rows(), 6);
  t.col(0) = s.col(0);
  t.col(1) = s.col(1);
  t.col(2) = s.col(3);
  t.col(3) = s.col(2);
  return t;
}

// Whether a pair's slave edge is a closed loop (a bore, a shaft's rim): its slave body's mesh in the step (the last
// body of that name, as /VTKHDF takes the slave's values from) says so. Its polyline then has a segment more, from
// the last node back to the first.
inline bool slave_is_closed(const Step& step, const PairField& p) {
  bool closed = false;
  for (const auto& b : step.bodies)
    if (b.name == p.slave_body) closed = b.mesh.edge_set_closed(p.slave_edge);
  return closed;
}

// The slave polyline's line cells as rows (first, second) of the pair's positions: consecutive nodes, and on a
// closed slave edge the last node back to the first.
inline Eigen::Matrix<std::int64_t, Eigen::Dynamic, 2> pair_segments(Eigen::Index n, bool closed) {
  const Eigen::Index count = closed && n > 2 ? n : std::max<Eigen::Index>(n - 1, 0);
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 2> out(count, 2);
  for (Eigen::Index j = 0; j < count; ++j) out.row(j) << j, (j + 1) % n;
  return out;
}

}  // namespace contact::io

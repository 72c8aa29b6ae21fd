#include "rigid_blocks.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>

namespace contact::limit {

namespace {

using SparseRows = mortar::SparseRows;

// The resultant at the body's reference point of the nodal forces sign x (row r of M), M's columns the body's dofs.
Resultant row_resultant(const SparseRows& M, int r, double sign, const mesh::Mesh& mesh,
                        const Eigen::Vector2d& reference) {
  Resultant out = Resultant::Zero();
  for (SparseRows::InnerIterator it(M, r); it; ++it) {
    const Eigen::Index col = it.col();
    const Eigen::Vector2d d = mesh.nodes[static_cast<size_t>(col / 2)] - reference;
    const double f = sign * it.value();
    if (col % 2 == 0) {
      out[0] += f;
      out[2] -= d.y() * f;
    } else {
      out[1] += f;
      out[2] += d.x() * f;
    }
  }
  return out;
}

// The rigid motions (vx, vy, size x omega) that move none of the body's prescribed displacement components.
Eigen::MatrixXd admissible_motions(const Body& body, const Eigen::Vector2d& reference, double size) {
  Eigen::Matrix3d CtC = Eigen::Matrix3d::Zero();
  int constraints = 0;
  for (const auto& bc : body.boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(body.mesh, bc)) {
      const Eigen::Vector2d d = (body.mesh.nodes[static_cast<size_t>(node)] - reference) / size;
      if (bc.ux) {
        const Eigen::Vector3d c(1.0, 0.0, -d.y());
        CtC += c * c.transpose();
        ++constraints;
      }
      if (bc.uy) {
        const Eigen::Vector3d c(0.0, 1.0, d.x());
        CtC += c * c.transpose();
        ++constraints;
      }
    }
  }
  if (constraints == 0) return Eigen::Matrix3d::Identity();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(CtC);
  const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::MatrixXd out(3, 0);
  for (int i = 0; i < 3; ++i)
    if (eig.eigenvalues()[i] <= 1e-10 * largest) {
      out.conservativeResize(3, out.cols() + 1);
      out.col(out.cols() - 1) = eig.eigenvectors().col(i);
    }
  return out;
}

}  // namespace

RigidBlocks rigid_blocks(const ddm::ContactSystem& system) {
  RigidBlocks blocks;
  const Problem& problem = system.problem();
  for (const auto& body : problem.bodies) {
    RigidBody b;
    b.name = body.name;
    const auto& nodes = body.mesh.nodes;
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
    for (const auto& p : nodes) {
      b.reference += p;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    if (!nodes.empty()) b.reference /= static_cast<double>(nodes.size());
    b.size = nodes.empty() ? 1.0 : std::max((hi - lo).norm(), 1e-300);
    b.motions = admissible_motions(body, b.reference, b.size);
    blocks.bodies.push_back(std::move(b));
  }
  const auto& pairs = system.pairs();
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto& p = pairs[k];
    blocks.slave_of_pair.push_back(p.slave_body);
    blocks.master_of_pair.push_back(p.master_body);
    blocks.friction_of_pair.push_back(p.has_friction() ? p.friction : FrictionSpec{});
    const auto& slave_mesh = problem.bodies[static_cast<size_t>(p.slave_body)].mesh;
    const auto& master_mesh = problem.bodies[static_cast<size_t>(p.master_body)].mesh;
    const Eigen::Vector2d& cs = blocks.bodies[static_cast<size_t>(p.slave_body)].reference;
    const Eigen::Vector2d& cm = blocks.bodies[static_cast<size_t>(p.master_body)].reference;
    for (int r = 0; r < p.n_rows(); ++r) {
      if (!(p.area[r] > 0)) continue;
      JointRow row;
      row.pair = k;
      row.row = r;
      row.node = p.slave_nodes[static_cast<size_t>(p.node_of_row[r])];
      row.point = slave_mesh.nodes[static_cast<size_t>(row.node)];
      row.normal = p.normal[static_cast<size_t>(r)];
      row.tangent =
          p.has_friction() ? p.tangent[static_cast<size_t>(r)] : Eigen::Vector2d(-row.normal.y(), row.normal.x());
      row.slave_normal = row_resultant(p.Gs, r, -1.0, slave_mesh, cs);
      row.master_normal = row_resultant(p.Gm, r, 1.0, master_mesh, cm);
      if (p.has_friction()) {
        row.slave_tangential = row_resultant(p.Ts, r, -1.0, slave_mesh, cs);
        row.master_tangential = row_resultant(p.Tm, r, 1.0, master_mesh, cm);
      }
      blocks.rows.push_back(row);
    }
  }
  return blocks;
}

std::vector<Resultant> load_resultants(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                                       const fem::LoadPoint& at) {
  const size_t nb = blocks.bodies.size();
  std::vector<double> sums(3 * nb, 0.0);
  for (size_t a = 0; a < nb; ++a) {
    if (!system.runner().owns(a)) continue;  // (its owner assembles its loads)
    const Eigen::VectorXd f = system.body(a).external_load(at);
    const auto& nodes = system.problem().bodies[a].mesh.nodes;
    const Eigen::Vector2d& c = blocks.bodies[a].reference;
    for (size_t i = 0; i < nodes.size() && 2 * i + 1 < static_cast<size_t>(f.size()); ++i) {
      const Eigen::Vector2d fi(f[static_cast<Eigen::Index>(2 * i)], f[static_cast<Eigen::Index>(2 * i + 1)]);
      const Eigen::Vector2d d = nodes[i] - c;
      sums[3 * a] += fi.x();
      sums[3 * a + 1] += fi.y();
      sums[3 * a + 2] += d.x() * fi.y() - d.y() * fi.x();
    }
  }
  system.runner().sum(sums.data(), sums.size());  // (a cancel it carries is the caller's frame's to see)
  std::vector<Resultant> out(nb);
  for (size_t a = 0; a < nb; ++a) out[a] = Resultant(sums[3 * a], sums[3 * a + 1], sums[3 * a + 2]);
  return out;
}

}  // namespace contact::limit

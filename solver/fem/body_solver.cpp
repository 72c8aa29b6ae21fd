#include "body_solver.hpp"

#include "rigid_modes.hpp"

#include <chrono>
#include <sstream>
#include <stdexcept>

namespace contact::fem {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

BodySolver::BodySolver(const Body& body, const Model& model, bool factorize_now, const std::vector<int>& interface_dofs)
    : body_(body),
      elasticity_(make_elasticity(body.material, model)),
      constraints_(2 * body.mesh.num_nodes()),
      interface_dofs_(interface_dofs) {
  const auto t0 = std::chrono::steady_clock::now();
  setup_constraints();
  if (!ok()) return;
  assemble_system();
  assembly_seconds_ = seconds_since(t0);
  if (factorize_now) factorize();
}

void BodySolver::setup_constraints() {
  // Hanging nodes of a refined (1-irregular) mesh: for Q1 the value is the mean of the side's end nodes.
  for (const auto& [node, ends] : mesh::hanging_nodes(body_.mesh))
    for (int c = 0; c < 2; ++c)
      constraints_.add_line(2 * node + c, {{2 * ends.first + c, 0.5}, {2 * ends.second + c, 0.5}});
  for (const auto& bc : body_.boundary) {
    if (bc.kind != BoundaryCondition::Kind::displacement) continue;
    for (int node : body_.mesh.edge_set_nodes(bc.edge)) {
      if (bc.ux) constraints_.add_dirichlet(2 * node, *bc.ux);
      if (bc.uy) constraints_.add_dirichlet(2 * node + 1, *bc.uy);
    }
  }
  const std::string err = constraints_.close();
  if (!err.empty()) {
    error_ = "body '" + body_.name + "': " + err;
    return;
  }
  // CHOLMOD factorises a singular stiffness without complaint (a tiny pivot), so check the supports.
  std::vector<PrescribedDof> prescribed;
  for (int d = 0; d < constraints_.n_dofs(); ++d)
    if (constraints_.is_dirichlet(d)) prescribed.push_back({d / 2, d % 2});
  const auto modes = free_rigid_motions(body_.mesh, prescribed);
  if (!modes.empty()) {
    std::string list;
    for (const auto& m : modes) list += (list.empty() ? "" : ", ") + m;
    error_ = "body '" + body_.name + "' is not restrained against rigid motion (" + list +
             " free): each body needs its own displacement conditions";
  }
}

void BodySolver::assemble_system() {
  const auto& m = body_.mesh;
  const int n = 2 * m.num_nodes();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(m.num_cells()) * 64);
  f_ext_ = Eigen::VectorXd::Zero(n);
  const bool has_body_force = body_.body_force.squaredNorm() > 0;
  for (int c = 0; c < m.num_cells(); ++c) {
    const auto x = cell_coordinates(m, c);
    const Matrix8d Ke = element_stiffness(x, elasticity_);
    const auto& nodes = m.cells[static_cast<size_t>(c)];
    int dofs[8];
    for (int k = 0; k < 4; ++k) {
      dofs[2 * k] = 2 * nodes[static_cast<size_t>(k)];
      dofs[2 * k + 1] = 2 * nodes[static_cast<size_t>(k)] + 1;
    }
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j) triplets.emplace_back(dofs[i], dofs[j], Ke(i, j));
    if (has_body_force) {
      const Vector8d fe = element_body_force(x, body_.body_force, elasticity_);
      for (int i = 0; i < 8; ++i) f_ext_[dofs[i]] += fe[i];
    }
  }
  K_.resize(n, n);
  K_.setFromTriplets(triplets.begin(), triplets.end());

  // Edge tractions: constant over each straight side, so the consistent load is half the side's force at
  // each end node (exact). A normal pressure p acts as t = -p n with n the outward normal.
  for (const auto& bc : body_.boundary) {
    if (bc.kind != BoundaryCondition::Kind::traction) continue;
    auto it = m.edge_sets.find(bc.edge);
    if (it == m.edge_sets.end()) continue;
    for (const auto& e : it->second) {
      const auto nn = m.edge_nodes(e);
      const Eigen::Vector2d a = m.nodes[static_cast<size_t>(nn[0])], b = m.nodes[static_cast<size_t>(nn[1])];
      const double length = (b - a).norm();
      Eigen::Vector2d t = bc.traction;
      if (bc.normal_pressure) {
        const Eigen::Vector2d outward((b - a).y() / length, -(b - a).x() / length);
        t = -bc.pressure * outward;
      }
      for (int node : nn) f_ext_.segment<2>(2 * node) += 0.5 * length * elasticity_.thickness * t;
    }
  }

  const auto& T = constraints_.T();
  K_red_ = (T.transpose() * K_ * T).pruned();
  rhs_base_ = T.transpose() * (f_ext_ - K_ * constraints_.g());
}

std::vector<int> BodySolver::interface_unknowns_of(const std::vector<int>& dofs) const {
  // The free unknowns x_k with T(dof, k) != 0 for some interface dof (a prescribed dof depends on none).
  std::vector<char> used(static_cast<size_t>(n_free()), 0);
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = constraints_.T();
  for (int dof : dofs)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, dof); it; ++it) used[static_cast<size_t>(it.col())] = 1;
  std::vector<int> out;
  for (int k = 0; k < n_free(); ++k)
    if (used[static_cast<size_t>(k)]) out.push_back(k);
  return out;
}

void BodySolver::factorize() {
  const auto t0 = std::chrono::steady_clock::now();
  if (n_free() == 0) return;  // everything prescribed: nothing to factorise
  factor_ = std::make_unique<Cholesky>(K_red_, interface_unknowns_of(interface_dofs_));
  factorization_seconds_ = seconds_since(t0);
  if (!factor_->ok()) {
    std::ostringstream os;
    os << "body '" << body_.name << "': the stiffness matrix (" << n_free() << " unknowns) could not be factorised: "
       << factor_->error() << " (is the body restrained against rigid motion by its displacement conditions?)";
    error_ = os.str();
  }
}

const std::vector<int>& BodySolver::interface_unknowns() const {
  static const std::vector<int> none;
  return factor_ ? factor_->trailing_order() : none;
}

const Eigen::MatrixXd& BodySolver::interface_factor() const {
  static const Eigen::MatrixXd none;
  return factor_ ? factor_->trailing_factor() : none;
}

Eigen::VectorXd BodySolver::solve_reduced(const Eigen::VectorXd& reduced_rhs) const {
  if (n_free() == 0) return Eigen::VectorXd::Zero(0);
  if (!factor_) throw std::logic_error("BodySolver::solve_reduced called on a solver built without factorisation");
  return factor_->solve(reduced_rhs);
}

Eigen::MatrixXd BodySolver::solve_reduced(const Eigen::MatrixXd& reduced_rhs) const {
  if (n_free() == 0) return Eigen::MatrixXd::Zero(0, reduced_rhs.cols());
  if (!factor_) throw std::logic_error("BodySolver::solve_reduced called on a solver built without factorisation");
  return factor_->solve(reduced_rhs);
}

Eigen::VectorXd BodySolver::solve_homogeneous(const Eigen::VectorXd& load) const {
  if (n_free() == 0) return Eigen::VectorXd::Zero(n_dofs());
  const Eigen::VectorXd rhs = constraints_.T().transpose() * load;
  return constraints_.T() * solve_reduced(rhs);
}

Eigen::VectorXd BodySolver::solve(const Eigen::VectorXd& extra_load) const {
  if (n_free() == 0) return constraints_.g();
  if (!factor_) throw std::logic_error("BodySolver::solve called on a solver built without factorisation");
  Eigen::VectorXd rhs = rhs_base_;
  if (extra_load.size() > 0) rhs.noalias() += constraints_.T().transpose() * extra_load;
  return constraints_.expand(factor_->solve(rhs));
}

Eigen::VectorXd BodySolver::reactions(const Eigen::VectorXd& u, const Eigen::VectorXd& extra_load) const {
  Eigen::VectorXd r = K_ * u - f_ext_;
  if (extra_load.size() > 0) r -= extra_load;
  for (int d = 0; d < r.size(); ++d)
    if (!constraints_.is_dirichlet(d)) r[d] = 0.0;
  return r;
}

StressFields BodySolver::stresses(const Eigen::VectorXd& u) const {
  const auto& m = body_.mesh;
  StressFields s;
  s.cell = Eigen::MatrixX4d::Zero(m.num_cells(), 4);
  s.node = Eigen::MatrixX4d::Zero(m.num_nodes(), 4);
  s.von_mises_cell = Eigen::VectorXd::Zero(m.num_cells());
  Eigen::VectorXi count = Eigen::VectorXi::Zero(m.num_nodes());
  for (int c = 0; c < m.num_cells(); ++c) {
    const auto& nodes = m.cells[static_cast<size_t>(c)];
    Vector8d ue;
    for (int k = 0; k < 4; ++k) ue.segment<2>(2 * k) = u.segment<2>(2 * nodes[static_cast<size_t>(k)]);
    const auto gs = gauss_stresses(cell_coordinates(m, c), ue, elasticity_);
    const Eigen::Vector3d mean = gs.rowwise().mean();
    const double szz = elasticity_.nu_zz * (mean[0] + mean[1]);
    s.cell.row(c) << mean[0], mean[1], mean[2], szz;
    s.von_mises_cell[c] = von_mises(mean[0], mean[1], mean[2], szz);
    const auto corners = extrapolate_to_corners(gs);
    for (int k = 0; k < 4; ++k) {
      const int node = nodes[static_cast<size_t>(k)];
      s.node.row(node).head<3>() += corners.row(k);
      count[node]++;
    }
  }
  for (int n = 0; n < m.num_nodes(); ++n) {
    if (count[n] > 0) s.node.row(n).head<3>() /= count[n];
    s.node(n, 3) = elasticity_.nu_zz * (s.node(n, 0) + s.node(n, 1));
  }
  return s;
}

}  // namespace contact::fem

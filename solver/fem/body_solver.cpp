#include "body_solver.hpp"

#include "../common/background.hpp"
#include "../common/assert.hpp"

#include "element.hpp"
#include "../common/scoped_timer.hpp"
#include "../mesh/rigid_modes.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <chrono>
#include <sstream>
#include <stdexcept>

namespace contact::fem {

BodySolver::BodySolver(const Body& body, const Model& model, bool factorize_now, const std::vector<int>& interface_dofs,
                       bool allow_floating, bool local, std::function<bool()> cancelled)
    : body_(body),
      elasticity_(make_elasticity(body.material, model)),
      weight_(body.weight(model.gravity)),
      constraints_(2 * body.mesh.num_nodes()),
      interface_dofs_(interface_dofs),
      allow_floating_(allow_floating),
      factorize_(factorize_now),
      local_(local),
      cancelled_(std::move(cancelled)) {
  {
    ScopedTimer timer(assembly_seconds_);
    setup_constraints();
    if (!ok() || !local) return;
    assemble_system();
    if (!ok()) return;
    setup_history_groups();
  }
  if (factorize_now) factorize();
}

void BodySolver::stop_cancelled(const char* during) {
  was_cancelled_ = true;
  error_ = "body '" + body_.name + "': cancelled during the " + during;
}

void BodySolver::setup_constraints() {
  // Hanging nodes of a refined (1-irregular) mesh: for Q1 the value is the mean of the side's end nodes.
  for (const auto& [node, ends] : mesh::hanging_nodes(body_.mesh))
    for (int c = 0; c < 2; ++c)
      constraints_.add_line(2 * node + c, {{2 * ends.first + c, 0.5}, {2 * ends.second + c, 0.5}});
  std::vector<mesh::PrescribedDof> prescribed;
  for (const auto& bc : body_.boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(body_.mesh, bc)) {
      if (bc.ux) {
        constraints_.add_dirichlet(2 * node, *bc.ux);
        prescribed.push_back({node, 0});
      }
      if (bc.uy) {
        constraints_.add_dirichlet(2 * node + 1, *bc.uy);
        prescribed.push_back({node, 1});
      }
    }
  }
  // CHOLMOD factorises a singular stiffness without complaint (a tiny pivot), so check the supports first.
  mesh::RigidModes modes = mesh::free_rigid_modes(body_.mesh, prescribed);
  if (modes.modes.cols() > 0 && !allow_floating_) {
    std::string list;
    for (const auto& m : modes.names) list += (list.empty() ? "" : ", ") + m;
    error_ = "body '" + body_.name + "' is not restrained against rigid motion (" + list +
             " free): this method solves each body on its own, so each body needs its own displacement conditions";
    return;
  }
  if (modes.modes.cols() > 0 && factorize_) {
    // A floating body: fix as many dofs as it has free motions, chosen by QR with column pivoting among the
    // unconstrained dofs away from the contact (if there are enough), so that the motions restricted to them are
    // as well conditioned as possible; the factorisation then gives a generalised inverse of the stiffness.
    std::vector<char> avoid(static_cast<size_t>(constraints_.n_dofs()), 0);
    for (const auto& [node, c] : prescribed) avoid[static_cast<size_t>(2 * node + c)] = 1;
    for (const auto& [node, ends] : mesh::hanging_nodes(body_.mesh))
      avoid[static_cast<size_t>(2 * node)] = avoid[static_cast<size_t>(2 * node + 1)] = 1;
    // A set of candidates is good only if the free motions restricted to it have full rank: away from the
    // contact there may be enough dofs but all of one component (a brick whose top and bottom are both contact
    // edges leaves only x dofs, which see no vertical translation), so the second pass takes every dof.
    const Eigen::Index k = modes.modes.cols();
    for (int pass = 0; pass < 2 && fixing_dofs_.empty(); ++pass) {
      std::vector<int> candidates;
      std::vector<char> skip = avoid;
      if (pass == 0)
        for (int d : interface_dofs_) skip[static_cast<size_t>(d)] = 1;
      for (int d = 0; d < constraints_.n_dofs(); ++d)
        if (!skip[static_cast<size_t>(d)]) candidates.push_back(d);
      if (static_cast<Eigen::Index>(candidates.size()) < k) continue;
      Eigen::MatrixXd at(k, static_cast<Eigen::Index>(candidates.size()));
      for (size_t j = 0; j < candidates.size(); ++j)
        at.col(static_cast<Eigen::Index>(j)) = modes.modes.row(candidates[j]).transpose();
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(at);
      qr.setThreshold(1e-8);
      if (qr.rank() < k) continue;
      for (Eigen::Index i = 0; i < k; ++i)
        fixing_dofs_.push_back(candidates[static_cast<size_t>(qr.colsPermutation().indices()[i])]);
    }
    if (fixing_dofs_.empty()) {
      // Not reachable for a mesh with at least one cell (every free motion moves some unprescribed dof).
      error_ = "body '" + body_.name + "': no set of its unknowns holds its free rigid motions";
      return;
    }
    for (int dof : fixing_dofs_) constraints_.add_dirichlet(dof, 0.0);
  }
  rigid_modes_ = std::move(modes.modes);
  rigid_mode_names_ = std::move(modes.names);
  const std::string err = constraints_.close();
  if (!err.empty()) error_ = "body '" + body_.name + "': " + err;
}

void BodySolver::add_condition_load(const BoundaryCondition& bc, Eigen::VectorXd& f) const {
  const auto& m = body_.mesh;
  if (bc.kind == BoundaryCondition::Kind::force && !bc.vertex.empty()) {
    for (int node : condition_nodes(m, bc)) f.segment<2>(2 * node) += bc.force;
    return;
  }
  if (bc.kind != BoundaryCondition::Kind::traction && bc.kind != BoundaryCondition::Kind::force) return;
  auto it = m.edge_sets.find(bc.edge);
  if (it == m.edge_sets.end()) return;
  double edge_length = 0;
  for (const auto& e : it->second) {
    const auto nn = m.edge_nodes(e);
    edge_length += (m.nodes[static_cast<size_t>(nn[1])] - m.nodes[static_cast<size_t>(nn[0])]).norm();
  }
  for (const auto& e : it->second) {
    const auto nn = m.edge_nodes(e);
    const Eigen::Vector2d a = m.nodes[static_cast<size_t>(nn[0])], b = m.nodes[static_cast<size_t>(nn[1])];
    const double length = (b - a).norm();
    Eigen::Vector2d t = bc.traction;
    if (bc.kind == BoundaryCondition::Kind::force) {
      t = bc.force / (edge_length * elasticity_.thickness);
    } else if (bc.normal_pressure) {
      const Eigen::Vector2d outward((b - a).y() / length, -(b - a).x() / length);
      t = -bc.pressure * outward;
    }
    for (int node : nn) f.segment<2>(2 * node) += 0.5 * length * elasticity_.thickness * t;
  }
}

// Each condition with a history (or a live load) gets its own share of the loads: its traction or force, its prescribed
// values (the dofs it prescribes, at the value the constraints hold), and T^T (f - K g) of those, element by element
// over the cells its prescribed values touch.
void BodySolver::setup_history_groups() {
  const auto& m = body_.mesh;
  const Eigen::SparseMatrix<double, Eigen::RowMajor> T = constraints_.T();
  if ((!body_.body_force_history.empty() || body_.body_force_live) && body_.body_force.squaredNorm() > 0) {
    // The job's body force (not the weight, which follows the loading) at factor 1, cell by cell.
    LoadGroup group;
    group.history = &body_.body_force_history;
    group.live = body_.body_force_live;
    group.f_ext = Eigen::VectorXd::Zero(n_dofs());
    for (int c = 0; c < m.num_cells(); ++c) {
      const CellVector fe = cell_body_force(m, c, body_.body_force, elasticity_);
      const CellDofs dofs = cell_dofs(m.cells[static_cast<size_t>(c)]);
      for (Eigen::Index i = 0; i < dofs.size(); ++i) group.f_ext[dofs[i]] += fe[i];
    }
    group.g = Eigen::VectorXd::Zero(n_dofs());
    group.rhs = T.transpose() * group.f_ext;
    groups_.push_back(std::move(group));
  }
  for (const auto& bc : body_.boundary) {
    if (bc.history.empty() && !bc.live) continue;
    LoadGroup group;
    group.history = &bc.history;
    group.live = bc.live;
    group.f_ext = Eigen::VectorXd::Zero(n_dofs());
    add_condition_load(bc, group.f_ext);
    group.g = Eigen::VectorXd::Zero(n_dofs());
    for (int node : condition_nodes(m, bc)) {
      if (bc.ux) group.g[2 * node] = constraints_.g()[2 * node];
      if (bc.uy) group.g[2 * node + 1] = constraints_.g()[2 * node + 1];
    }
    group.rhs = T.transpose() * group.f_ext;
    if (group.g.cwiseAbs().maxCoeff() > 0)
      for (int c = 0; c < m.num_cells(); ++c) {
        const CellVector gc = cell_values(m, c, group.g);
        if (gc.cwiseAbs().maxCoeff() == 0) continue;
        const CellVector load = -(cell_stiffness(m, c, elasticity_) * gc);
        const CellDofs dofs = cell_dofs(m.cells[static_cast<size_t>(c)]);
        for (Eigen::Index i = 0; i < dofs.size(); ++i)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator ii(T, dofs[i]); ii; ++ii)
            group.rhs[ii.col()] += ii.value() * load[i];
      }
    groups_.push_back(std::move(group));
  }
}

Eigen::VectorXd BodySolver::scaled(const Eigen::VectorXd& base, Eigen::VectorXd LoadGroup::*part,
                                   const LoadPoint& at) const {
  const double factor = at.value();
  Eigen::VectorXd out = factor * base;
  for (const auto& group : groups_) {
    const double own = at.of_condition(*group.history, group.live);
    if (own != factor) out += (own - factor) * (group.*part);
  }
  return out;
}

void BodySolver::assemble_system() {
  // The reduced system T^T K T x = T^T (f - K g) is assembled directly, element by element: each element's
  // stiffness goes through the rows of T of its dofs (a free dof: itself; a prescribed one: nothing, its value
  // moves to the right-hand side; a hanging node: its two masters). No matrix of all dofs is stored, and the
  // sparsity pattern is built first so that the values are summed in place (no triplet list): the memory of the
  // assembly is that of the reduced matrix.
  const auto& m = body_.mesh;
  const int n = 2 * m.num_nodes(), nf = n_free();
  const Eigen::SparseMatrix<double, Eigen::RowMajor> T = constraints_.T();
  const Eigen::VectorXd& g = constraints_.g();
  f_ext_ = Eigen::VectorXd::Zero(n);
  // The body forces at factor 1: the job's body_force and the body's weight under gravity.
  const Eigen::Vector2d body_force = body_.body_force + weight_;
  const bool has_body_force = body_force.squaredNorm() > 0;

  // Edge tractions: constant over each straight side, so the consistent load is half the side's force at
  // each end node (exact). A normal pressure p acts as t = -p n with n the outward normal. A total force on an
  // edge is the uniform traction force / (length x thickness); at a vertex it is a point load.
  for (const auto& bc : body_.boundary) add_condition_load(bc, f_ext_);

  // Pattern: the free unknowns each element couples, column by column.
  std::vector<std::vector<int>> columns(static_cast<size_t>(nf));
  std::vector<int> unknowns;
  for (int c = 0; c < m.num_cells(); ++c) {
    unknowns.clear();
    for (int d : cell_dofs(m.cells[static_cast<size_t>(c)]))
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(T, d); it; ++it)
        unknowns.push_back(static_cast<int>(it.col()));
    for (int k : unknowns)
      columns[static_cast<size_t>(k)].insert(columns[static_cast<size_t>(k)].end(), unknowns.begin(), unknowns.end());
  }
  std::vector<int> outer(static_cast<size_t>(nf) + 1, 0), inner;
  for (int k = 0; k < nf; ++k) {
    auto& col = columns[static_cast<size_t>(k)];
    std::sort(col.begin(), col.end());
    col.erase(std::unique(col.begin(), col.end()), col.end());
    outer[static_cast<size_t>(k) + 1] = outer[static_cast<size_t>(k)] + static_cast<int>(col.size());
  }
  inner.reserve(static_cast<size_t>(outer.back()));
  for (auto& col : columns) {
    inner.insert(inner.end(), col.begin(), col.end());
    std::vector<int>().swap(col);
  }
  std::vector<double> values(inner.size(), 0.0);
  auto entry = [&](int row, int col) -> double& {
    const auto first = inner.begin() + outer[static_cast<size_t>(col)],
               last = inner.begin() + outer[static_cast<size_t>(col) + 1];
    return values[static_cast<size_t>(std::lower_bound(first, last, row) - inner.begin())];
  };

  // Values and the right-hand side.
  rhs_base_ = T.transpose() * f_ext_;       // T^T f of the tractions; each element adds T^T (f_e - K_e g_e)
  constexpr int kCellsBetweenPolls = 8192;  // ~10 ms of assembly
  for (int c = 0; c < m.num_cells(); ++c) {
    if (cancelled_ && c % kCellsBetweenPolls == 0 && cancelled_()) return stop_cancelled("assembly");
    const CellMatrix Ke = cell_stiffness(m, c, elasticity_);
    const CellDofs dofs = cell_dofs(m.cells[static_cast<size_t>(c)]);
    const Eigen::Index nd = dofs.size();
    CellVector fe = CellVector::Zero(nd);
    if (has_body_force) {
      fe = cell_body_force(m, c, body_force, elasticity_);
      for (Eigen::Index i = 0; i < nd; ++i) f_ext_[dofs[i]] += fe[i];
    }
    const CellVector load = fe - Ke * cell_values(m, c, g);  // this element's share of f - K g
    for (Eigen::Index i = 0; i < nd; ++i)
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator ii(T, dofs[i]); ii; ++ii) {
        const int ki = static_cast<int>(ii.col());
        rhs_base_[ki] += ii.value() * load[i];
        for (Eigen::Index j = 0; j < nd; ++j)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator jj(T, dofs[j]); jj; ++jj)
            entry(static_cast<int>(jj.col()), ki) += ii.value() * jj.value() * Ke(j, i);
      }
  }
  K_red_ = std::make_shared<const Eigen::SparseMatrix<double>>(Eigen::Map<const Eigen::SparseMatrix<double>>(
      nf, nf, static_cast<Eigen::Index>(values.size()), outer.data(), inner.data(), values.data()));
}

Eigen::SparseMatrix<double> BodySolver::stiffness() const {
  const auto& m = body_.mesh;
  const int n = 2 * m.num_nodes();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(m.num_cells()) * 64);
  for (int c = 0; c < m.num_cells(); ++c) {
    const CellMatrix Ke = cell_stiffness(m, c, elasticity_);
    const CellDofs dofs = cell_dofs(m.cells[static_cast<size_t>(c)]);
    for (Eigen::Index i = 0; i < dofs.size(); ++i)
      for (Eigen::Index j = 0; j < dofs.size(); ++j) triplets.emplace_back(dofs[i], dofs[j], Ke(i, j));
  }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(triplets.begin(), triplets.end());
  return K;
}

std::vector<int> BodySolver::interface_unknowns_of(const std::vector<int>& dofs) const {
  // The free unknowns x_k with T(dof, k) != 0 for some interface dof (a prescribed dof depends on none).
  std::vector<char> used(static_cast<size_t>(n_free()), 0);
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = constraints_.T();
  for (int dof : dofs)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, dof); it; ++it)
      used[static_cast<size_t>(it.col())] = 1;
  std::vector<int> out;
  for (int k = 0; k < n_free(); ++k)
    if (used[static_cast<size_t>(k)]) out.push_back(k);
  return out;
}

void BodySolver::factorize() {
  if (n_free() == 0) return;  // everything prescribed: nothing to factorise
  {
    ScopedTimer timer(factorization_seconds_);
    // With a cancel to watch, on a thread of its own that owns its inputs (common/background.hpp).
    std::function<std::unique_ptr<Cholesky>()> work = [K = K_red_, last = interface_unknowns_of(interface_dofs_)] {
      return std::make_unique<Cholesky>(*K, last);
    };
    factor_ = run_unless_cancelled(std::move(work), cancelled_);
  }
  if (!factor_) return stop_cancelled("factorisation");
  if (!factor_->ok()) {
    std::ostringstream os;
    os << "body '" << body_.name << "': the stiffness matrix (" << n_free()
       << " unknowns) could not be factorised: " << factor_->error();
    if (rigid_modes_.cols() == 0)
      os << " (is the body restrained against rigid motion by its displacement conditions?)";
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

Eigen::VectorXd BodySolver::reduced_rhs(const LoadPoint& at) const { return scaled(rhs_base_, &LoadGroup::rhs, at); }

Eigen::VectorXd BodySolver::external_load(const LoadPoint& at) const { return scaled(f_ext_, &LoadGroup::f_ext, at); }

Eigen::VectorXd BodySolver::prescribed(const LoadPoint& at) const {
  return scaled(constraints_.g(), &LoadGroup::g, at);
}

Eigen::VectorXd BodySolver::expand(const Eigen::VectorXd& x, const LoadPoint& at) const {
  return constraints_.T() * x + prescribed(at);
}

Eigen::VectorXd BodySolver::solve_homogeneous(const Eigen::VectorXd& load) const {
  if (n_free() == 0) return Eigen::VectorXd::Zero(n_dofs());
  const Eigen::VectorXd rhs = constraints_.T().transpose() * load;
  return constraints_.T() * solve_reduced(rhs);
}

Eigen::VectorXd BodySolver::solve(const Eigen::VectorXd& extra_load, const LoadPoint& at) const {
  if (extra_load.size() > 0) CONTACT_ASSERT_SIZE(extra_load.size(), n_dofs(), "a body's extra load");
  if (n_free() == 0) return prescribed(at);
  if (!factor_)
    throw std::logic_error(local_ ? "BodySolver::solve called on a solver built without factorisation"
                                  : "body '" + body_.name + "' is solved by another process");
  Eigen::VectorXd rhs = reduced_rhs(at);
  if (extra_load.size() > 0) rhs.noalias() += constraints_.T().transpose() * extra_load;
  return expand(factor_->solve(rhs), at);
}

Eigen::VectorXd BodySolver::reactions(const Eigen::VectorXd& u, const Eigen::VectorXd& extra_load,
                                      const LoadPoint& at) const {
  // K u - f_ext - extra at the prescribed dofs, element by element. A hanging node's residual belongs to its
  // masters (its equation is theirs, through u_h = sum w_j u_j): where a master is prescribed, its share is part
  // of the support's reaction, so every element counts and the hanging nodes' residuals are moved to their
  // masters. (Counting only the elements with a prescribed dof left the refined two-cylinder example's supports
  // 2-4 % off the contact force they balance.)
  const auto& m = body_.mesh;
  Eigen::VectorXd r = Eigen::VectorXd::Zero(2 * m.num_nodes());
  for (int c = 0; c < m.num_cells(); ++c) {
    const CellDofs dofs = cell_dofs(m.cells[static_cast<size_t>(c)]);
    const CellVector fe = cell_stiffness(m, c, elasticity_) * cell_values(m, c, u);
    for (Eigen::Index i = 0; i < dofs.size(); ++i) r[dofs[i]] += fe[i];
  }
  r -= external_load(at);
  if (extra_load.size() > 0) r -= extra_load;
  r = constraints_.condense_to_masters(r);
  for (int d = 0; d < r.size(); ++d)
    if (!constraints_.is_dirichlet(d)) r[d] = 0.0;
  for (int d : fixing_dofs_) r[d] = 0.0;  // not a support
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
    const PointStresses ps = cell_point_stresses(m, c, cell_values(m, c, u), elasticity_);
    const Eigen::Vector3d mean = ps.rowwise().mean();
    const double szz = elasticity_.nu_zz * (mean[0] + mean[1]);
    s.cell.row(c) << mean[0], mean[1], mean[2], szz;
    s.von_mises_cell[c] = von_mises(mean[0], mean[1], mean[2], szz);
    const NodeStresses corners = cell_node_stresses(nodes, ps);
    for (int k = 0; k < nodes.size(); ++k) {
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

// All linear constraints of one body's mesh in one object (deal.II's AffineConstraints idea): prescribed
// displacement components now, hanging-node constraints after refinement. Each constrained dof is
//   u_i = sum_j w_ij u_j + b_i     (Dirichlet: no entries, b_i the prescribed value)
// and close() turns the set into the map from free unknowns x to all dofs, u = T x + g, so that the
// reduced stiffness T^T K T stays symmetric positive definite and is factorised once.
#pragma once

#include <Eigen/SparseCore>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace contact::fem {

class Constraints {
 public:
  explicit Constraints(int n_dofs = 0) : n_dofs_(n_dofs) {}

  // Prescribes dof = value (a later call for the same dof replaces the earlier one).
  void add_dirichlet(int dof, double value);
  // dof = sum entries (dof_j, w_j) + inhomogeneity. The masters may themselves be constrained (chains are
  // resolved by close(); cycles are an error).
  void add_line(int dof, std::vector<std::pair<int, double>> entries, double inhomogeneity = 0.0);

  // Resolves chains and builds T and g. Returns an error message (empty on success).
  std::string close();

  int n_dofs() const { return n_dofs_; }
  int n_free() const { return n_free_; }
  bool is_constrained(int dof) const { return lines_.count(dof) != 0; }
  bool is_dirichlet(int dof) const;
  const Eigen::SparseMatrix<double>& T() const { return T_; }       // n_dofs x n_free
  const Eigen::VectorXd& g() const { return g_; }                   // n_dofs
  const std::vector<int>& free_dofs() const { return free_dofs_; }  // free unknown k -> dof

  Eigen::VectorXd expand(const Eigen::VectorXd& x) const { return T_ * x + g_; }

  // A nodal force vector (n_dofs) with every linearly constrained dof's value (a hanging node's) moved to its
  // masters with the line's weights, through chains, and zero there: the forces the masters carry. Dirichlet
  // dofs keep what they have and what reaches them (a support's reaction includes its hanging neighbours').
  Eigen::VectorXd condense_to_masters(const Eigen::VectorXd& f) const;

 private:
  struct Line {
    std::vector<std::pair<int, double>> entries;
    double inhomogeneity = 0.0;
  };
  int n_dofs_ = 0;
  int n_free_ = 0;
  std::map<int, Line> lines_;
  Eigen::SparseMatrix<double> T_;
  Eigen::VectorXd g_;
  std::vector<int> free_dofs_;
};

}  // namespace contact::fem

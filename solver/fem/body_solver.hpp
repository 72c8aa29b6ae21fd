// One elastic body on a fixed mesh: assembly, constraints, one CHOLMOD factorisation, many solves.
//
// The DDM changes only the right-hand side between iterations (paper eq. (16)), so the reduced stiffness
// T^T K T is factorised once per mesh and every iteration costs one forward/back substitution per body.
// Owns copies of nothing but its matrices: the Body and Model passed in must outlive the solver.
#pragma once

#include "contact/problem.hpp"
#include "cholesky.hpp"
#include "constraints.hpp"
#include "elasticity.hpp"
#include "load_point.hpp"

#include <Eigen/SparseCore>

#include <functional>
#include <memory>
#include <string>

namespace contact::fem {

struct StressFields {
  Eigen::MatrixX4d cell;  // mean over the quadrature points: sxx, syy, sxy, szz (a triangle's: its constant)
  Eigen::MatrixX4d node;  // the cells' values carried to their nodes (element.hpp), averaged over the cells at a node
  Eigen::VectorXd von_mises_cell;
};

class BodySolver {
 public:
  // Sets up constraints, assembles and factorises. Never throws for a singular or indefinite matrix: check
  // ok() and error().
  // With factorize = false only assembly is done (for methods that factorise a coupled system instead).
  // interface_dofs (full dof numbers, e.g. the contact edges' dofs that contact forces act on): the free unknowns
  // they depend on are ordered last in the factorisation, so that interface_factor() holds the Cholesky factor of
  // the Schur complement on them (fem/cholesky.hpp).
  // allow_floating: a body that its own displacement conditions do not restrain is accepted (it is held by its
  // contacts): its rigid modes R are fixed at a few well-chosen dofs for the factorisation, so every solve gives
  // a particular solution K^+ f (zero at those dofs; meaningful when R^T f = 0), and the caller adds R alpha.
  // local = false: the body belongs to another process (MPI ranks, parallel/task_runner.hpp): only its constraints and
  // rigid modes are set up (the same as on its owner), nothing is assembled or factorised, and the owner's outcome
  // arrives through adopt_outcome(). Its solves throw; its stresses and reactions need no factorisation and work.
  // cancelled (optional): polled during the assembly and while the factorisation runs on a thread of its own
  // (common/background.hpp); once it says so the constructor returns within a poll, the body not ok() and
  // was_cancelled() true, and an unfinished factorisation ends in the background.
  BodySolver(const Body& body, const Model& model, bool factorize = true, const std::vector<int>& interface_dofs = {},
             bool allow_floating = false, bool local = true, std::function<bool()> cancelled = {});

  bool local() const { return local_; }
  // A body of another process: its owner's error (if any) and factorisation seconds.
  void adopt_outcome(const std::string& error, double factorization_seconds) {
    error_ = error;
    factorization_seconds_ = factorization_seconds;
  }

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  bool was_cancelled() const { return was_cancelled_; }

  int n_dofs() const { return constraints_.n_dofs(); }
  int n_free() const { return constraints_.n_free(); }

  // Displacements (all dofs) under the body's own loads at load point `at` plus `extra_load` (full dof vector, e.g.
  // contact forces). One back-substitution; safe to call concurrently for different BodySolver objects.
  Eigen::VectorXd solve(const Eigen::VectorXd& extra_load, const LoadPoint& at = {}) const;
  // The same for a load that is already reduced (T^T f) and without the body's own loads/prescribed values:
  // the linear response x = K_red^{-1} b. Used by the interface methods.
  Eigen::VectorXd solve_reduced(const Eigen::VectorXd& reduced_rhs) const;
  // The same for several right-hand sides at once (columns): one blocked back-substitution.
  Eigen::MatrixXd solve_reduced(const Eigen::MatrixXd& reduced_rhs) const;
  // Linear response to a load only (no body loads, prescribed values 0): T K_red^{-1} T^T f.
  Eigen::VectorXd solve_homogeneous(const Eigen::VectorXd& load) const;

  // Support reactions: the force the supports exert on the body, K u - f_ext - extra_load (f_ext at `at`), kept at
  // the prescribed (Dirichlet) dofs and zero elsewhere.
  Eigen::VectorXd reactions(const Eigen::VectorXd& u, const Eigen::VectorXd& extra_load,
                            const LoadPoint& at = {}) const;

  StressFields stresses(const Eigen::VectorXd& u) const;

  const Constraints& constraints() const { return constraints_; }
  // The stiffness of all dofs, assembled on demand (not kept: the solver needs only the reduced one).
  Eigen::SparseMatrix<double> stiffness() const;
  const Eigen::SparseMatrix<double>& reduced_stiffness() const { return *K_red_; }
  // The body's own loads and prescribed values at a load point (fem/load_point.hpp; the default: the end of the
  // first step, the loading at 1): the factorisation does not change, only these. The body keeps no load state: the
  // point is the run's (ddm/run_state.hpp).
  bool has_histories() const { return !groups_.empty(); }
  // The factor a condition of this body is at: its own history's where it has one, else the loading's.
  double condition_factor(const BoundaryCondition& bc, const LoadPoint& at) const {
    return at.of_condition(bc.history, bc.live);
  }
  Eigen::VectorXd external_load(const LoadPoint& at = {}) const;  // all dofs: tractions, forces, body force
  Eigen::VectorXd reduced_rhs(const LoadPoint& at = {}) const;    // T^T (f_ext - K g)
  Eigen::VectorXd prescribed(const LoadPoint& at = {}) const;     // g: the prescribed values (0 elsewhere), all dofs
  Eigen::VectorXd expand(const Eigen::VectorXd& x, const LoadPoint& at = {}) const;  // T x + g
  const Elasticity& elasticity() const { return elasticity_; }
  // The free unknowns behind the interface dofs, in the order of the rows of interface_factor(), and the
  // lower-triangular L_ZZ with L_ZZ L_ZZ^T = the Schur complement of the reduced stiffness on them (both empty
  // without interface dofs). The full dofs the constructor was given are kept to tell whether a new interface
  // needs a new factorisation.
  const std::vector<int>& interface_unknowns() const;
  const Eigen::MatrixXd& interface_factor() const;
  const std::vector<int>& interface_dofs() const { return interface_dofs_; }
  // Floating bodies: the free rigid motions (all dofs x k; empty for a restrained body), their names ("translation
  // in y", ...), and the dofs fixed to factorise (not supports: they carry no reaction; none without a
  // factorisation, when the coupled system is factorised instead).
  bool floating() const { return rigid_modes_.cols() > 0; }
  const Eigen::MatrixXd& rigid_modes() const { return rigid_modes_; }
  const std::vector<std::string>& rigid_mode_names() const { return rigid_mode_names_; }
  const std::vector<int>& fixing_dofs() const { return fixing_dofs_; }
  // Numbers stored in the Cholesky factor (its memory is 8 bytes each, plus the integer pattern).
  double factor_entries() const { return factor_ ? factor_->factor_entries() : 0.0; }
  double factorization_seconds() const { return factorization_seconds_; }
  double assembly_seconds() const { return assembly_seconds_; }

 private:
  // One per load with a factor of its own (a history, a condition's or the body force's, or a live load of a
  // collapse analysis): its share of the loads (f_ext), of the prescribed values (g) and of the reduced right-hand
  // side (T^T (f - K g)), at factor 1.
  struct LoadGroup {
    const std::vector<double>* history = nullptr;
    bool live = false;
    Eigen::VectorXd f_ext, g, rhs;
  };
  void setup_constraints();
  void assemble_system();
  void stop_cancelled(const char* during);
  void factorize();
  void add_condition_load(const BoundaryCondition& bc, Eigen::VectorXd& f) const;
  void setup_history_groups();
  // The loading's factor at `at` times the base (every condition at factor 1) plus, per condition with a history,
  // its own factor's difference times its part.
  Eigen::VectorXd scaled(const Eigen::VectorXd& base, Eigen::VectorXd LoadGroup::*part, const LoadPoint& at) const;
  std::vector<int> interface_unknowns_of(const std::vector<int>& dofs) const;

  const Body& body_;
  Elasticity elasticity_;
  Eigen::Vector2d weight_;  // density x gravity, per volume (follows the loading)
  Constraints constraints_;
  // Shared with a factorisation that a cancel may leave running after this object is gone.
  std::shared_ptr<const Eigen::SparseMatrix<double>> K_red_ = std::make_shared<const Eigen::SparseMatrix<double>>();
  Eigen::VectorXd f_ext_, rhs_base_;
  std::vector<int> interface_dofs_;
  bool allow_floating_ = false, factorize_ = true, local_ = true, was_cancelled_ = false;
  std::function<bool()> cancelled_;
  std::vector<LoadGroup> groups_;
  Eigen::MatrixXd rigid_modes_;
  std::vector<std::string> rigid_mode_names_;
  std::vector<int> fixing_dofs_;
  std::unique_ptr<Cholesky> factor_;
  std::string error_;
  double factorization_seconds_ = 0.0, assembly_seconds_ = 0.0;
};

}  // namespace contact::fem

// SMALBE with inner MPRGP on the interface problem (feti.hpp describes the method): the engine of the iterative
// interface solver, for the box l <= z <= u with G z = e. Frictionless contact gives l = 0 and no u on the normal
// rows; friction adds the tangential rows with -b <= q <= b (feti_friction.cpp). Private to ddm/interface/.
//
// One object serves a sequence of solves on the same interface problem with different bounds (Coulomb's outer
// iteration on the slip bounds): the coarse space, the norm estimate, the equality multipliers nu and the
// penalty rho carry over from one solve to the next, so each starts where the last ended.
#pragma once

#include "../../linalg/mprgp.hpp"
#include "coarse_space.hpp"
#include "interface_solver.hpp"

#include <functional>

namespace contact::ddm {

class Smalbe {
 public:
  Smalbe(const InterfaceQp& qp, const InterfaceSolverSettings& settings, InterfaceSolveContext& context);

  // Whether every floating body's equilibrium rows are independent; otherwise `out` says which are not.
  bool prepare(linalg::QpSolution& out);

  struct Bounds {
    Eigen::VectorXd lower, upper;  // on z (upper: +inf where absent; lower = upper fixes a row)
  };
  // The complementarity a report shows for (z, h); unset: the normal rows' min(z, c h) with c = 1 / diag(H).
  using Measure = std::function<double(const Eigen::VectorXd& z, const Eigen::VectorXd& h)>;
  struct Solve {
    double tolerance = 1e-12;  // the projected gradient and the equilibrium, relative (feti.hpp)
    bool report = true;        // call context.on_step after every outer iteration
    Measure measure;
  };
  // Solves over the box from z0 (or from the last solve's answer, or zero); `out` gets z, h, alpha, the outer
  // iterations (steps) and converged or why not; its inner_iterations keep counting over the solves.
  void solve(const Bounds& bounds, const Eigen::VectorXd* z0, const Solve& how, linalg::QpSolution& out);

  // y = H x (one product with F, summed over the processes); true: cancelled.
  bool apply_H(const Eigen::VectorXd& x, Eigen::VectorXd& y);
  // The diagonal of H (every process holds it whole).
  const Eigen::VectorXd& diagonal() const { return diagonal_; }
  const CoarseSpace& coarse() const { return coarse_; }
  double seconds_F() const { return seconds_F_; }
  double seconds_coarse() const { return seconds_coarse_; }
  long face_steps() const { return face_steps_; }  // products with F in CG on settled faces (in inner_iterations)
  // MPRGP's own steps over the object's life, by kind: where the products go when they grow with the mesh (on a
  // 16 x 16 wall from 4 to 16 cells a brick the face CG stayed flat and these grew 3x; docs/friction-solvers.md).
  const linalg::MprgpResult& mprgp_steps() const { return steps_; }
  const linalg::MprgpResult& last_inner() const { return last_inner_; }

 private:
  bool apply_A(const Eigen::VectorXd& x, Eigen::VectorXd& y);
  bool precondition(const Eigen::VectorXd& r, Eigen::VectorXd& y);
  void setup();
  bool finish(const Eigen::VectorXd& x, const Bounds& bounds, linalg::QpSolution& out);
  enum class FaceSolve { solved, not_solved, cancelled };
  // The equality-constrained QP on x's face, by CG to the projected gradient `target`; solved: x is the answer to
  // `tolerance` (smalbe_face.cpp).
  FaceSolve solve_face(Eigen::VectorXd& x, double tolerance, double target, linalg::QpSolution& out);
  bool report(int step, const Solve& how, linalg::QpSolution& out);  // true: stop (the step callback asked)
  bool update_multipliers(const Eigen::VectorXd& x, const linalg::MprgpResult& r, int outer, double& M,
                          double& previous_L, std::vector<double>& violation);
  bool stagnating(const std::vector<double>& violation) const;
  std::vector<Eigen::Index> unbalanced_rows(const Eigen::VectorXd& z) const;
  void scales(double& scale_g) const;

  const InterfaceQp& qp_;
  const InterfaceSolverSettings& s_;
  InterfaceSolveContext& ctx_;
  CoarseSpace coarse_;
  const Eigen::Index m_;
  Eigen::VectorXd z_I_, Pc_, diagonal_, nu_, last_z_;
  Eigen::VectorXd range_;  // Q x of the last x apply_A took
  double rho_ = 1.0, norm_A_ = 1.0, norm_PHP_ = 1.0;
  long face_steps_ = 0;                            // products with H in solve_face, over the object's life
  linalg::MprgpResult steps_;                      // its cg_steps, expansion_steps, proportioning_steps summed
  double seconds_F_ = 0.0, seconds_coarse_ = 0.0;  // products with F (and their sum over processes), P and Q
  bool ready_ = false;
  linalg::BoundQp bound_;
  linalg::MprgpResult last_inner_;
  std::vector<char> previous_active_;
};

}  // namespace contact::ddm

// SMALBE's last stretch on a settled face (smalbe.hpp). Once MPRGP's inner solves stop changing the face (only
// conjugate-gradient steps), what is left is an equality-constrained QP on the free rows F:
//
//   min 1/2 z^T H z + g^T z   over z_F,   z fixed at its bounds off F,   G z = e,
//
// which projected conjugate gradients solve directly, in ker G_F with the face's own projector
// P_F = I - G_F^T (G_F G_F^T)^-1 G_F (Dostal 2009, section 2.5: CG for equality constraints). SMALBE reaches the
// same point by multiplier updates whose pace is set by how well the face holds the bodies: on a brick wall the
// face holds each brick through a few nodes, and each update took the equilibrium violation down about 2x at
// 64 x 64 bricks against 5x at 8 x 8 (then rho raised 10x and a CG solve of 30-50 steps, every Coulomb outer
// iteration). The face's projector enforces G z = e exactly at every step instead.
//
// The answer is SMALBE's when it is one: feasible on the face and with the multipliers' signs right on the bounds
// (the projected gradient of h + G^T alpha below the tolerance). Otherwise the face was not the answer's, and
// SMALBE goes on from where it was (the products spent are counted). A face that leaves a body's rigid motion free
// (G_F G_F^T singular: a brick whose contact rows all sit on their bounds) is left to SMALBE too.
#include "smalbe.hpp"

#include <cmath>

#include "../../common/scoped_timer.hpp"

namespace contact::ddm {

Smalbe::FaceSolve Smalbe::solve_face(Eigen::VectorXd& x_inout, double tolerance, double target,
                                     linalg::QpSolution& out) {
  const bool upper = bound_.upper.size() == m_;
  std::vector<char> free(static_cast<size_t>(m_));
  Eigen::VectorXd mask(m_), x = x_inout;
  for (Eigen::Index j = 0; j < m_; ++j) {
    const bool at_lower = x[j] <= bound_.lower[j], at_upper = upper && x[j] >= bound_.upper[j];
    if (at_lower) x[j] = bound_.lower[j];
    if (at_upper) x[j] = bound_.upper[j];
    free[static_cast<size_t>(j)] = !at_lower && !at_upper;
    mask[j] = free[static_cast<size_t>(j)] ? 1.0 : 0.0;
  }
  std::unique_ptr<CoarseSpace::Face> face;
  {
    ScopedTimer timer(seconds_coarse_);
    face = coarse_.face(free);
  }
  if (!face->ok()) return FaceSolve::not_solved;
  // A start on G z = e: the least change on the face (G x = 0 with z = x + z_I).
  x -= face->correction(coarse_.G() * x);
  const auto projected = [&](const Eigen::VectorXd& v) {
    ScopedTimer timer(seconds_coarse_);
    return face->project(mask.cwiseProduct(v));
  };
  const auto precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& y) {
    if (!bound_.precondition) {
      y = r;
      return false;
    }
    Eigen::VectorXd Mr;
    const bool stop = qp_.problem.apply_preconditioner(r, Mr, ctx_.frame.runner()) || ctx_.frame.stop_requested();
    y = projected(Mr);
    return stop;
  };
  const auto product = [&](const Eigen::VectorXd& v, Eigen::VectorXd& Hv) {
    ++out.inner_iterations;
    ++face_steps_;
    return apply_H(v, Hv);
  };
  Eigen::VectorXd h, Hd, y;
  if (product(x + z_I_, h)) return FaceSolve::cancelled;
  h += qp_.g;
  Eigen::VectorXd r = -projected(h);
  if (precondition(r, y)) return FaceSolve::cancelled;
  Eigen::VectorXd d = y;
  double ry = r.dot(y);
  // The face's QP is well posed whether or not the face is the answer's (a wrong one shows at the end, by a bound
  // crossed or a multiplier of the wrong sign); CG on it converges like FETI's, in 10-25 products on the walls'
  // settled faces, and the budget only bounds what a face far from its answer can cost.
  const long budget = std::min<long>(300, s_.max_iterations - out.inner_iterations);
  for (long k = 0; r.norm() > target; ++k) {
    if (k >= budget) return FaceSolve::not_solved;
    if (product(d, Hd)) return FaceSolve::cancelled;
    const double dHd = d.dot(Hd);
    if (!(dHd > 0)) return FaceSolve::not_solved;
    const double alpha = ry / dHd;
    x += alpha * d;
    h += alpha * Hd;
    r -= alpha * projected(Hd);
    if (precondition(r, y)) return FaceSolve::cancelled;
    const double ry_next = r.dot(y);
    d = y + (ry_next / ry) * d;
    ry = ry_next;
  }
  // The answer's only if feasible on the face and the bounds' multipliers have their signs (MPRGP's chopped
  // gradient of h + G^T alpha: a lower bound pushed down, an upper one pushed up).
  for (Eigen::Index j = 0; j < m_; ++j)
    if (free[static_cast<size_t>(j)] && (x[j] < bound_.lower[j] || (upper && x[j] > bound_.upper[j])))
      return FaceSolve::not_solved;
  Eigen::VectorXd alpha, gradient = h;
  if (!coarse_.empty()) {
    ScopedTimer timer(seconds_coarse_);
    alpha = face->multipliers(mask.cwiseProduct(h));
    gradient += coarse_.G().transpose() * alpha;
  }
  double chopped = 0.0;
  for (Eigen::Index j = 0; j < m_; ++j) {
    if (free[static_cast<size_t>(j)] || (upper && bound_.lower[j] == bound_.upper[j])) continue;
    const double g = x[j] <= bound_.lower[j] ? std::min(gradient[j], 0.0) : std::max(gradient[j], 0.0);
    chopped += g * g;
  }
  if (std::sqrt(chopped + r.squaredNorm()) > tolerance) return FaceSolve::not_solved;
  // SMALBE's multipliers nu stay its own. Set from the face's (nu = Q h + G^T alpha, which makes SMALBE's gradient
  // P h + nu equal h + G^T alpha) they start the next solve nearer, but a brick that the next bounds leave
  // indeterminate (its contact rows all on their bounds) then keeps a multiplier along its free motion that the
  // updates do not correct: the last load step of Masonry.WhereABricksSlipIsIndeterminate... took 281,270 MPRGP
  // iterations instead of 4,261, and gave that brick another of its admissible motions.
  x_inout = x;
  return FaceSolve::solved;
}

}  // namespace contact::ddm

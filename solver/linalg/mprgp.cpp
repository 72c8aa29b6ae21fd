#include "mprgp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace contact::linalg {

namespace {

// The free gradient phi (g on the free set, 0 elsewhere).
Eigen::VectorXd free_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Eigen::VectorXd& l) {
  return (x.array() > l.array()).select(g, 0.0);
}

// The chopped gradient beta (min(g, 0) on the bound, 0 elsewhere).
Eigen::VectorXd chopped_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Eigen::VectorXd& l) {
  return (x.array() > l.array()).select(Eigen::VectorXd::Zero(x.size()), g.cwiseMin(0.0));
}

// The largest step alpha with x - alpha p >= l.
double feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& p, const Eigen::VectorXd& l) {
  double alpha = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (p[i] > 0) alpha = std::min(alpha, (x[i] - l[i]) / p[i]);
  return alpha;
}

class Mprgp {
 public:
  Mprgp(const BoundQp& qp, const MprgpSettings& settings, MprgpResult& out) : qp_(qp), s_(settings), out_(out) {}

  // The free gradient, preconditioned in the face when there is a preconditioner.
  bool search_direction(Eigen::VectorXd& z) {
    const Eigen::VectorXd phi = free_gradient(out_.x, out_.gradient, qp_.lower);
    if (!qp_.precondition) {
      z = phi;
      return false;
    }
    Eigen::VectorXd y;
    const bool stop = qp_.precondition(phi, y);
    z = (out_.x.array() > qp_.lower.array()).select(y, 0.0);
    return stop;
  }

  bool product(const Eigen::VectorXd& v, Eigen::VectorXd& Av) {
    ++out_.iterations;
    return qp_.apply(v, Av);
  }

  // Restart: the gradient from scratch and the direction from the free gradient.
  bool restart() {
    Eigen::VectorXd Ax;
    if (product(out_.x, Ax)) return true;
    out_.gradient = Ax - qp_.b;
    return search_direction(p_);
  }

  // A CG step in the face, or the expansion step when the CG step leaves the feasible set.
  bool cg_or_expansion() {
    Eigen::VectorXd Ap;
    if (product(p_, Ap)) return true;
    const double pAp = p_.dot(Ap);
    if (!(pAp > 0)) return restart();  // p = 0 to round-off: nothing to do in this face
    const double alpha_cg = out_.gradient.dot(p_) / pAp;
    const double alpha_f = feasible_step(out_.x, p_, qp_.lower);
    if (alpha_cg <= alpha_f) {
      ++out_.cg_steps;
      out_.x -= alpha_cg * p_;
      out_.gradient -= alpha_cg * Ap;
      Eigen::VectorXd z;
      if (search_direction(z)) return true;
      const double beta = z.dot(Ap) / pAp;
      p_ = z - beta * p_;
      return false;
    }
    ++out_.expansion_steps;
    out_.x -= alpha_f * p_;
    out_.gradient -= alpha_f * Ap;
    const Eigen::VectorXd phi = free_gradient(out_.x, out_.gradient, qp_.lower);
    out_.x = (out_.x - s_.alpha_bar * phi).cwiseMax(qp_.lower);
    return restart();
  }

  // A step along the chopped gradient, which frees the constraints it points away from.
  bool proportioning(const Eigen::VectorXd& beta) {
    Eigen::VectorXd Ad;
    if (product(beta, Ad)) return true;
    ++out_.proportioning_steps;
    const double dAd = beta.dot(Ad);
    if (!(dAd > 0)) return restart();
    const double alpha = out_.gradient.dot(beta) / dAd;
    out_.x -= alpha * beta;
    out_.gradient -= alpha * Ad;
    return search_direction(p_);
  }

  // Whether the chopped gradient is small against the reduced free gradient phi~ = min((x - l) / alpha_bar, phi).
  bool proportional(const Eigen::VectorXd& beta) const {
    const Eigen::VectorXd phi = free_gradient(out_.x, out_.gradient, qp_.lower);
    const Eigen::VectorXd reduced =
        (phi.array() > 0).select(((out_.x - qp_.lower) / s_.alpha_bar).cwiseMin(phi), phi);
    return beta.squaredNorm() <= s_.gamma * s_.gamma * reduced.dot(phi);
  }

 private:
  const BoundQp& qp_;
  const MprgpSettings& s_;
  MprgpResult& out_;
  Eigen::VectorXd p_;
};

}  // namespace

Eigen::VectorXd projected_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Eigen::VectorXd& lower) {
  return free_gradient(x, g, lower) + chopped_gradient(x, g, lower);
}

MprgpResult solve_mprgp(const BoundQp& qp, const Eigen::VectorXd& x0, const MprgpSettings& settings,
                        const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&, double)>& done) {
  MprgpResult out;
  out.x = x0.cwiseMax(qp.lower);
  Mprgp method(qp, settings, out);
  if (method.restart()) {
    out.cancelled = true;
    return out;
  }
  for (;;) {
    out.projected_gradient = projected_gradient(out.x, out.gradient, qp.lower).norm();
    if (done(out.x, out.gradient, out.projected_gradient)) {
      out.converged = true;
      return out;
    }
    if (out.iterations >= settings.max_iterations) return out;
    const Eigen::VectorXd beta = chopped_gradient(out.x, out.gradient, qp.lower);
    const bool stop = method.proportional(beta) ? method.cg_or_expansion() : method.proportioning(beta);
    if (stop) {
      out.cancelled = true;
      return out;
    }
  }
}

double estimate_norm(const std::function<bool(const Eigen::VectorXd&, Eigen::VectorXd&)>& apply, Eigen::Index n,
                     int iterations) {
  if (n == 0) return 0.0;
  // A fixed, non-symmetric start so that no eigenvector is missed by symmetry.
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = 1.0 + 0.5 * std::sin(0.7 * static_cast<double>(i) + 0.3);
  v.normalize();
  double lambda = 0.0;
  Eigen::VectorXd Av;
  for (int k = 0; k < iterations; ++k) {
    if (apply(v, Av)) break;
    lambda = v.dot(Av);
    const double norm = Av.norm();
    if (!(norm > 0)) break;
    v = Av / norm;
  }
  return lambda;
}

}  // namespace contact::linalg

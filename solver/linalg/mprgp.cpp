#include "mprgp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace contact::linalg {

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

// The box l <= x <= u; u is +inf where the problem has no upper bound (the one-sided QP of frictionless contact).
struct Box {
  const Eigen::VectorXd& l;
  Eigen::VectorXd u;
  Box(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper)
      : l(lower), u(upper.size() == lower.size() ? upper : Eigen::VectorXd::Constant(lower.size(), infinity)) {}
  auto is_free(const Eigen::VectorXd& x) const { return x.array() > l.array() && x.array() < u.array(); }
  Eigen::VectorXd project(const Eigen::VectorXd& x) const { return x.cwiseMax(l).cwiseMin(u); }
};

// The free gradient phi (g on the free set, 0 elsewhere).
Eigen::VectorXd free_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Box& box) {
  return box.is_free(x).select(g, 0.0);
}

// The chopped gradient beta: min(g, 0) at the lower bound, max(g, 0) at the upper one (the components that point
// into the box), 0 on the free set and on a fixed unknown (l = u: it cannot move either way).
Eigen::VectorXd chopped_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Box& box) {
  Eigen::VectorXd beta = Eigen::VectorXd::Zero(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const bool lower = x[i] <= box.l[i], upper = x[i] >= box.u[i];
    if (lower && !upper) beta[i] = std::min(g[i], 0.0);
    if (upper && !lower) beta[i] = std::max(g[i], 0.0);
  }
  return beta;
}

// The largest step alpha with l <= x - alpha p <= u, and the unknown that blocks it (-1: none).
double feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& p, const Box& box, Eigen::Index& blocking) {
  double alpha = infinity;
  blocking = -1;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double a = p[i] > 0 ? (x[i] - box.l[i]) / p[i] : p[i] < 0 ? (x[i] - box.u[i]) / p[i] : infinity;
    if (a < alpha) {
      alpha = a;
      blocking = i;
    }
  }
  return alpha;
}

class Mprgp {
 public:
  Mprgp(const BoundQp& qp, const MprgpSettings& settings, MprgpResult& out)
      : qp_(qp), s_(settings), out_(out), box_(qp.lower, qp.upper) {}

  const Box& box() const { return box_; }

  // The free gradient, preconditioned in the face when there is a preconditioner.
  bool search_direction(Eigen::VectorXd& z) {
    const Eigen::VectorXd phi = free_gradient(out_.x, out_.gradient, box_);
    if (!qp_.precondition) {
      z = phi;
      return false;
    }
    Eigen::VectorXd y;
    const bool stop = qp_.precondition(phi, y);
    z = box_.is_free(out_.x).select(y, 0.0);
    return stop;
  }

  // A v, and L v in Lv_ when the problem tracks an image.
  bool product(const Eigen::VectorXd& v, Eigen::VectorXd& Av) {
    ++out_.report.iterations;
    const bool stop = qp_.apply(v, Av);
    if (qp_.image) Lv_ = qp_.image();
    return stop;
  }

  // x -= alpha d and g -= alpha A d, with L x alongside (Lv_ = L d, from d's product).
  void step(double alpha, const Eigen::VectorXd& d, const Eigen::VectorXd& Ad) {
    out_.x -= alpha * d;
    out_.gradient -= alpha * Ad;
    if (qp_.image) out_.image -= alpha * Lv_;
  }

  // Restart: the gradient (and the image) from scratch and the direction from the free gradient.
  bool restart() {
    Eigen::VectorXd Ax;
    if (product(out_.x, Ax)) return true;
    out_.gradient = Ax - qp_.b;
    if (qp_.image) out_.image = Lv_;
    return search_direction(p_);
  }

  // A CG step in the face, or the expansion step when the CG step leaves the feasible set.
  bool cg_or_expansion() {
    Eigen::VectorXd Ap;
    if (product(p_, Ap)) return true;
    const double pAp = p_.dot(Ap);
    if (!(pAp > 0)) return restart();  // p = 0 to round-off: nothing to do in this face
    const double alpha_cg = out_.gradient.dot(p_) / pAp;
    Eigen::Index blocking = -1;
    const double alpha_f = feasible_step(out_.x, p_, box_, blocking);
    if (alpha_cg <= alpha_f) {
      ++out_.cg_steps;
      step(alpha_cg, p_, Ap);
      Eigen::VectorXd z;
      if (search_direction(z)) return true;
      const double beta = z.dot(Ap) / pAp;
      p_ = z - beta * p_;
      return false;
    }
    ++out_.expansion_steps;
    out_.x -= alpha_f * p_;
    out_.gradient -= alpha_f * Ap;  // x's image: from the restart's product below
    // The blocking unknown lands on its bound exactly (the step's rounding could leave it a hair inside, free).
    out_.x[blocking] = p_[blocking] > 0 ? qp_.lower[blocking] : box_.u[blocking];
    const Eigen::VectorXd phi = free_gradient(out_.x, out_.gradient, box_);
    out_.x = box_.project(out_.x - s_.alpha_bar * phi);
    return restart();
  }

  // A step along the chopped gradient, which frees the constraints it points away from; with upper bounds no
  // longer than the box allows (an unknown leaving one bound may reach the other, where it stops exactly).
  bool proportioning(const Eigen::VectorXd& beta) {
    Eigen::VectorXd Ad;
    if (product(beta, Ad)) return true;
    ++out_.proportioning_steps;
    const double dAd = beta.dot(Ad);
    if (!(dAd > 0)) return restart();
    Eigen::Index blocking = -1;
    const double alpha_f = feasible_step(out_.x, beta, box_, blocking);
    const double alpha = std::min(out_.gradient.dot(beta) / dAd, alpha_f);
    step(alpha, beta, Ad);
    // (The blocking unknown set exactly on its bound moves it by rounding only: the image stays as it is.)
    if (alpha == alpha_f) out_.x[blocking] = beta[blocking] > 0 ? qp_.lower[blocking] : box_.u[blocking];
    return search_direction(p_);
  }

  // Whether the chopped gradient is small against the reduced free gradient phi~: min((x - l) / alpha_bar, phi)
  // where phi > 0 (a step of alpha_bar would reach l), max((x - u) / alpha_bar, phi) where phi < 0.
  bool proportional(const Eigen::VectorXd& beta) const {
    const Eigen::VectorXd phi = free_gradient(out_.x, out_.gradient, box_);
    const Eigen::VectorXd reduced = (phi.array() > 0)
                                        .select(((out_.x - qp_.lower) / s_.alpha_bar).cwiseMin(phi),
                                                ((out_.x - box_.u) / s_.alpha_bar).cwiseMax(phi));
    return beta.squaredNorm() <= s_.gamma * s_.gamma * reduced.dot(phi);
  }

 private:
  const BoundQp& qp_;
  const MprgpSettings& s_;
  MprgpResult& out_;
  const Box box_;
  Eigen::VectorXd p_;
  Eigen::VectorXd Lv_;  // the image of the vector of the last product
};

}  // namespace

Eigen::VectorXd projected_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Eigen::VectorXd& lower,
                                   const Eigen::VectorXd& upper) {
  const Box box(lower, upper);
  return free_gradient(x, g, box) + chopped_gradient(x, g, box);
}

MprgpResult solve_mprgp(const BoundQp& qp, const Eigen::VectorXd& x0, const MprgpSettings& settings,
                        const std::function<bool(const MprgpResult& state)>& done) {
  MprgpResult out;
  Mprgp method(qp, settings, out);
  out.x = method.box().project(x0);
  if (method.restart()) {
    out.report.stop = SolveStop::cancelled;
    return out;
  }
  for (;;) {
    const Box& box = method.box();
    out.report.measure = (free_gradient(out.x, out.gradient, box) + chopped_gradient(out.x, out.gradient, box)).norm();
    if (done(out)) {
      out.report.stop = SolveStop::converged;
      return out;
    }
    if (out.report.iterations >= settings.max_iterations) return out;
    const Eigen::VectorXd beta = chopped_gradient(out.x, out.gradient, box);
    const bool stop = method.proportional(beta) ? method.cg_or_expansion() : method.proportioning(beta);
    if (stop) {
      out.report.stop = SolveStop::cancelled;
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

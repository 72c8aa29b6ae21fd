#include "monolithic_friction.hpp"

#include "../linalg/anderson.hpp"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <cmath>
#include <limits>

namespace contact::ddm::monolithic {

namespace {

constexpr double kProximal = 1e-8;    // of each unknown's own stiffness: the proximal term (minimise)
constexpr double kSufficient = 1e-4;  // Armijo's constant
constexpr int kMaxBacktracks = 40;
constexpr int kMaxNewton = 100;  // Newton steps of one minimisation (a piecewise quadratic: a few)
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// What each row is: a normal row, a friction row's tangential row (its index in `rows`), or a tangential row no body
// can move (a symmetry line: q = 0, no term).
struct RowKinds {
  std::vector<int> friction;  // per row: -1 normal, -2 fixed, else the friction row
  explicit RowKinds(Eigen::Index m, const std::vector<char>& mask, const std::vector<linalg::FrictionRow>& rows)
      : friction(static_cast<size_t>(m), -1) {
    for (Eigen::Index r = 0; r < m; ++r)
      if (mask[static_cast<size_t>(r)]) friction[static_cast<size_t>(r)] = -2;
    for (size_t t = 0; t < rows.size(); ++t) friction[static_cast<size_t>(rows[t].tangential)] = static_cast<int>(t);
  }
};

// L at fixed multipliers and bounds, and what its gradient and Newton matrix need.
class Lagrangian {
 public:
  Lagrangian(const Stacked& s, const RowKinds& kinds, const Eigen::VectorXd& rho, const Eigen::VectorXd& lambda,
             const Eigen::VectorXd& bound)
      : s_(s), kinds_(kinds), rho_(rho), lambda_(lambda), bound_(bound) {}

  struct Point {
    Eigen::VectorXd h, mu;       // the rows' gaps and slips; the envelope's multipliers mu*
    std::vector<char> interior;  // rows whose mu* lies inside C (they add rho B_r^T B_r to the Newton matrix)
    double value = 0.0;
  };

  Point at(const Eigen::VectorXd& x) const {
    Point p;
    p.h = s_.g0 + s_.B * x;
    const Eigen::Index m = p.h.size();
    p.mu = Eigen::VectorXd::Zero(m);
    p.interior.assign(static_cast<size_t>(m), 0);
    double terms = 0.0;
    for (Eigen::Index r = 0; r < m; ++r) {
      const int kind = kinds_.friction[static_cast<size_t>(r)];
      if (kind == -2) continue;
      const double trial = lambda_[r] - rho_[r] * p.h[r];
      double mu;
      if (kind == -1) {
        mu = std::max(0.0, trial);
        p.interior[static_cast<size_t>(r)] = trial > 0;
      } else {
        const double b = bound_[kind];
        mu = std::clamp(trial, -b, b);
        p.interior[static_cast<size_t>(r)] = std::abs(trial) < b;
      }
      p.mu[r] = mu;
      terms += -mu * p.h[r] - (mu - lambda_[r]) * (mu - lambda_[r]) / (2 * rho_[r]);
    }
    p.value = 0.5 * x.dot(s_.K * x) - s_.b.dot(x) + terms;
    return p;
  }

  Eigen::VectorXd gradient(const Eigen::VectorXd& x, const Point& p) const {
    return s_.K * x - s_.b - s_.B.transpose() * p.mu;
  }

  // The size of the forces in the gradient (the loads and the contact forces), for its rounding floor.
  double force_scale(const Point& p) const {
    return s_.b.norm() + Eigen::VectorXd(s_.B.transpose() * p.mu).norm() + 1e-300;
  }

  SpMat newton_matrix(const Point& p) const {
    Eigen::VectorXd w(p.h.size());
    for (Eigen::Index r = 0; r < w.size(); ++r) w[r] = p.interior[static_cast<size_t>(r)] ? rho_[r] : 0.0;
    return s_.K + SpMat(s_.B.transpose() * w.asDiagonal() * s_.B);
  }

 private:
  const Stacked& s_;
  const RowKinds& kinds_;
  const Eigen::VectorXd &rho_, &lambda_, &bound_;
};

// The Newton matrices' Cholesky factor. Their pattern is K's and B^T B's whichever rows are inside C (the rows
// outside enter with weight 0, kept as stored zeros), so CHOLMOD's ordering and symbolic analysis are made once per
// solve and each step only factorises numerically.
class NewtonFactor {
 public:
  NewtonFactor() { factor_.cholmod().print = 0; }
  // H^-1 g (empty when H could not be factorised). H compressed.
  Eigen::VectorXd solve(const SpMat& H, const Eigen::VectorXd& g) {
    const std::vector<int> outer(H.outerIndexPtr(), H.outerIndexPtr() + H.outerSize() + 1);
    const std::vector<int> inner(H.innerIndexPtr(), H.innerIndexPtr() + H.nonZeros());
    if (outer != outer_ || inner != inner_) {  // a new pattern (Eigen may drop a zero): analysed again
      factor_.analyzePattern(H);
      outer_ = outer;
      inner_ = inner;
    }
    factor_.factorize(H);
    if (factor_.info() != Eigen::Success) return {};
    return factor_.solve(g);
  }

 private:
  Eigen::CholmodDecomposition<SpMat, Eigen::Lower> factor_;
  std::vector<int> outer_, inner_;
};

// x <- argmin L(x) + 1/2 (x - x_k)^T T (x - x_k), x_k the update's start, by Newton steps with the Armijo line
// search. The proximal term T (kProximal of each unknown's own stiffness) keeps every Newton matrix positive
// definite: along a brick that slides at both its joints L has no curvature (and, until the joints around it
// engage, a slope), and the step there is the slope over T, a finite move per update, where a bare Newton step would
// be unbounded. At the multipliers' fixed point x = x_k, so the answer is L's own (the proximal method of
// multipliers, Rockafellar 1976).
enum class Minimised { yes, singular, cancelled };
Minimised minimise(const Lagrangian& L, const Eigen::VectorXd& proximal, NewtonFactor& factor,
                   const std::function<bool()>& cancelled, Eigen::VectorXd& x, int& steps) {
  const Eigen::VectorXd centre = x;
  const auto value = [&](const Lagrangian::Point& p, const Eigen::VectorXd& y) {
    const Eigen::VectorXd d = y - centre;
    return p.value + 0.5 * d.dot(proximal.cwiseProduct(d));
  };
  Lagrangian::Point p = L.at(x);
  for (int k = 0; k < kMaxNewton; ++k) {
    const Eigen::VectorXd g = L.gradient(x, p) + proximal.cwiseProduct(x - centre);
    if (g.norm() <= 1e-15 * L.force_scale(p)) return Minimised::yes;  // at the minimum to rounding
    if (cancelled && cancelled()) return Minimised::cancelled;
    SpMat H = L.newton_matrix(p) + SpMat(proximal.asDiagonal());
    H.makeCompressed();
    const Eigen::VectorXd d = -factor.solve(H, g);
    ++steps;
    if (d.size() != g.size() || !d.allFinite()) return Minimised::singular;
    const double slope = g.dot(d);
    if (slope >= 0) return Minimised::yes;  // no descent left: at the minimum to rounding
    const double v0 = value(p, x);
    double alpha = 1.0;
    Eigen::VectorXd y = x + d;
    Lagrangian::Point q = L.at(y);
    const Lagrangian::Point full = q;
    int b = 0;
    for (; b < kMaxBacktracks && value(q, y) > v0 + kSufficient * alpha * slope; ++b) {
      alpha *= 0.5;
      y = x + alpha * d;
      q = L.at(y);
    }
    if (b == kMaxBacktracks) {
      // No step verifies a decrease: near the minimum L's changes are below its rounding. The full step if it
      // lowers the gradient, else x is the minimum to rounding.
      const Eigen::VectorXd g_full = L.gradient(x + d, full) + proximal.cwiseProduct(x + d - centre);
      if (g_full.norm() >= g.norm()) return Minimised::yes;
      alpha = 1.0;
      y = x + d;
      q = full;
    }
    // A full step that kept every row's side lands on the piece's minimum (the function is quadratic there).
    const bool same_piece = alpha == 1.0 && q.interior == p.interior;
    x = std::move(y);
    p = std::move(q);
    if (same_piece) return Minimised::yes;
  }
  return Minimised::yes;  // still descending after kMaxNewton steps: the update makes progress all the same
}

}  // namespace

AlmOutcome solve_by_augmented_lagrangian(const Stacked& s, const std::vector<char>& mask, const Eigen::VectorXd& c,
                                         const Eigen::VectorXd& x0, const Eigen::VectorXd& lambda0,
                                         const AlmSettings& settings, const AlmCallback& after_update,
                                         const AlmConfirm& confirm, const std::function<bool()>& cancelled) {
  const Eigen::Index n = s.b.size(), m = s.g0.size(), nf = static_cast<Eigen::Index>(s.friction.size());
  const RowKinds kinds(m, mask, s.friction);
  const Eigen::VectorXd rho = settings.boost * c;
  const Eigen::VectorXd proximal = kProximal * s.K.diagonal().cwiseAbs();
  AlmOutcome out;
  out.x = x0.size() == n ? x0 : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
  Eigen::VectorXd lambda = lambda0.size() == m ? lambda0 : Eigen::VectorXd(Eigen::VectorXd::Zero(m));
  // The slip bounds: Coulomb's mu z from the multipliers (Tresca's own), or +inf (tied) where there are none yet.
  const auto bounds_of = [&](const Eigen::VectorXd& l, bool tied) {
    Eigen::VectorXd b(nf);
    for (Eigen::Index t = 0; t < nf; ++t) {
      const auto& row = s.friction[static_cast<size_t>(t)];
      b[t] = tied ? kInfinity : row.coulomb ? row.mu * std::max(0.0, l[row.normal]) : row.bound;
    }
    return b;
  };
  bool tied = lambda0.size() != m;
  Eigen::VectorXd bound = bounds_of(lambda, tied);
  linalg::NonnegativeAnderson mixing(5);
  NewtonFactor factor;
  double inner_tolerance = 1e-3;  // the first bounds are wrong by far more than any finer Tresca answer would fix
  while (out.updates < settings.max_updates) {
    // Tresca at `bound`: multiplier updates until they settle to the inner tolerance (a convex problem: they do).
    bool settled = false;
    double last_change = kInfinity;
    while (!settled && out.updates < settings.max_updates) {
      Eigen::VectorXd x = out.x;
      const Lagrangian L(s, kinds, rho, lambda, bound);
      const Minimised minimised = minimise(L, proximal, factor, cancelled, x, out.newton_steps);
      if (minimised == Minimised::cancelled) {
        out.cancelled = true;
        return out;
      }
      if (minimised == Minimised::singular) {
        out.failure = "its Newton matrix could not be factorised";
        return out;
      }
      const Lagrangian::Point p = L.at(x);
      const double change = (p.mu - lambda).norm() / std::max(p.mu.norm(), 1e-300);
      out.x = std::move(x);
      out.lambda = p.mu;
      out.h = p.h;
      ++out.updates;
      lambda = out.lambda;
      out.complementarity = linalg::friction_complementarity(out.lambda, out.h, c, s.friction, mask);
      if (after_update && after_update(out.updates, out.x, out.lambda, out.h, out.complementarity)) {
        out.cancelled = true;
        return out;
      }
      // Settled to the tolerance, or no longer settling: bounds a rounding's worth off those of a brick that slides
      // at both its joints hold it in no equilibrium, and its multipliers drift by a constant step per update.
      settled = change <= inner_tolerance || change > 0.5 * last_change;
      last_change = change;
    }
    if (!settled) break;
    if (out.complementarity <= settings.tolerance) {
      out.converged = true;
      return out;
    }
    if (confirm && out.complementarity <= settings.confirm_below && confirm(out)) {
      out.converged = out.confirmed = true;
      return out;
    }
    // Coulomb: the bounds from the normal multipliers, and the next Tresca solve to a hundredth of their change.
    const Eigen::VectorXd next = bounds_of(lambda, false);
    const double moved = tied ? 1.0 : (next - bound).norm() / std::max(next.norm(), 1e-300);
    // Anderson-mixed as the FETI solver's bounds (ddm/interface/feti_friction.cpp): where the stick and slip sets
    // no longer change z(b) is affine and the mixing converges like a Krylov method, the plain update by a constant
    // factor (here about 0.7 per outer iteration, with a tail of hundreds where one node flips).
    bound = tied ? next : mixing.next(next, next - bound);
    tied = false;
    inner_tolerance = std::clamp(0.01 * moved, 0.1 * settings.tolerance, 1e-3);
  }
  out.failure = "the multipliers did not settle within " + std::to_string(settings.max_updates) + " updates";
  return out;
}

}  // namespace contact::ddm::monolithic

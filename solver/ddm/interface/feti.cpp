#include "feti.hpp"

#include "../../common/scoped_timer.hpp"

#include "../../linalg/mprgp.hpp"
#include "coarse_space.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace contact::ddm {

namespace {

using linalg::ActiveSetResult;

class Smalbe {
 public:
  Smalbe(const InterfaceQp& qp, const InterfaceSolverSettings& settings, InterfaceSolveContext& context)
      : qp_(qp), s_(settings), ctx_(context), coarse_(qp.problem, qp.equilibrium), m_(qp.problem.size()) {}

  ActiveSetResult run(const Eigen::VectorXd* z0);

 private:
  bool apply_H(const Eigen::VectorXd& x, Eigen::VectorXd& y);
  bool apply_A(const Eigen::VectorXd& x, Eigen::VectorXd& y);
  bool precondition(const Eigen::VectorXd& r, Eigen::VectorXd& y);
  void setup();
  // The pressures, rigid amplitudes and gaps of the current iterate, as the direct solver would report them.
  bool finish(const Eigen::VectorXd& x, ActiveSetResult& out);
  bool report(int step, ActiveSetResult& out);
  bool stagnating(const std::vector<double>& violation) const;
  std::vector<Eigen::Index> unbalanced_rows(const Eigen::VectorXd& z) const;

  const InterfaceQp& qp_;
  const InterfaceSolverSettings& s_;
  InterfaceSolveContext& ctx_;
  CoarseSpace coarse_;
  const Eigen::Index m_;
  Eigen::VectorXd z_I_, Pc_, diagonal_;
  double rho_ = 1.0, norm_A_ = 1.0, norm_PHP_ = 1.0;
  double seconds_F_ = 0.0, seconds_coarse_ = 0.0;  // products with F (and their sum over processes), P and Q
  linalg::BoundQp bound_;
  std::vector<char> previous_active_;
};

bool Smalbe::apply_H(const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  bool stop = false;
  {
    ScopedTimer timer(seconds_F_);  // the per-iteration costs docs/parallel.md's model is built from
    stop = qp_.problem.apply(x, y, ctx_.runner);
  }
  if (qp_.penalty.size() == m_) y += qp_.penalty.cwiseProduct(x);
  // One process: the token directly; several: only the agreed answer of the sum, the same on every process.
  if (!ctx_.runner.distributed()) stop = stop || ctx_.cancel.cancelled();
  return stop;
}

bool Smalbe::apply_A(const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  Eigen::VectorXd Px, HPx;
  {
    ScopedTimer timer(seconds_coarse_);
    Px = coarse_.project(x);
  }
  const bool stop = apply_H(Px, HPx);
  ScopedTimer timer(seconds_coarse_);
  y = coarse_.project(HPx) + rho_ * (x - Px);
  return stop;
}

bool Smalbe::precondition(const Eigen::VectorXd& r, Eigen::VectorXd& y) {
  const Eigen::VectorXd Pr = coarse_.project(r);
  Eigen::VectorXd Mr;
  bool stop = qp_.problem.apply_preconditioner(Pr, Mr, ctx_.runner);
  if (!ctx_.runner.distributed()) stop = stop || ctx_.cancel.cancelled();
  y = coarse_.project(Mr) + (r - Pr) / rho_;
  return stop;
}

void Smalbe::setup() {
  z_I_ = coarse_.particular();
  Eigen::VectorXd Hz;
  apply_H(z_I_, Hz);
  Pc_ = coarse_.project(Hz + qp_.g);
  // ||A|| = max(||P H P||, rho) with rho = ||P H P||: Dostal's choice, which keeps A's condition that of P H P.
  const double norm_PHP = linalg::estimate_norm(
      [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
        const Eigen::VectorXd Px = coarse_.project(x);
        Eigen::VectorXd HPx;
        const bool stop = apply_H(Px, HPx);
        y = coarse_.project(HPx);
        return stop;
      },
      m_);
  rho_ = norm_PHP > 0 ? norm_PHP : 1.0;
  norm_A_ = norm_PHP_ = rho_;
  diagonal_ = qp_.problem.diagonal();
  if (qp_.penalty.size() == m_) diagonal_ += qp_.penalty;
  bound_.apply = [this](const Eigen::VectorXd& x, Eigen::VectorXd& y) { return apply_A(x, y); };
  if (s_.preconditioner != InterfacePreconditioner::none)
    bound_.precondition = [this](const Eigen::VectorXd& r, Eigen::VectorXd& y) { return precondition(r, y); };
  bound_.lower = -z_I_;
}

bool Smalbe::finish(const Eigen::VectorXd& x, ActiveSetResult& out) {
  out.z = (x + z_I_).cwiseMax(0.0);
  Eigen::VectorXd Hz;
  const bool stop = apply_H(out.z, Hz);
  out.h = qp_.g + Hz;
  out.alpha = Eigen::VectorXd::Zero(coarse_.rows());
  if (!coarse_.empty()) {
    std::vector<char> active(static_cast<size_t>(m_));
    for (Eigen::Index j = 0; j < m_; ++j) active[static_cast<size_t>(j)] = out.z[j] > 0;
    out.alpha = coarse_.multipliers(out.h, active);
    if (out.alpha.size() != coarse_.rows()) {
      out.unrestrained = coarse_.unheld_by(active);
      if (out.unrestrained.empty())
        for (Eigen::Index i = 0; i < coarse_.rows(); ++i) out.unrestrained.push_back(i);
      out.alpha = Eigen::VectorXd::Zero(coarse_.rows());
    }
    out.h += coarse_.G().transpose() * out.alpha;
  }
  return stop;
}

bool Smalbe::report(int step, ActiveSetResult& out) {
  linalg::ActiveSetStep r;
  r.step = step;
  std::vector<char> active(static_cast<size_t>(m_));
  Eigen::VectorXd C(m_);
  for (Eigen::Index j = 0; j < m_; ++j) {
    active[static_cast<size_t>(j)] = out.z[j] > 0;
    r.active += active[static_cast<size_t>(j)];
    if (!previous_active_.empty()) r.changes += active[static_cast<size_t>(j)] != previous_active_[static_cast<size_t>(j)];
    C[j] = out.z[j] - std::max(0.0, out.z[j] - out.h[j] / diagonal_[j]);
  }
  if (previous_active_.empty()) r.changes = r.active;
  previous_active_ = std::move(active);
  r.complementarity = C.norm() / std::max(out.z.norm(), 1e-300);
  out.steps = step;
  return ctx_.on_step(out.z, out.h, r);
}

// The equality violation has stopped falling over the last outer iterations while the multipliers grow: no
// non-negative pressures balance some floating body (its loads pull it off its contacts).
bool Smalbe::stagnating(const std::vector<double>& violation) const {
  const size_t k = violation.size();
  return k >= 8 && violation[k - 1] > 0.5 * violation[k - 4] && rho_ >= 1e6 * norm_PHP_;
}

// The rows of the floating bodies whose equilibrium G_b z = e_b is violated by more than a thousandth of the
// largest violation: the bodies that their contacts do not hold.
std::vector<Eigen::Index> Smalbe::unbalanced_rows(const Eigen::VectorXd& z) const {
  const Eigen::VectorXd residual = coarse_.G() * z - coarse_.e();
  const double largest = residual.cwiseAbs().maxCoeff();
  std::vector<Eigen::Index> out;
  for (const auto& f : qp_.problem.floating())
    if (residual.segment(f.offset, f.count).cwiseAbs().maxCoeff() > 1e-3 * largest)
      for (Eigen::Index i = 0; i < f.count; ++i) out.push_back(f.offset + i);
  return out;
}

ActiveSetResult Smalbe::run(const Eigen::VectorXd* z0) {
  ActiveSetResult out;
  if (!coarse_.ok()) {
    out.unrestrained = coarse_.unheld();
    out.message = "the contact nodes cannot hold every floating body";
    return out;
  }
  setup();
  // The gradient's scale: the free response's penetration (where the contact acts), not its open gaps, which can
  // be orders of magnitude larger on a curved surface and would make the tolerance meaningless.
  const double penetration = Pc_.cwiseMin(0.0).norm();
  const double scale_g = penetration > 0 ? penetration : std::max(Pc_.norm(), 1e-300);
  const double eta = 0.1 * scale_g;
  const double norm_PHP = norm_PHP_;
  double M = norm_A_;
  Eigen::VectorXd x = z0 && z0->size() == m_ ? Eigen::VectorXd(*z0 - z_I_) : Eigen::VectorXd::Zero(m_);
  Eigen::VectorXd nu = Eigen::VectorXd::Zero(m_);
  double previous_L = -std::numeric_limits<double>::infinity();
  std::vector<double> violation;
  linalg::MprgpSettings inner;
  const int max_outer = std::max(1, ctx_.max_steps);
  for (int outer = 1; outer <= max_outer; ++outer) {
    inner.alpha_bar = 1.9 / (1.05 * norm_A_);  // the power method underestimates ||A|| a little
    bound_.b = -(Pc_ + nu);
    inner.max_iterations = std::max<long>(1, s_.max_iterations - out.inner_iterations);
    bool global = false;
    const auto done = [&](const Eigen::VectorXd& xi, const Eigen::VectorXd&, double norm_gp) {
      const double feasibility = coarse_.range_part(xi).norm();
      const double z_scale = std::max((xi + z_I_).norm(), 1e-300);
      if (norm_gp <= s_.tolerance * scale_g && feasibility <= s_.tolerance * z_scale) return global = true;
      return norm_gp <= std::max(std::min(M * feasibility, eta), 0.1 * s_.tolerance * scale_g);
    };
    const linalg::MprgpResult r = linalg::solve_mprgp(bound_, x, inner, done);
    out.inner_iterations += r.iterations;
    x = r.x;
    const bool stop = finish(x, out) || r.cancelled;
    if (stop || !report(outer, out)) {
      out.cancelled = true;
      out.message = "cancelled";
      return out;
    }
    if (global) {
      out.converged = out.unrestrained.empty();
      std::ostringstream os;
      os << "FETI (projected MPRGP, SMALBE) converged: " << out.inner_iterations << " MPRGP iterations in " << outer
         << " outer iterations (" << r.cg_steps << " CG, " << r.expansion_steps << " expansion, "
         << r.proportioning_steps << " proportioning steps in the last; F products " << seconds_F_
         << " s, coarse projections " << seconds_coarse_ << " s)";
      out.message = out.converged ? os.str() : "the contact nodes in contact do not hold every floating body";
      return out;
    }
    if (out.inner_iterations >= s_.max_iterations || !r.converged) break;
    // SMALBE's update: the multipliers, and M halved when the Lagrangian did not grow by rho/2 ||Q x||^2.
    const Eigen::VectorXd Qx = coarse_.range_part(x);
    const double L = 0.5 * x.dot(r.gradient - bound_.b);
    nu += rho_ * Qx;
    if (outer > 1 && L < previous_L + 0.5 * rho_ * Qx.squaredNorm()) M /= 2;
    previous_L = L;
    violation.push_back(Qx.norm());
    if (stagnating(violation)) {
      if (out.unrestrained.empty()) out.unrestrained = unbalanced_rows(out.z);
      out.message = "the contact nodes in contact do not hold every floating body";
      return out;
    }
    // On a face much smaller than the contact surface (a cylinder on a block) rho Q acts there only through the
    // face's share of the rigid modes' gaps, and the multiplier updates crawl: raise rho (A's spectrum on ker G
    // is unchanged; the expansion step shortens with ||A||) while the violation falls by less than 10x.
    const size_t k = violation.size();
    if (k >= 2 && violation[k - 1] > 0.1 * violation[k - 2] && rho_ < 1e6 * norm_PHP) {
      rho_ *= 10;
      norm_A_ = std::max(norm_PHP, rho_);
    }
  }
  std::ostringstream os;
  os << "FETI did not converge within " << out.inner_iterations << " MPRGP iterations and " << out.steps
     << " outer iterations (interface.max_iterations " << s_.max_iterations << ")";
  out.message = os.str();
  return out;
}

}  // namespace

linalg::ActiveSetResult FetiSolver::solve(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context) {
  Smalbe smalbe(qp, settings_, context);
  return smalbe.run(z0);
}

}  // namespace contact::ddm

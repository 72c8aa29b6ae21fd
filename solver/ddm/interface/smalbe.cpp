#include "smalbe.hpp"

#include "../../common/scoped_timer.hpp"
#include "../friction_policy.hpp"

#include <cmath>
#include <limits>
#include <sstream>

namespace contact::ddm {

using linalg::QpSolution;

Smalbe::Smalbe(const InterfaceQp& qp, const InterfaceSolverSettings& settings, InterfaceSolveContext& context)
    : qp_(qp), s_(settings), ctx_(context), coarse_(qp.problem, qp.equilibrium), m_(qp.problem.size()) {}

bool Smalbe::prepare(QpSolution& out) {
  if (!coarse_.ok()) {
    out.unrestrained = coarse_.unheld();
    out.report.stop = SolveStop::singular;
    out.report.message = "the contact nodes cannot hold every floating body";
    return false;
  }
  if (!ready_) setup();
  return true;
}

bool Smalbe::apply_H(const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  bool stop = false;
  {
    ScopedTimer timer(seconds_F_);  // the per-iteration costs docs/parallel.md's model is built from
    stop = qp_.problem.apply(x, y, ctx_.frame.runner());
  }
  if (qp_.penalty.size() == m_) y += qp_.penalty.cwiseProduct(x);
  // Several processes: the sum carried every process's stop request, and the frame's check gives the agreed one.
  return stop || ctx_.frame.stop_requested();
}

bool Smalbe::apply_A(const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  Eigen::VectorXd Px, HPx;
  {
    ScopedTimer timer(seconds_coarse_);
    Px = coarse_.project(x);
  }
  const bool stop = apply_H(Px, HPx);
  ScopedTimer timer(seconds_coarse_);
  range_ = x - Px;  // Q x: MPRGP carries it along to the iterates (bound_.image), for the stopping test
  y = coarse_.project(HPx) + rho_ * range_;
  return stop;
}

bool Smalbe::precondition(const Eigen::VectorXd& r, Eigen::VectorXd& y) {
  const Eigen::VectorXd Pr = coarse_.project(r);
  Eigen::VectorXd Mr;
  const bool stop = qp_.problem.apply_preconditioner(Pr, Mr, ctx_.frame.runner()) || ctx_.frame.stop_requested();
  y = coarse_.project(Mr) + (r - Pr) / rho_;
  return stop;
}

void Smalbe::setup() {
  ready_ = true;
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
  nu_ = Eigen::VectorXd::Zero(m_);
  bound_.apply = [this](const Eigen::VectorXd& x, Eigen::VectorXd& y) { return apply_A(x, y); };
  bound_.image = [this]() -> const Eigen::VectorXd& { return range_; };
  if (s_.preconditioner != InterfacePreconditioner::none)
    bound_.precondition = [this](const Eigen::VectorXd& r, Eigen::VectorXd& y) { return precondition(r, y); };
}

// The pressures (and tangential multipliers), rigid amplitudes and gaps of the current iterate, as the direct
// solver would report them. A row is at its bound exactly where MPRGP holds it there (x on the shifted bound), so
// the rows that enter the rigid amplitudes' least squares (the free ones: a closed gap or a sticking node) do
// not depend on the rounding of x + z_I.
bool Smalbe::finish(const Eigen::VectorXd& x, const Bounds& bounds, QpSolution& out) {
  std::vector<char> active(static_cast<size_t>(m_));
  out.z = x + z_I_;
  const bool upper = bounds.upper.size() == m_;
  for (Eigen::Index j = 0; j < m_; ++j) {
    const bool at_lower = x[j] <= bound_.lower[j], at_upper = upper && x[j] >= bound_.upper[j];
    if (at_lower) out.z[j] = bounds.lower[j];
    if (at_upper) out.z[j] = bounds.upper[j];
    active[static_cast<size_t>(j)] = !at_lower && !at_upper;
  }
  last_z_ = out.z;  // the next solve's start
  Eigen::VectorXd Hz;
  const bool stop = apply_H(out.z, Hz);
  out.h = qp_.g + Hz;
  out.alpha = Eigen::VectorXd::Zero(coarse_.rows());
  if (!coarse_.empty()) {
    // With friction a floating body whose contact nodes all sit on their bounds (a brick whose bed joints both
    // slip) has an indeterminate rigid motion along the slip when its loads balance (SMALBE's equalities, checked
    // apart): the least rigid motion is not the answer there, since it lets some slip point along its friction
    // force. SMALBE's own equality multipliers are: MPRGP's gradient P h + nu, which its stop makes sign-consistent
    // on every bound, is h + G^T alpha_s with alpha_s = (G G^T)^-1 G (nu - h). So the motions no free column fixes
    // are taken nearest to alpha_s; the others by the least squares on the free columns, as without friction. A
    // body that would slide away is still named, by the stagnating equality violation.
    const Eigen::VectorXd prior = upper ? coarse_.solve_GGt(coarse_.G() * (nu_ - out.h)) : Eigen::VectorXd();
    out.alpha = coarse_.multipliers(out.h, active, upper, upper ? &prior : nullptr);
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

bool Smalbe::report(int step, const Solve& how, QpSolution& out) {
  linalg::ActiveSetStep r;
  r.step = step;
  const Eigen::Index normal = qp_.problem.normal_size();
  std::vector<char> active(static_cast<size_t>(normal));
  Eigen::VectorXd C(normal);
  for (Eigen::Index j = 0; j < normal; ++j) {
    active[static_cast<size_t>(j)] = out.z[j] > 0;
    r.active += active[static_cast<size_t>(j)];
    if (!previous_active_.empty())
      r.changes += active[static_cast<size_t>(j)] != previous_active_[static_cast<size_t>(j)];
    C[j] = out.z[j] - std::max(0.0, out.z[j] - out.h[j] / diagonal_[j]);
  }
  if (previous_active_.empty()) r.changes = r.active;
  previous_active_ = std::move(active);
  r.complementarity = how.measure ? how.measure(out.z, out.h) : C.norm() / std::max(out.z.norm(), 1e-300);
  out.report.iterations = step;
  return ctx_.on_step(out.z, out.h, r);
}

// The equality violation has stopped falling over the last outer iterations while the multipliers grow: no
// admissible pressures balance some floating body (its loads pull it off its contacts, or along them harder than
// friction holds).
bool Smalbe::stagnating(const std::vector<double>& violation) const {
  const size_t k = violation.size();
  const policy::Smalbe& p = policy::kFrictionPolicy.smalbe;
  return k >= static_cast<size_t>(p.stagnation_window) && violation[k - 1] > p.stagnation_fall * violation[k - 4] &&
         rho_ >= p.stagnation_rho * norm_PHP_;
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

// The gradient's scale: the free response's penetration (where the contact acts), not its open gaps, which can be
// orders of magnitude larger on a curved surface and would make the tolerance meaningless. With friction the
// normal rows' alone too: the free slips of the tangential rows (after the normal ones) are as large as the open
// gaps on a curved surface, where they would loosen the tolerance by as much (hertz_force: 1e-8 instead of 1e-12).
void Smalbe::scales(double& scale_g) const {
  const double penetration = Pc_.head(qp_.problem.normal_size()).cwiseMin(0.0).norm();
  scale_g = penetration > 0 ? penetration : std::max(Pc_.norm(), 1e-300);
}

void Smalbe::solve(const Bounds& bounds, const Eigen::VectorXd* z0, const Solve& how, QpSolution& out) {
  if (!ready_) setup();
  out.report.stop = SolveStop::max_iterations;
  out.unrestrained.clear();
  bound_.lower = bounds.lower - z_I_;
  bound_.upper = bounds.upper.size() == m_ ? Eigen::VectorXd(bounds.upper - z_I_) : Eigen::VectorXd();
  double scale_g = 1.0;
  scales(scale_g);
  const policy::Smalbe& tuning = policy::kFrictionPolicy.smalbe;
  const double eta = tuning.eta * scale_g;
  // rho from ||P H P|| again: raised where the previous solve's multipliers crawled, at its cap it would take the
  // equality violation's rounding floor near a warm start for a body nothing holds (stagnating()).
  rho_ = norm_A_ = norm_PHP_;
  double M = norm_A_;
  const Eigen::VectorXd* start = z0 && z0->size() == m_ ? z0 : last_z_.size() == m_ ? &last_z_ : nullptr;
  Eigen::VectorXd x = start ? Eigen::VectorXd(*start - z_I_) : Eigen::VectorXd::Zero(m_);
  double previous_L = -std::numeric_limits<double>::infinity();
  std::vector<double> violation;
  int face_attempts = 0;
  linalg::MprgpSettings inner;
  const int max_outer = std::max(1, ctx_.max_steps);
  for (int outer = 1; outer <= max_outer; ++outer) {
    inner.alpha_bar = tuning.step / (tuning.norm_margin * norm_A_);
    bound_.b = -(Pc_ + nu_);
    inner.max_iterations = std::max<long>(1, s_.max_iterations - out.inner_iterations);
    bool global = false;
    const auto done = [&](const linalg::MprgpResult& state) {
      const double norm_gp = state.projected_gradient();
      const double feasibility = state.image.norm();  // ||Q x||
      const double z_scale = std::max((state.x + z_I_).norm(), 1e-300);
      if (norm_gp <= how.tolerance * scale_g && feasibility <= how.tolerance * z_scale) return global = true;
      return norm_gp <= std::max(std::min(M * feasibility, eta), tuning.inner_floor * how.tolerance * scale_g);
    };
    last_inner_ = linalg::solve_mprgp(bound_, x, inner, done);
    const linalg::MprgpResult& r = last_inner_;
    out.inner_iterations += r.report.iterations;
    steps_.cg_steps += r.cg_steps;
    steps_.expansion_steps += r.expansion_steps;
    steps_.proportioning_steps += r.proportioning_steps;
    x = r.x;
    out.report.iterations = outer;
    // A face that the last inner solve kept throughout (CG steps only) after a multiplier update: solved on the
    // face directly (smalbe_face.cpp), at most twice a solve (a face that was not the answer's costs its products).
    if (!global && r.report.converged() && outer >= 2 && face_attempts < tuning.face_attempts &&
        r.expansion_steps == 0 && r.proportioning_steps == 0) {
      ++face_attempts;
      // CG to a tenth of the tolerance where it is the finest the solve is asked for, as SMALBE's inner solves go
      // (their floor, in `done`): stopped at the tolerance itself the answer was 20x less accurate than
      // SMALBE's (hertz_force.json: pressures 1.7e-8 from the monolithic reference against 7.5e-10). The
      // intermediate solves of Coulomb's outer iteration need only their own tolerance (a tenth there too cost the
      // 8 x 8 wall 30 % more products).
      const double target = how.tolerance <= tuning.face_finest_factor * s_.tolerance ? tuning.face_target_finest : 1.0;
      const FaceSolve f = solve_face(x, how.tolerance * scale_g, target * how.tolerance * scale_g, out);
      if (f == FaceSolve::cancelled) {
        out.report.stop = SolveStop::cancelled;
        out.report.message = "cancelled";
        return;
      }
      global = f == FaceSolve::solved;
    }
    // The answer's pressures, gradient and rigid amplitudes (a product with F and a least squares on the free
    // rows) where someone reads them: a report, or the solve's end. Between two multiplier updates nobody does
    // (Coulomb's Tresca solves report nothing: about 8 % of a 64 x 64 wall's run went here).
    const bool last =
        global || r.report.cancelled() || !r.report.converged() || out.inner_iterations >= s_.max_iterations;
    const bool stop = ((last || how.report) && finish(x, bounds, out)) || r.report.cancelled();
    if (stop || (how.report && report(outer, how, out))) {
      out.report.stop = SolveStop::cancelled;
      out.report.message = "cancelled";
      return;
    }
    if (global) {
      out.report.stop = out.unrestrained.empty() ? SolveStop::converged : SolveStop::singular;
      std::ostringstream os;
      os << "FETI (projected MPRGP, SMALBE) converged: " << out.inner_iterations << " MPRGP iterations in " << outer
         << " outer iterations (" << r.cg_steps << " CG, " << r.expansion_steps << " expansion, "
         << r.proportioning_steps << " proportioning steps in the last; " << face_steps_
         << " products in CG on settled faces; F products " << seconds_F_ << " s, coarse projections "
         << seconds_coarse_ << " s)";
      out.report.message =
          out.report.converged() ? os.str() : "the contact nodes in contact do not hold every floating body";
      return;
    }
    if (last) break;
    if (!update_multipliers(x, r, outer, M, previous_L, violation)) {
      if (!how.report && finish(x, bounds, out)) {
        out.report.stop = SolveStop::cancelled;
        out.report.message = "cancelled";
        return;
      }
      if (out.unrestrained.empty()) out.unrestrained = unbalanced_rows(out.z);
      out.report.stop = SolveStop::singular;
      out.report.message = "the contact nodes in contact do not hold every floating body";
      return;
    }
  }
  std::ostringstream os;
  os << "FETI did not converge within " << out.inner_iterations << " MPRGP iterations and " << out.report.iterations
     << " outer iterations (interface.max_iterations " << s_.max_iterations << ")";
  out.report.message = os.str();
}

// SMALBE's update after an inner solve: the multipliers, and M halved when the Lagrangian did not grow by
// rho/2 ||Q x||^2. False when the equality violation stagnates (a floating body nothing holds).
bool Smalbe::update_multipliers(const Eigen::VectorXd& x, const linalg::MprgpResult& r, int outer, double& M,
                                double& previous_L, std::vector<double>& violation) {
  const Eigen::VectorXd Qx = coarse_.range_part(x);
  const double L = 0.5 * x.dot(r.gradient - bound_.b);
  nu_ += rho_ * Qx;
  if (outer > 1 && L < previous_L + 0.5 * rho_ * Qx.squaredNorm()) M /= 2;
  previous_L = L;
  violation.push_back(Qx.norm());
  if (stagnating(violation)) return false;
  // On a face much smaller than the contact surface (a cylinder on a block) rho Q acts there only through the
  // face's share of the rigid modes' gaps, and the multiplier updates crawl: rho is raised (A's spectrum on ker G is
  // unchanged; the expansion step shortens with ||A||) once the violation has fallen little in each of the last
  // three updates, up to a cap; past the cap only where the updates have stalled while the inner solves are cheap
  // (the multipliers' pace, not MPRGP's, is what costs). Three updates, not one: each Tresca solve of Coulomb's
  // outer iteration starts from the last answer projected onto its new bounds, whose violation the first updates
  // take down by 2-3x each; raising rho there made every later CG step work against a large rho on the free rows.
  // The factors and caps: policy::Smalbe (ddm/friction_policy.hpp); the runs that chose them: docs/algorithm.md,
  // "The interface solvers".
  const size_t k = violation.size();
  const auto fell_little = [&](size_t i, double factor) { return violation[i] > factor * violation[i - 1]; };
  const auto fell_little_thrice = [&](double factor) {
    return k >= 4 && fell_little(k - 1, factor) && fell_little(k - 2, factor) && fell_little(k - 3, factor);
  };
  const policy::Smalbe& tuning = policy::kFrictionPolicy.smalbe;
  const bool crawling = fell_little_thrice(tuning.rho_crawl);
  const bool stalled = fell_little_thrice(tuning.rho_frozen) ||
                       (fell_little_thrice(tuning.rho_stall) && r.report.iterations <= tuning.rho_stall_inner);
  if (crawling && rho_ < (stalled ? tuning.rho_stall_cap : tuning.rho_cap) * norm_PHP_) {
    rho_ *= tuning.rho_raise;
    norm_A_ = std::max(norm_PHP_, rho_);
  }
  return true;
}

}  // namespace contact::ddm

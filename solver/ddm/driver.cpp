#include "driver.hpp"

#include <Eigen/QR>

#include <cmath>
#include <deque>
#include <limits>
#include <sstream>

namespace contact::ddm {

void OffsetObserver::on_iteration(const IterationReport& r) {
  IterationReport copy = r;
  copy.iteration += offset_;
  if (update_ > 0) copy.update = update_;
  if (!refined_.empty()) {
    for (size_t a = 0; a < copy.bodies.size() && a < refined_.size(); ++a) copy.bodies[a].elements_refined = refined_[a];
    refined_.clear();
  }
  inner_.on_iteration(copy);
}

MethodOutcome MethodRunner::run(RunContext& context) {
  switch (settings_.method) {
    case Method::monolithic: return run_monolithic(system_, settings_, context);
    case Method::robin: return run_robin(system_, settings_, context);
    case Method::interface_newton: {
      if (system_.pairs().empty()) return run_neumann(system_, settings_, context);
      int setup = 0;
      if (!interface_newton_) {
        interface_newton_ = std::make_unique<InterfaceNewton>(system_, settings_, context.runner);
        setup = 1;  // the free response of every body
      }
      MethodOutcome out = interface_newton_->solve(settings_, context);
      out.solves_per_body += setup;
      return out;
    }
    case Method::neumann: break;
  }
  return run_neumann(system_, settings_, context);
}

namespace {

// Augmented Lagrangian (Uzawa): solve the penalty problem on the gaps shifted by theta lambda, then set lambda
// to the resulting pressures P(lambda) = max(0, lambda - g / theta); repeat until the pressures settle. The fixed
// point has g >= 0 where lambda = 0 and g = 0 where lambda > 0: exact non-penetration, for any theta.
// Plain Uzawa converges linearly and slowly where points at the edge of the contact zone have both gap and
// multiplier near zero (100 updates on stack3), so the multiplier fixed point is Anderson-mixed (depth 5,
// projected onto lambda >= 0, restarted when a mixed update makes the residual ten times worse).
MethodOutcome run_augmented_lagrangian(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                                       MethodRunner& runner, int& updates) {
  MethodOutcome total;
  Displacements warm;
  const auto& al = settings.augmented_lagrangian;
  const auto& pairs = system.pairs();
  std::vector<Eigen::Index> offset(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) offset[k + 1] = offset[k] + pairs[k].n_rows();
  Eigen::VectorXd sqrt_w(offset.back());
  for (size_t k = 0; k < pairs.size(); ++k) sqrt_w.segment(offset[k], pairs[k].n_rows()) = pairs[k].area.cwiseSqrt();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(offset.back());
  std::deque<Eigen::VectorXd> d_lambda, d_residual, d_image;
  Eigen::VectorXd previous_lambda, previous_residual, previous_image;
  double best = std::numeric_limits<double>::infinity();
  const size_t depth = 5;

  for (int update = 1; update <= al.max_updates; ++update) {
    OffsetObserver observer(context.observer, total.iterations, update);
    RunContext inner{observer, context.cancel, context.runner, context.start, warm.empty() ? nullptr : &warm};
    MethodOutcome o = runner.run(inner);
    updates = update;
    for (auto& r : o.history) {
      r.iteration += total.iterations;
      r.update = update;
      total.history.push_back(std::move(r));
    }
    total.iterations += o.iterations;
    total.add_work(o);
    total.gamma = o.gamma;
    total.u = std::move(o.u);
    total.z = std::move(o.z);
    if (o.reason != StopReason::converged) {
      total.reason = o.reason;
      total.message = "augmented Lagrangian update " + std::to_string(update) + ": " + o.message;
      return total;
    }
    // P(lambda): the pressures of this solve.
    const Pressures solved = total.z.empty() ? system.penalty_pressures(total.u) : total.z;
    Eigen::VectorXd image(offset.back());
    for (size_t k = 0; k < pairs.size(); ++k) image.segment(offset[k], pairs[k].n_rows()) = solved[k];
    const Eigen::VectorXd residual = sqrt_w.cwiseProduct(image - lambda);
    const double scale = sqrt_w.cwiseProduct(image).norm();
    const double change = scale > 0 ? residual.norm() / scale : 0.0;
    if (change <= al.tolerance) {
      // Keep the multipliers the last solve used, so that the reported pressures are exactly its pressures.
      total.converged = true;
      total.reason = StopReason::converged;
      std::ostringstream os;
      os << "augmented Lagrangian: pressures settled (relative change " << change << " <= " << al.tolerance << ") after "
         << update << " updates; last inner solve: " << o.message;
      total.message = os.str();
      return total;
    }
    // Anderson-mixed Uzawa update.
    if (residual.norm() > 10 * best) {
      d_lambda.clear();
      d_residual.clear();
      d_image.clear();
      previous_lambda.resize(0);
    }
    best = std::min(best, residual.norm());
    if (previous_lambda.size()) {
      d_lambda.push_back(lambda - previous_lambda);
      d_residual.push_back(residual - previous_residual);
      d_image.push_back(image - previous_image);
      if (d_lambda.size() > depth) {
        d_lambda.pop_front();
        d_residual.pop_front();
        d_image.pop_front();
      }
    }
    previous_lambda = lambda;
    previous_residual = residual;
    previous_image = image;
    Eigen::VectorXd next = image;
    while (!d_residual.empty()) {
      Eigen::MatrixXd A(residual.size(), static_cast<Eigen::Index>(d_residual.size()));
      for (size_t i = 0; i < d_residual.size(); ++i) A.col(static_cast<Eigen::Index>(i)) = d_residual[i];
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
      const double d0 = std::abs(qr.matrixR()(0, 0));
      const double dmin = std::abs(qr.matrixR()(A.cols() - 1, A.cols() - 1));
      if (qr.rank() == A.cols() && dmin > 1e-10 * d0) {
        const Eigen::VectorXd c = qr.solve(residual);
        for (size_t i = 0; i < d_image.size(); ++i) next -= c[static_cast<Eigen::Index>(i)] * d_image[i];
        break;
      }
      d_lambda.pop_front();
      d_residual.pop_front();
      d_image.pop_front();
    }
    lambda = next.cwiseMax(0.0);
    for (size_t k = 0; k < pairs.size(); ++k) system.set_multipliers(k, lambda.segment(offset[k], pairs[k].n_rows()));
    warm = total.u;
    if (update == al.max_updates) {
      total.reason = StopReason::max_iterations;
      std::ostringstream os;
      os << "augmented Lagrangian: max_updates = " << update << " reached with a relative pressure change of " << change;
      total.message = os.str();
    }
  }
  return total;
}

}  // namespace

MethodOutcome run_enforced(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                           MethodRunner& runner, int& updates) {
  updates = 0;
  if (settings.enforcement == Enforcement::exact &&
      (settings.method == Method::neumann || settings.method == Method::robin)) {
    MethodOutcome out;
    out.reason = StopReason::error;
    out.message = std::string("method ") + (settings.method == Method::neumann ? "neumann" : "robin") +
                  " iterates on the penalty problem: enforcement exact is not available with it (use penalty, or "
                  "augmented_lagrangian for exact contact in the limit; or method interface_newton)";
    return out;
  }
  if (settings.enforcement == Enforcement::augmented_lagrangian)
    return run_augmented_lagrangian(system, settings, context, runner, updates);
  return runner.run(context);
}

}  // namespace contact::ddm

#include "augmented_lagrangian.hpp"

#include "../linalg/anderson.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

namespace contact::ddm {

// Augmented Lagrangian (Uzawa): solve the penalty problem on the gaps shifted by theta lambda, then set lambda
// to the resulting pressures P(lambda) = max(0, lambda - g / theta); repeat until the pressures settle. The fixed
// point has g >= 0 where lambda = 0 and g = 0 where lambda > 0: exact non-penetration, for any theta.
// Plain Uzawa converges linearly and slowly where points at the edge of the contact zone have both gap and
// multiplier near zero (100 updates on stack3), so the multiplier fixed point is Anderson-mixed (depth 5,
// projected onto lambda >= 0, restarted when a mixed update makes the residual ten times worse).
MethodOutcome run_augmented_lagrangian(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                                       ContactMethod& method, int& updates) {
  OutcomeAccumulator updates_so_far;
  MethodOutcome& total = updates_so_far.total();
  Displacements warm;
  const auto& al = settings.augmented_lagrangian;
  const auto& pairs = system.pairs();
  std::vector<Eigen::Index> offset(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) offset[k + 1] = offset[k] + pairs[k].n_rows();
  Eigen::VectorXd sqrt_w(offset.back());
  for (size_t k = 0; k < pairs.size(); ++k) sqrt_w.segment(offset[k], pairs[k].n_rows()) = pairs[k].area.cwiseSqrt();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(offset.back());
  linalg::AndersonHistory<Eigen::VectorXd> history(5);  // multiplier fixed point: image differences
  Eigen::VectorXd previous_lambda, previous_residual, previous_image;
  double best = std::numeric_limits<double>::infinity();

  for (int update = 1; update <= al.max_updates; ++update) {
    updates_so_far.run(context, warm.empty() ? nullptr : &warm, InnerMarks{update, {}},
                       [&](RunContext& inner) { return method.run(inner); });
    updates = update;
    // The updates' stop is their own (below); their answer is the displacements and pressures alone, without
    // rigid amplitudes or tangential multipliers (friction needs exact contact).
    total.converged = false;
    total.rigid_amplitudes.clear();
    total.q.clear();
    const std::string inner_message = std::move(total.message);
    if (total.reason != StopReason::converged) {
      total.message = "augmented Lagrangian update " + std::to_string(update) + ": " + inner_message;
      return updates_so_far.take();
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
         << update << " updates; last inner solve: " << inner_message;
      total.message = os.str();
      return updates_so_far.take();
    }
    // Anderson-mixed Uzawa update.
    if (residual.norm() > 10 * best) {
      history.clear();
      previous_lambda.resize(0);
    }
    best = std::min(best, residual.norm());
    if (previous_lambda.size()) history.push(residual - previous_residual, image - previous_image);
    previous_lambda = lambda;
    previous_residual = residual;
    previous_image = image;
    Eigen::VectorXd next = image;
    history.mix(residual, [&](double c, const Eigen::VectorXd& d_image) { next -= c * d_image; });
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
  return updates_so_far.take();
}


}  // namespace contact::ddm

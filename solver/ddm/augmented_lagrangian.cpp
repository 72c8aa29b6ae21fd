#include "augmented_lagrangian.hpp"

#include "../linalg/anderson.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

namespace contact::ddm {

namespace {

// The contact multipliers of all pairs as one vector lambda, and their Uzawa update, Anderson-mixed (depth 5,
// projected onto lambda >= 0, restarted when a mixed update makes the residual ten times worse).
class UzawaMultipliers {
 public:
  explicit UzawaMultipliers(const ContactSystem& system) : pairs_(system.pairs()), offset_(pairs_.size() + 1, 0) {
    for (size_t k = 0; k < pairs_.size(); ++k) offset_[k + 1] = offset_[k] + pairs_[k].n_rows();
    sqrt_w_.resize(offset_.back());
    for (size_t k = 0; k < pairs_.size(); ++k)
      sqrt_w_.segment(offset_[k], pairs_[k].n_rows()) = pairs_[k].area.cwiseSqrt();
    lambda_ = Eigen::VectorXd::Zero(offset_.back());
  }

  // P(lambda): a solve's pressures, all pairs stacked.
  Eigen::VectorXd image(const Pressures& solved) const {
    Eigen::VectorXd out(offset_.back());
    for (size_t k = 0; k < pairs_.size(); ++k) out.segment(offset_[k], pairs_[k].n_rows()) = solved[k];
    return out;
  }

  // The fixed-point residual P(lambda) - lambda, weighted by the square roots of the rows' areas.
  Eigen::VectorXd residual(const Eigen::VectorXd& image) const { return sqrt_w_.cwiseProduct(image - lambda_); }

  // Its norm relative to the image's (0 for no pressure at all).
  double relative_change(const Eigen::VectorXd& image, const Eigen::VectorXd& residual) const {
    const double scale = sqrt_w_.cwiseProduct(image).norm();
    return scale > 0 ? residual.norm() / scale : 0.0;
  }

  // lambda <- the Anderson-mixed image, projected onto lambda >= 0, and given to the run state.
  void update(RunState& state, const Eigen::VectorXd& image, const Eigen::VectorXd& residual) {
    lambda_ = mixing_.next(image, residual);
    state.multipliers.resize(pairs_.size());
    for (size_t k = 0; k < pairs_.size(); ++k) state.multipliers[k] = lambda_.segment(offset_[k], pairs_[k].n_rows());
  }

 private:
  const std::vector<mortar::PairDiscretization>& pairs_;
  std::vector<Eigen::Index> offset_;  // per pair, into lambda
  Eigen::VectorXd sqrt_w_, lambda_;
  linalg::NonnegativeAnderson mixing_{5};  // the multiplier fixed point
};

}  // namespace

// Augmented Lagrangian (Uzawa): solve the penalty problem on the gaps shifted by theta lambda, then set lambda
// to the resulting pressures P(lambda) = max(0, lambda - g / theta); repeat until the pressures settle. The fixed
// point has g >= 0 where lambda = 0 and g = 0 where lambda > 0: exact non-penetration, for any theta.
// Plain Uzawa converges linearly and slowly where points at the edge of the contact zone have both gap and
// multiplier near zero (100 updates on stack3), so the multiplier fixed point is Anderson-mixed (UzawaMultipliers).
void run_augmented_lagrangian(const ContactSystem& system, RunFrame& frame, ContactMethod& method) {
  MethodOutcome& total = frame.outcome();
  Displacements warm;
  const auto& al = frame.settings().augmented_lagrangian;
  UzawaMultipliers multipliers(system);
  for (int update = 1; update <= al.max_updates; ++update) {
    frame.nested(warm.empty() ? nullptr : &warm, InnerMarks{update, {}}, [&](RunFrame& inner) { method.run(inner); });
    total.updates = update;
    // The updates' stop is their own (below); their answer is the last solve's displacements, pressures and
    // floating bodies' rigid amplitudes (the result's rigid motion), without tangential multipliers (friction
    // needs exact contact).
    total.converged = false;
    total.q.clear();
    const std::string inner_message = std::move(total.message);
    if (total.stop_reason != StopReason::converged) {
      total.message = "augmented Lagrangian update " + std::to_string(update) + ": " + inner_message;
      return;
    }
    const Eigen::VectorXd image =
        multipliers.image(total.z.empty() ? system.penalty_pressures(total.u, frame.state()) : total.z);
    const Eigen::VectorXd residual = multipliers.residual(image);
    const double change = multipliers.relative_change(image, residual);
    if (change <= al.tolerance) {
      // Keep the multipliers the last solve used, so that the reported pressures are exactly its pressures.
      total.converged = true;
      total.stop_reason = StopReason::converged;
      std::ostringstream os;
      os << "augmented Lagrangian: pressures settled (relative change " << change << " <= " << al.tolerance
         << ") after " << update << " updates; last inner solve: " << inner_message;
      total.message = os.str();
      return;
    }
    multipliers.update(frame.state(), image, residual);
    warm = total.u;
    if (update == al.max_updates) {
      total.stop_reason = StopReason::max_iterations;
      std::ostringstream os;
      os << "augmented Lagrangian: max_updates = " << update << " reached with a relative pressure change of "
         << change;
      total.message = os.str();
    }
  }
}

}  // namespace contact::ddm

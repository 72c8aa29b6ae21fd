// Anderson mixing (type II, Walker & Ni 2011) for a fixed point x = g(x): the last few differences of the residual
// r = g(x) - x (in whatever norm the caller weights it) and of the quantities to be combined (`Step`: the iterate
// and map differences, whole displacement fields or multipliers) are kept; the next iterate is the plain update
// minus sum_i c_i dStep_i with c = argmin || r - sum_i c_i dr_i ||, solved by QR with column pivoting. Columns that
// make the least-squares problem ill-conditioned (rank deficiency, or a last pivot below 1e-10 of the first) are
// dropped, oldest first. Used by the interface fixed point of the Neumann and Robin schemes (ddm/fixed_point.cpp)
// and by the augmented-Lagrangian multiplier update (ddm/augmented_lagrangian.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/QR>

#include <cmath>
#include <deque>
#include <utility>

namespace contact::linalg {

template <class Step>
class AndersonHistory {
 public:
  explicit AndersonHistory(size_t depth) : depth_(depth < 1 ? 1 : depth) {}

  // Adds one pair of differences (residual, step); the oldest beyond `depth` is dropped.
  void push(Eigen::VectorXd residual_difference, Step step_difference) {
    dr_.push_back(std::move(residual_difference));
    steps_.push_back(std::move(step_difference));
    if (dr_.size() > depth_) pop_oldest();
  }
  void clear() {
    dr_.clear();
    steps_.clear();
  }
  size_t size() const { return dr_.size(); }
  bool empty() const { return dr_.empty(); }

  // Calls combine(c_i, dStep_i) for the least-squares coefficients of r against the residual differences kept
  // (after dropping the columns that make it ill-conditioned); nothing when the history is empty.
  template <class Combine>
  void mix(const Eigen::VectorXd& r, Combine&& combine) {
    while (!dr_.empty()) {
      Eigen::MatrixXd A(r.size(), static_cast<Eigen::Index>(dr_.size()));
      for (size_t i = 0; i < dr_.size(); ++i) A.col(static_cast<Eigen::Index>(i)) = dr_[i];
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
      const double d0 = std::abs(qr.matrixR()(0, 0));
      const double dmin = std::abs(qr.matrixR()(A.cols() - 1, A.cols() - 1));
      if (qr.rank() == A.cols() && dmin > 1e-10 * d0) {
        const Eigen::VectorXd c = qr.solve(r);
        for (size_t i = 0; i < steps_.size(); ++i) combine(c[static_cast<Eigen::Index>(i)], steps_[i]);
        return;
      }
      pop_oldest();
    }
  }

 private:
  void pop_oldest() {
    dr_.pop_front();
    steps_.pop_front();
  }

  size_t depth_;
  std::deque<Eigen::VectorXd> dr_;
  std::deque<Step> steps_;
};

}  // namespace contact::linalg

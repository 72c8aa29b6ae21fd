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

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
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

// Anderson mixing of a fixed point x = g(x) constrained to x >= 0 (contact multipliers, slip bounds): the caller
// passes each image g(x_k) with its residual (g(x_k) - x_k, weighted as it likes); next() returns the image mixed
// with the history's image differences and cut at 0 (the image itself while there is no history). The history
// restarts when a residual is more than ten times the best one so far (a mixed step that made things worse, or a
// change the extrapolation did not see). Used by the augmented-Lagrangian multipliers and the iterative solver's
// Coulomb slip bounds (ddm/interface/feti_friction.cpp).
class NonnegativeAnderson {
 public:
  explicit NonnegativeAnderson(size_t depth = 5) : history_(depth) {}

  Eigen::VectorXd next(const Eigen::VectorXd& image, const Eigen::VectorXd& residual) {
    const double norm = residual.norm();
    if (norm > 10 * best_ || last_residual_.size() != residual.size()) {
      history_.clear();
    } else {
      history_.push(residual - last_residual_, image - last_image_);
    }
    best_ = std::min(best_, norm);
    last_residual_ = residual;
    last_image_ = image;
    Eigen::VectorXd out = image;
    history_.mix(residual, [&](double c, const Eigen::VectorXd& d_image) { out -= c * d_image; });
    return out.cwiseMax(0.0);
  }
  // Whether the last next() combined any history (false: it returned the image).
  bool mixed() const { return !history_.empty(); }
  void reset() {
    history_.clear();
    last_residual_.resize(0);
    best_ = std::numeric_limits<double>::infinity();
  }

 private:
  AndersonHistory<Eigen::VectorXd> history_;
  Eigen::VectorXd last_residual_, last_image_;
  double best_ = std::numeric_limits<double>::infinity();
};

}  // namespace contact::linalg

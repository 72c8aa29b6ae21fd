#include "interpolation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace contact::bem {

ChebyshevGrid::ChebyshevGrid(int points_per_direction) : p_(points_per_direction) {
  if (p_ < 1 || p_ > kMaxPerDirection)
    throw std::invalid_argument("bem: a Chebyshev grid has 1 to 16 nodes per direction, not " + std::to_string(p_));
  nodes_.resize(p_);
  weights_.resize(p_);
  for (int i = 0; i < p_; ++i) {
    const double angle = (2 * i + 1) * M_PI / (2 * p_);  // Chebyshev points of the first kind
    nodes_[i] = std::cos(angle);
    weights_[i] = (i % 2 == 0 ? 1.0 : -1.0) * std::sin(angle);
  }
}

ChebyshevGrid ChebyshevGrid::for_tolerance(double tolerance) {
  const double rho = 3.0 + std::sqrt(8.0);
  const double wanted = tolerance > 0.0 ? std::log(1.0 / tolerance) / std::log(rho) + 1.0 : 16.0;
  return ChebyshevGrid(std::clamp(static_cast<int>(std::ceil(wanted)), 4, kMaxPerDirection));
}

ChebyshevGrid::Interval ChebyshevGrid::interval(const BoundingBox& box, int axis) const {
  const Eigen::Vector2d half = 0.5 * (box.hi - box.lo);
  const double floor = std::max(1e-3 * half.maxCoeff(), 1e-300);
  return {0.5 * (box.lo[axis] + box.hi[axis]), std::max(half[axis], floor)};
}

std::vector<Eigen::Vector2d> ChebyshevGrid::nodes_in(const BoundingBox& box) const {
  const Interval x = interval(box, 0), y = interval(box, 1);
  std::vector<Eigen::Vector2d> out;
  out.reserve(static_cast<std::size_t>(nodes()));
  for (int i = 0; i < p_; ++i)
    for (int j = 0; j < p_; ++j)
      out.emplace_back(x.centre + x.half_width * nodes_[i], y.centre + y.half_width * nodes_[j]);
  return out;
}

ChebyshevGrid::Basis ChebyshevGrid::basis(double t) const {
  Basis l(p_);
  for (int i = 0; i < p_; ++i) {
    const double d = t - nodes_[i];
    if (d == 0.0) {  // at a node: its basis function is 1, the others 0
      l.setZero();
      l[i] = 1.0;
      return l;
    }
    l[i] = weights_[i] / d;
  }
  return l / l.sum();
}

Eigen::RowVector3d ChebyshevGrid::at(const BoundingBox& box, const Eigen::MatrixX3d& values,
                                     const Eigen::Vector2d& x) const {
  const Interval ix = interval(box, 0), iy = interval(box, 1);
  const Basis lx = basis((x.x() - ix.centre) / ix.half_width);
  const Basis ly = basis((x.y() - iy.centre) / iy.half_width);
  Eigen::RowVector3d out = Eigen::RowVector3d::Zero();
  for (int i = 0; i < p_; ++i) {
    Eigen::RowVector3d along_y = Eigen::RowVector3d::Zero();
    for (int j = 0; j < p_; ++j) along_y += ly[j] * values.row(i * p_ + j);
    out += lx[i] * along_y;
  }
  return out;
}

}  // namespace contact::bem

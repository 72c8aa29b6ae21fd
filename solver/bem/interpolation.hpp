// Tensor-product Chebyshev interpolation over a box, for the far field of the interior evaluation
// (hierarchical_somigliana.cpp; docs/bem.md, "Interior points through interpolation").
//
// The stresses that the elements of a cluster produce are analytic away from them. Over a box of diameter at
// most its distance to those elements, each coordinate's interpolation interval (half-width w <= diam / 2) has its
// nearest singularity at least 2w beyond its ends, i.e. at |t| >= 3 in the normalised variable, so the Chebyshev
// interpolant of degree p - 1 converges like rho^-p with rho = 3 + sqrt(8) = 5.83 (Trefethen, Approximation
// Theory and Approximation Practice, ch. 8). `for_tolerance` picks p from the relative accuracy asked for.
#pragma once

#include "cluster_tree.hpp"

#include <Eigen/Core>
#include <vector>

namespace contact::bem {

class ChebyshevGrid {
 public:
  static constexpr int kMaxPerDirection = 16;
  explicit ChebyshevGrid(int points_per_direction);
  // The smallest p with rho^-(p - 1) <= tolerance (one degree spare for the 2D tensor product), 4 <= p <= 16.
  static ChebyshevGrid for_tolerance(double tolerance);

  int per_direction() const { return p_; }
  int nodes() const { return p_ * p_; }
  // The p x p nodes of the box (row k = i p + j: i-th node in x, j-th in y). A side of zero width is widened to
  // 1e-3 of the other (points on a line), so the nodes are distinct.
  std::vector<Eigen::Vector2d> nodes_in(const BoundingBox& box) const;
  // The interpolant of `values` (one row of a stress per node, in the order of nodes_in) at x inside the box.
  Eigen::RowVector3d at(const BoundingBox& box, const Eigen::MatrixX3d& values, const Eigen::Vector2d& x) const;

 private:
  struct Interval {
    double centre, half_width;
  };
  Interval interval(const BoundingBox& box, int axis) const;
  // The p Lagrange basis functions of the nodes at t in [-1, 1] (barycentric form); no heap allocation.
  using Basis = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxPerDirection, 1>;
  Basis basis(double t) const;

  int p_;
  Eigen::VectorXd nodes_, weights_;  // on [-1, 1]; barycentric weights
};

}  // namespace contact::bem

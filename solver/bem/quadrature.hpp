// Integration along a straight element: Gauss-Legendre rules, adaptive splitting towards a nearby source point,
// and the closed forms for an element that contains the source point.
//
// An element is x(s) = start + s * tangent, s in [0, L] (arc length), with linear shape functions
// N_0(s) = 1 - s / L (start node) and N_1(s) = s / L (end node).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace contact::bem {

// Gauss-Legendre points and weights mapped to [0, 1]; n = 1..16 (computed once, by Newton's method).
struct GaussRule {
  std::vector<double> points;
  std::vector<double> weights;
};
const GaussRule& gauss_legendre(int n);

// Distance from `point` to the segment [a, b].
double distance_to_segment(const Eigen::Vector2d& point, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// Integrates over s in [s_begin, s_end] of the element (start, unit tangent) by calling add(s, weight) at the
// quadrature points. The source point xi lies off the piece. A piece is integrated by Gauss-Legendre once its
// length is at most its distance to xi, with 4, 6, 10 or 16 points for length/distance <= 0.05, 0.15, 0.4 or 1;
// longer pieces are halved. The kernels are analytic but for their pole (at most of order 1/r^2) at xi, so the
// Gauss error decays like rho^(-2 points), rho the Bernstein ellipse through xi: rho >= 80, 27, 10, 4.2 for these
// ratios, which keeps every rule below ~1e-15 relative to the kernel's size on the piece. Pieces shrink geometrically
// towards the point nearest xi, so a point at distance d costs about log2(L / d) levels of two pieces.
template <class Add>
void integrate_adaptively(const Eigen::Vector2d& start, const Eigen::Vector2d& tangent, double s_begin, double s_end,
                          const Eigen::Vector2d& xi, Add&& add, int depth = 0) {
  constexpr int kMaxDepth = 60;
  const double length = s_end - s_begin;
  const double distance = distance_to_segment(xi, start + s_begin * tangent, start + s_end * tangent);
  const double ratio = distance > 0.0 ? length / distance : HUGE_VAL;
  if (ratio > 1.0 && depth < kMaxDepth) {
    const double middle = 0.5 * (s_begin + s_end);
    integrate_adaptively(start, tangent, s_begin, middle, xi, add, depth + 1);
    integrate_adaptively(start, tangent, middle, s_end, xi, add, depth + 1);
    return;
  }
  const GaussRule& rule = gauss_legendre(ratio <= 0.05 ? 4 : ratio <= 0.15 ? 6 : ratio <= 0.4 ? 10 : 16);
  for (std::size_t q = 0; q < rule.points.size(); ++q) add(s_begin + length * rule.points[q], length * rule.weights[q]);
}

// int_0^L N_m(s) ln(1 / |s - s_xi|) ds for m = 0, 1 and s_xi in [0, L] (closed form).
Eigen::Vector2d log_moments(double length, double s_xi);

// Cauchy principal value PV int_0^L N_m(s) / (s - s_xi) ds for m = 0, 1 and s_xi in (0, L). At an end
// (s_xi = 0 or L) only the shape function that vanishes there has a finite integral, +1 at s_xi = 0 (m = 1) and
// -1 at s_xi = L (m = 0); the other is not needed (the rigid-body identity replaces it) and is returned as 0.
Eigen::Vector2d cauchy_moments(double length, double s_xi);

}  // namespace contact::bem

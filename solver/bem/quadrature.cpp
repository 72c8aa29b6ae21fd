#include "quadrature.hpp"

#include <array>
#include <cmath>
#include <mutex>
#include <stdexcept>

namespace contact::bem {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxGaussPoints = 16;

// Golub-Welsch would do as well; Newton on P_n from the Chebyshev-like initial guesses converges in a few steps.
GaussRule make_gauss_legendre(int n) {
  GaussRule rule;
  rule.points.resize(static_cast<std::size_t>(n));
  rule.weights.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;  // P_0, P_1, then the recurrence up to P_n
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1.0;
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const auto k = static_cast<std::size_t>(i);
    rule.points[k] = 0.5 * (1.0 - x);                                   // [-1, 1] -> [0, 1], ascending
    rule.weights[k] = 1.0 / ((1.0 - x * x) * derivative * derivative);  // 2 / (...) halved for [0, 1]
  }
  return rule;
}

// F0(A) = int_0^A ln(1/s) ds, F1(A) = int_0^A s ln(1/s) ds (0 at A = 0).
double log_integral0(double a) { return a > 0.0 ? a * (1.0 - std::log(a)) : 0.0; }
double log_integral1(double a) { return a > 0.0 ? a * a * (0.25 - 0.5 * std::log(a)) : 0.0; }

}  // namespace

const GaussRule& gauss_legendre(int n) {
  if (n < 1 || n > kMaxGaussPoints) throw std::invalid_argument("gauss_legendre: n must be in 1..16");
  static std::array<GaussRule, kMaxGaussPoints + 1> rules;
  static std::once_flag once;
  std::call_once(once, [] {
    for (int k = 1; k <= kMaxGaussPoints; ++k) rules[static_cast<std::size_t>(k)] = make_gauss_legendre(k);
  });
  return rules[static_cast<std::size_t>(n)];
}

double distance_to_segment(const Eigen::Vector2d& point, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double squared = ab.squaredNorm();
  const double s = squared > 0.0 ? std::clamp((point - a).dot(ab) / squared, 0.0, 1.0) : 0.0;
  return (point - (a + s * ab)).norm();
}

Eigen::Vector2d log_moments(double length, double s_xi) {
  // N(s) = alpha + beta s. Left of xi (s = s_xi - sigma) and right of it (s = s_xi + sigma):
  // int N ln(1/|s - s_xi|) = N(s_xi) (F0(s_xi) + F0(L - s_xi)) + beta (F1(L - s_xi) - F1(s_xi)).
  const double left = s_xi, right = length - s_xi;
  const double f0 = log_integral0(left) + log_integral0(right);
  const double f1 = log_integral1(right) - log_integral1(left);
  const double n1 = s_xi / length;  // N_1(s_xi); N_0(s_xi) = 1 - n1; beta = -1/L, +1/L
  return {(1.0 - n1) * f0 - f1 / length, n1 * f0 + f1 / length};
}

Eigen::Vector2d cauchy_moments(double length, double s_xi) {
  // N(s) = N(s_xi) + beta (s - s_xi): PV = N(s_xi) ln((L - s_xi) / s_xi) + beta L.
  if (s_xi <= 0.0) return {0.0, 1.0};
  if (s_xi >= length) return {-1.0, 0.0};
  const double n1 = s_xi / length;
  const double logarithm = std::log((length - s_xi) / s_xi);
  return {(1.0 - n1) * logarithm - 1.0, n1 * logarithm + 1.0};
}

}  // namespace contact::bem

#include "curve_fit.hpp"

#include <cmath>

namespace contact::mesh {

namespace {

// The signed curvature of the circle through p, q, r (positive when the chain turns left at q): 2 sin(turn) / |r - p|.
double curvature(const Point& p, const Point& q, const Point& r) {
  const Point u = q - p, v = r - q;
  const double cross = u.x() * v.y() - u.y() * v.x();
  return 2 * cross / (u.norm() * v.norm() * (r - p).norm());
}

}  // namespace

std::vector<std::optional<Curve>> fitted_arcs(const std::vector<Point>& nodes, bool closed) {
  const size_t n = nodes.size();
  const size_t sides = n < 2 ? 0 : (closed ? n : n - 1);
  std::vector<std::optional<Curve>> out(sides);
  if (n < 3) return out;
  // The node's circle where it has two neighbours.
  std::vector<std::optional<double>> at_node(n);
  for (size_t i = 0; i < n; ++i) {
    if (!closed && (i == 0 || i + 1 == n)) continue;
    at_node[i] = curvature(nodes[(i + n - 1) % n], nodes[i], nodes[(i + 1) % n]);
  }
  for (size_t k = 0; k < sides; ++k) {
    const Point a = nodes[k], b = nodes[(k + 1) % n];
    double sum = 0;
    int count = 0;
    for (const auto& kappa : {at_node[k], at_node[(k + 1) % n]})
      if (kappa) sum += *kappa, ++count;
    const double kappa = count ? sum / count : 0.0;
    const double c = (b - a).norm();
    // Straight where the sag kappa c^2 / 8 is below 1e-7 of the side (a larger radius would cost the arc its
    // digits: the centre 1e6 sides away), or no arc of that curvature spans the side.
    if (!(std::abs(kappa) * c > 1e-6) || !(std::abs(kappa) * c < 2)) continue;
    const double radius = 1 / std::abs(kappa);
    const Point e = (b - a) / c, left(-e.y(), e.x());
    Curve arc;
    arc.kind = Curve::Kind::arc;
    arc.radius = radius;
    // The centre on the side's bisector, to the left where the chain turns left.
    arc.center = 0.5 * (a + b) + (kappa > 0 ? 1.0 : -1.0) * std::sqrt(radius * radius - 0.25 * c * c) * left;
    out[k] = arc;
  }
  return out;
}

}  // namespace contact::mesh

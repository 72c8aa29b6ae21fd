#include "curve_fit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace contact::mesh {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The signed curvature of the circle through p, q, r (positive when the chain turns left at q): 2 sin(turn) / |r - p|.
double curvature(const Point& p, const Point& q, const Point& r) {
  const Point u = q - p, v = r - q;
  const double cross = u.x() * v.y() - u.y() * v.x();
  return 2 * cross / (u.norm() * v.norm() * (r - p).norm());
}

// The angle the chain turns through at q, in [0, pi].
double turn(const Point& p, const Point& q, const Point& r) {
  const Point u = q - p, v = r - q;
  return std::abs(std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v)));
}

// fitted_arcs on a chain without corners.
std::vector<std::optional<Curve>> smooth_arcs(const std::vector<Point>& nodes, bool closed) {
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

}  // namespace

std::vector<bool> chain_corners(const std::vector<Point>& nodes, bool closed) {
  const size_t n = nodes.size();
  std::vector<bool> corner(n, false);
  if (n < 3) return corner;
  std::vector<std::optional<double>> angle(n);
  for (size_t i = 0; i < n; ++i)
    if (closed || (i > 0 && i + 1 < n)) angle[i] = turn(nodes[(i + n - 1) % n], nodes[i], nodes[(i + 1) % n]);
  for (size_t i = 0; i < n; ++i) {
    if (!angle[i]) continue;
    const double a = *angle[i];
    bool sharper = a > 5 * kPi / 180;
    for (size_t j : {(i + n - 1) % n, (i + 1) % n})
      if (j != i && angle[j] && !(a > 3 * *angle[j])) sharper = false;
    corner[i] = a > kPi / 4 || sharper;
  }
  return corner;
}

std::vector<std::optional<Curve>> fitted_arcs(const std::vector<Point>& nodes, bool closed) {
  const size_t n = nodes.size();
  const std::vector<bool> corner = chain_corners(nodes, closed);
  const auto first = std::find(corner.begin(), corner.end(), true);
  if (first == corner.end()) return smooth_arcs(nodes, closed);
  // Piecewise between corners: each piece an open chain from a corner (or an open chain's start) to the next.
  const size_t sides = closed ? n : n - 1;
  std::vector<std::optional<Curve>> out(sides);
  const size_t start = closed ? static_cast<size_t>(first - corner.begin()) : 0;
  size_t done = 0;
  while (done < sides) {
    std::vector<Point> piece = {nodes[(start + done) % n]};
    size_t k = done;
    do {
      ++k;
      piece.push_back(nodes[(start + k) % n]);
    } while (k < sides && !corner[(start + k) % n]);
    const auto arcs = smooth_arcs(piece, false);
    for (size_t s = 0; s < arcs.size(); ++s) out[(start + done + s) % sides] = arcs[s];
    done = k;
  }
  return out;
}

void fit_edge_curves(Mesh& m, const std::string& edge) {
  if (!m.edge_sets.count(edge) || m.edge_curves.count(edge)) return;
  const std::vector<int> ids = m.edge_set_nodes(edge);
  const bool closed = m.edge_set_closed(edge);
  std::vector<Point> x;
  for (int i : ids) x.push_back(m.nodes[static_cast<size_t>(i)]);
  const auto arcs = fitted_arcs(x, closed);
  for (size_t k = 0; k < arcs.size(); ++k) {
    if (!arcs[k]) continue;
    const int i = ids[k], j = ids[(k + 1) % ids.size()];
    m.side_curves.emplace(std::make_pair(std::min(i, j), std::max(i, j)), *arcs[k]);
  }
}

std::optional<std::string> set_edge_curve(Mesh& m, const std::string& edge, const Curve& curve) {
  if (!m.edge_sets.count(edge)) return std::nullopt;
  for (const auto& e : m.edge_sets.at(edge)) {
    const auto [i, j] = m.edge_nodes(e);
    Curve side = curve;
    if (auto message = fit_curve(side, m.nodes[static_cast<size_t>(i)], m.nodes[static_cast<size_t>(j)])) {
      std::ostringstream os;
      os << "side [" << i << ", " << j << "]: " << *message;
      return os.str();
    }
    m.side_curves[std::make_pair(std::min(i, j), std::max(i, j))] = side;
  }
  return std::nullopt;
}

}  // namespace contact::mesh

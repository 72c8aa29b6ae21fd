#include "edge_curves.hpp"

#include "segments.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace contact::mortar {

namespace {

// The root of smallest magnitude of A t^2 + B t + C = 0 (nullopt without a real root). The stable form
// (Numerical Recipes 5.6): q = -(B + sign(B) sqrt(B^2 - 4 A C)) / 2, roots q / A and C / q.
std::optional<double> smallest_root(double A, double B, double C) {
  if (A == 0.0) {
    if (B == 0.0) return std::nullopt;
    return -C / B;
  }
  const double disc = B * B - 4 * A * C;
  if (disc < 0) return std::nullopt;
  const double q = -0.5 * (B + (B >= 0 ? 1.0 : -1.0) * std::sqrt(disc));
  if (q == 0.0) return 0.0;  // B = C = 0: the double root 0
  const double r1 = q / A, r2 = C / q;
  return std::abs(r1) < std::abs(r2) ? r1 : r2;
}

}  // namespace

EdgeCurves::EdgeCurves(std::vector<Eigen::Vector2d> points, std::vector<std::optional<mesh::Curve>> curves)
    : points_(std::move(points)), curves_(std::move(curves)) {
  for (auto& c : curves_)
    if (c && c->kind == mesh::Curve::Kind::line) c.reset();
  curves_.resize(points_.size() < 2 ? 0 : points_.size() - 1);
}

EdgeCurves EdgeCurves::of_sides(const mesh::Mesh& mesh, const std::vector<int>& polyline,
                                const std::vector<std::string>& edges) {
  std::vector<Eigen::Vector2d> points;
  for (int n : polyline) points.push_back(mesh.nodes[static_cast<size_t>(n)]);
  std::vector<std::optional<mesh::Curve>> curves;
  for (size_t k = 0; k + 1 < polyline.size(); ++k) {
    const auto named = mesh.edge_curves.find(edges[k]);
    const auto side = mesh.side_curves.find(std::minmax(polyline[k], polyline[k + 1]));
    if (side != mesh.side_curves.end())
      curves.emplace_back(side->second);
    else if (named != mesh.edge_curves.end())
      curves.emplace_back(named->second);
    else
      curves.emplace_back(std::nullopt);
  }
  return EdgeCurves(std::move(points), std::move(curves));
}

bool EdgeCurves::any_curved() const {
  return std::any_of(curves_.begin(), curves_.end(), [](const auto& c) { return c.has_value(); });
}

EdgeCurves::Frame EdgeCurves::at(size_t k, double xi) const {
  const Eigen::Vector2d a = points_[k], b = points_[k + 1];
  const Eigen::Vector2d chord_normal = outward_normal(a, b);
  Frame f;
  f.point = a + xi * (b - a);
  f.normal = chord_normal;
  if (!curved(k)) return f;
  const mesh::Curve& c = *curves_[k];
  Eigen::Vector2d n = chord_normal;
  if (c.kind == mesh::Curve::Kind::arc) {
    const Eigen::Vector2d r = f.point - c.center;
    n = r / r.norm();
    f.point = c.center + c.radius * n;
  } else {  // parabola y = a x^2 + b x + c
    const double x = f.point.x();
    f.point = {x, (c.a * x + c.b) * x + c.c};
    n = Eigen::Vector2d(-(2 * c.a * x + c.b), 1.0).normalized();
  }
  f.normal = n.dot(chord_normal) < 0 ? Eigen::Vector2d(-n) : n;
  return f;
}

std::optional<double> EdgeCurves::hit(size_t k, const Eigen::Vector2d& x, const Eigen::Vector2d& n) const {
  if (!curved(k)) {  // the chord: x + t n = a + eta (b - a)
    const Eigen::Vector2d a = points_[k], f = points_[k + 1] - a, r = a - x;
    const double det = -n.x() * f.y() + n.y() * f.x();
    if (!(std::abs(det) > 1e-12 * f.norm())) return std::nullopt;
    return (-r.x() * f.y() + r.y() * f.x()) / det;
  }
  const mesh::Curve& c = *curves_[k];
  if (c.kind == mesh::Curve::Kind::arc) {  // |x + t n - centre|^2 = R^2
    const Eigen::Vector2d r = x - c.center;
    const double d = r.norm();
    return smallest_root(1.0, 2 * n.dot(r), (d - c.radius) * (d + c.radius));
  }
  // a (x + t n_x)^2 + b (x + t n_x) + c = y + t n_y
  const double px = x.x(), nx = n.x();
  return smallest_root(c.a * nx * nx, 2 * c.a * px * nx + c.b * nx - n.y(), (c.a * px + c.b) * px + c.c - x.y());
}

double EdgeCurves::chord_parameter(size_t k, const Eigen::Vector2d& p) const {
  const Eigen::Vector2d e = points_[k + 1] - points_[k];
  return (p - points_[k]).dot(e) / e.squaredNorm();
}

}  // namespace contact::mortar

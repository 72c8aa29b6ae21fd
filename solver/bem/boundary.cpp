#include "boundary.hpp"

#include <limits>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>

#include "quadrature.hpp"

namespace contact::bem {

namespace {

constexpr double kLengthTolerance = 1e-12;       // relative to the diameter: shorter elements count as zero
constexpr double kOrientationTolerance = 1e-13;  // relative to diameter^2 in the segment-intersection tests
constexpr double kAgreementTolerance = 1e-8;     // relative to the largest prescribed displacement
constexpr double kNullTolerance = 1e-10;         // relative to the largest singular value (rigid motions)

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument("bem: " + message); }

std::string point_text(const Eigen::Vector2d& p) {
  std::ostringstream os;
  os << std::setprecision(6) << '(' << p.x() << ", " << p.y() << ')';
  return os.str();
}

const char* component_name(int c) { return c == 0 ? "x" : "y"; }

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Do the closed segments [p1, p2] and [p3, p4] share a point? Collinearity within `tolerance` (an area).
bool segments_touch(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Vector2d& p3,
                    const Eigen::Vector2d& p4, double tolerance) {
  const double d1 = cross(p4 - p3, p1 - p3), d2 = cross(p4 - p3, p2 - p3);
  const double d3 = cross(p2 - p1, p3 - p1), d4 = cross(p2 - p1, p4 - p1);
  const auto strictly_opposite = [tolerance](double a, double b) {
    return (a > tolerance && b < -tolerance) || (a < -tolerance && b > tolerance);
  };
  if (strictly_opposite(d1, d2) && strictly_opposite(d3, d4)) return true;
  // q lies on [a, b] when it is collinear with it and inside its bounding box.
  const auto on_segment = [tolerance](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q,
                                      double d) {
    if (std::abs(d) > tolerance) return false;
    const Eigen::Vector2d ab = b - a;
    const double t = (q - a).dot(ab) / ab.squaredNorm();
    return t >= -1e-12 && t <= 1.0 + 1e-12;
  };
  return on_segment(p3, p4, p1, d1) || on_segment(p3, p4, p2, d2) || on_segment(p1, p2, p3, d3) ||
         on_segment(p1, p2, p4, d4);
}

// The sizes, the material and finite input.
void check_input(const BoundaryProblem& problem) {
  const std::size_t n = problem.nodes.size();
  if (n < 3) fail("the boundary needs at least 3 nodes, got " + std::to_string(n));
  if (problem.elements.size() != n)
    fail("wrong sizes: elements.size() = " + std::to_string(problem.elements.size()) + " but nodes.size() = " +
         std::to_string(n) + " (element e joins node e and node (e + 1) % n, so the two must be equal)");

  const Material& m = problem.material;
  if (!std::isfinite(m.E) || m.E <= 0.0) fail("Young's modulus must be positive and finite");
  if (!std::isfinite(m.nu) || m.nu <= -1.0 || m.nu > 0.5) fail("Poisson's ratio must lie in (-1, 0.5]");
  if (m.plane_strain && m.nu >= 0.5) fail("Poisson's ratio 0.5 is incompressible: not supported in plane strain");

  for (std::size_t i = 0; i < n; ++i)
    if (!problem.nodes[i].allFinite()) fail("node " + std::to_string(i) + " has a non-finite coordinate");
  for (std::size_t e = 0; e < n; ++e)
    if (!problem.elements[e].value.allFinite()) fail("element " + std::to_string(e) + " has a non-finite value");
}

// The elements' lengths, tangents and normals, the diameter and the shortest element (none of zero length).
BoundaryGeometry element_geometry(const BoundaryProblem& problem) {
  const std::size_t n = problem.nodes.size();
  BoundaryGeometry geometry;
  Eigen::Vector2d lo = problem.nodes[0], hi = problem.nodes[0];
  for (const auto& p : problem.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  geometry.diameter = (hi - lo).norm();
  if (geometry.diameter <= 0.0) fail("all nodes coincide");

  // Element geometry; zero-length elements.
  geometry.elements.resize(n);
  geometry.min_length = HUGE_VAL;
  for (std::size_t e = 0; e < n; ++e) {
    BoundaryElement& el = geometry.elements[e];
    el.start = problem.nodes[e];
    el.end = problem.nodes[(e + 1) % n];
    el.length = (el.end - el.start).norm();
    if (el.length <= kLengthTolerance * geometry.diameter)
      fail("element " + std::to_string(e) + " (nodes " + std::to_string(e) + " and " + std::to_string((e + 1) % n) +
           ") has zero length: repeated node at " + point_text(el.start));
    el.tangent = (el.end - el.start) / el.length;
    el.normal = Eigen::Vector2d(el.tangent.y(), -el.tangent.x());
    geometry.min_length = std::min(geometry.min_length, el.length);
  }
  return geometry;
}

// A simple counter-clockwise polygon: no elements folding back, no non-adjacent ones touching (if `self_overlap`).
void check_polygon(const BoundaryGeometry& geometry, bool self_overlap) {
  const std::size_t n = geometry.elements.size();
  // Self-overlap: adjacent elements that fold back, non-adjacent elements that touch or cross.
  for (std::size_t e = 0; e < n; ++e) {
    const BoundaryElement& a = geometry.elements[e];
    const BoundaryElement& b = geometry.elements[(e + 1) % n];
    if (std::abs(cross(a.tangent, b.tangent)) < 1e-12 && a.tangent.dot(b.tangent) < 0.0)
      fail("the polygon is self-overlapping: elements " + std::to_string(e) + " and " + std::to_string((e + 1) % n) +
           " fold back onto each other at node " + std::to_string((e + 1) % n));
  }
  for (std::size_t i = 0; self_overlap && i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) check_elements_apart(geometry, i, j);

  // Orientation: the shoelace area is positive for a counter-clockwise polygon.
  double twice_area = 0.0;
  for (const auto& el : geometry.elements) twice_area += cross(el.start, el.end);
  if (twice_area <= 0.0)
    fail("the polygon is clockwise (signed area " + std::to_string(0.5 * twice_area) +
         "): list the nodes counter-clockwise, with the body on the left");
}

// Prescribed displacements of two elements at their common node must agree.
void check_prescribed_agree(const BoundaryProblem& problem) {
  const std::size_t n = problem.nodes.size();
  double largest = 0.0;
  for (const auto& data : problem.elements)
    for (int c = 0; c < 2; ++c)
      if (data.displacement_prescribed[static_cast<std::size_t>(c)])
        largest = std::max(largest, data.value.row(c).cwiseAbs().maxCoeff());
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t before = (i + n - 1) % n;
    const ElementData& p = problem.elements[before];
    const ElementData& q = problem.elements[i];
    for (int c = 0; c < 2; ++c) {
      const auto k = static_cast<std::size_t>(c);
      if (!p.displacement_prescribed[k] || !q.displacement_prescribed[k]) continue;
      if (std::abs(p.value(c, 1) - q.value(c, 0)) > kAgreementTolerance * largest) {
        std::ostringstream os;
        os << "node " << i << ": the prescribed " << component_name(c) << "-displacements of elements " << before
           << " (" << p.value(c, 1) << ") and " << i << " (" << q.value(c, 0) << ") disagree";
        fail(os.str());
      }
    }
  }
}

}  // namespace

BoundaryGeometry check_problem(const BoundaryProblem& problem, bool self_overlap) {
  check_input(problem);
  BoundaryGeometry geometry = element_geometry(problem);
  check_polygon(geometry, self_overlap);
  check_prescribed_agree(problem);
  return geometry;
}

void check_elements_apart(const BoundaryGeometry& geometry, std::size_t i, std::size_t j) {
  const std::size_t n = geometry.elements.size();
  if (i == j || (i + 1) % n == j || (j + 1) % n == i) return;  // the same or adjacent elements
  const BoundaryElement& a = geometry.elements[i];
  const BoundaryElement& b = geometry.elements[j];
  const Eigen::Vector2d a_lo = a.start.cwiseMin(a.end), a_hi = a.start.cwiseMax(a.end);
  const Eigen::Vector2d b_lo = b.start.cwiseMin(b.end), b_hi = b.start.cwiseMax(b.end);
  if ((b_lo.array() > a_hi.array() + 1e-12 * geometry.diameter).any() ||
      (a_lo.array() > b_hi.array() + 1e-12 * geometry.diameter).any())
    return;
  const double tolerance = kOrientationTolerance * geometry.diameter * geometry.diameter;
  if (segments_touch(a.start, a.end, b.start, b.end, tolerance))
    fail("the polygon is self-overlapping: elements " + std::to_string(std::min(i, j)) + " and " +
         std::to_string(std::max(i, j)) + " intersect near " + point_text(0.5 * (a.start + a.end)));
}

void check_solution(const BoundaryProblem& problem, const BoundarySolution& solution) {
  const auto n = static_cast<Eigen::Index>(problem.nodes.size());
  if (solution.displacement.rows() != n || solution.traction.size() != problem.elements.size())
    fail("wrong sizes: the solution has " + std::to_string(solution.displacement.rows()) + " displacements and " +
         std::to_string(solution.traction.size()) + " tractions for a problem of " + std::to_string(n) +
         " nodes and elements");
  if (!solution.displacement.allFinite()) fail("the solution has a non-finite displacement");
  for (const auto& t : solution.traction)
    if (!t.allFinite()) fail("the solution has a non-finite traction");
}

void check_interior_point(const BoundaryGeometry& geometry, const Eigen::Vector2d& x) {
  if (!x.allFinite()) fail("the interior point is not finite");
  double distance = HUGE_VAL;
  bool inside = false;  // even-odd rule; the polygon is simple
  for (const auto& el : geometry.elements) {
    distance = std::min(distance, distance_to_segment(x, el.start, el.end));
    const Eigen::Vector2d& a = el.start;
    const Eigen::Vector2d& b = el.end;
    if ((a.y() > x.y()) != (b.y() > x.y())) {
      const double crossing = a.x() + (x.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (x.x() < crossing) inside = !inside;
    }
  }
  if (distance <= 1e-12 * geometry.diameter) fail("the point " + point_text(x) + " lies on the boundary");
  if (!inside) fail("the point " + point_text(x) + " is not inside the body");
}

std::vector<std::string> free_rigid_motions(const BoundaryProblem& problem) {
  // The three rigid modes about the bounding-box centre, the rotation scaled to unit size at the farthest node,
  // evaluated at every prescribed displacement component; their null space holds the free motions.
  const std::size_t n = problem.nodes.size();
  Eigen::Vector2d lo = problem.nodes[0], hi = problem.nodes[0];
  for (const auto& p : problem.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), std::numeric_limits<double>::min());
  std::vector<Eigen::RowVector3d> rows;
  for (std::size_t i = 0; i < n; ++i) {
    const ElementData& before = problem.elements[(i + n - 1) % n];
    const ElementData& after = problem.elements[i];
    const Eigen::Vector2d d = (problem.nodes[i] - centre) / radius;
    for (std::size_t c = 0; c < 2; ++c)
      if (before.displacement_prescribed[c] || after.displacement_prescribed[c])
        rows.push_back(c == 0 ? Eigen::RowVector3d(1.0, 0.0, -d.y()) : Eigen::RowVector3d(0.0, 1.0, d.x()));
  }
  if (rows.empty()) return {"translation in x", "translation in y", "rotation"};
  // At least three rows, so that the SVD has three singular values.
  Eigen::MatrixX3d modes = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(std::max<std::size_t>(rows.size(), 3)), 3);
  for (std::size_t k = 0; k < rows.size(); ++k) modes.row(static_cast<Eigen::Index>(k)) = rows[k];
  Eigen::JacobiSVD<Eigen::MatrixX3d> svd(modes, Eigen::ComputeFullV);
  const Eigen::Vector3d sigma = svd.singularValues();
  std::vector<std::string> free;
  for (int k = 0; k < 3; ++k) {
    if (sigma(k) > kNullTolerance * sigma(0)) continue;
    const Eigen::Vector3d v = svd.matrixV().col(k);
    if (std::abs(v(2)) < 1e-8) {
      const Eigen::Vector2d t = v.head<2>().normalized();
      free.push_back(std::abs(t.y()) < 1e-8   ? "translation in x"
                     : std::abs(t.x()) < 1e-8 ? "translation in y"
                                              : "translation along " + point_text(t.x() < 0 ? -t : t));
    } else {
      const Eigen::Vector2d pivot = centre + radius * Eigen::Vector2d(-v(1), v(0)) / v(2);
      free.push_back("rotation about " + point_text(pivot));
    }
  }
  return free;
}

void check_rigid_motions(const BoundaryProblem& problem, const BoundaryGeometry&) {
  const std::vector<std::string> free = free_rigid_motions(problem);
  bool any_prescribed = false;
  for (const auto& e : problem.elements)
    any_prescribed = any_prescribed || e.displacement_prescribed[0] || e.displacement_prescribed[1];
  if (!any_prescribed)
    fail(
        "no displacement is prescribed, so the body is free to translate and rotate: prescribe displacement "
        "components that restrain both translations and the rotation (a traction-only body is not supported)");
  if (!free.empty()) {
    std::string list;
    for (const auto& f : free) list += (list.empty() ? "" : ", ") + f;
    fail("the prescribed displacements leave rigid motion free (" + list +
         "): prescribe displacement components that restrain both translations and the rotation");
  }
}

}  // namespace contact::bem

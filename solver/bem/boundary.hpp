// The boundary polygon of a BoundaryProblem: element geometry, input checks, and point location.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "bem.hpp"

namespace contact::bem {

// Element e: x(s) = start + s * tangent, s in [0, length]; outward normal = tangent turned clockwise.
struct BoundaryElement {
  Eigen::Vector2d start, end, tangent, normal;
  double length;
};

struct BoundaryGeometry {
  std::vector<BoundaryElement> elements;  // element e joins node e and node (e + 1) % n
  double diameter = 0.0;                  // of the bounding box
  double min_length = 0.0;                // shortest element
};

// The length R in the kernels' ln(R / r) (kelvin.hpp): 4 x the diameter, the same for solve() and Somigliana.
inline double log_scale(const BoundaryGeometry& geometry) { return 4.0 * geometry.diameter; }

// Checks everything solve() promises to check except the rigid motions, and builds the geometry.
// Throws std::invalid_argument naming the fault. `self_overlap` = false skips the O(n^2) test for crossing
// elements (Somigliana's identities at many points re-check a problem that solve() has accepted).
BoundaryGeometry check_problem(const BoundaryProblem& problem, bool self_overlap = true);

// Throws std::invalid_argument unless elements i and j (neither equal nor adjacent) are apart: the O(n^2)
// self-overlap test of check_problem() pair by pair, for callers that find the candidate pairs faster.
void check_elements_apart(const BoundaryGeometry& geometry, std::size_t i, std::size_t j);

// Throws std::invalid_argument unless `solution` has one displacement per node and one traction per element,
// all finite.
void check_solution(const BoundaryProblem& problem, const BoundarySolution& solution);

// Throws std::invalid_argument unless `x` lies inside the polygon, farther than 1e-12 x diameter from it.
void check_interior_point(const BoundaryGeometry& geometry, const Eigen::Vector2d& x);

// The rigid motions the prescribed displacement components of `problem` leave free, by name ("translation in x",
// "rotation about (x, y)"); empty when they restrain both translations and the rotation. `problem` has at least
// one node and one element per node.
std::vector<std::string> free_rigid_motions(const BoundaryProblem& problem);

// Throws std::invalid_argument, naming the free motions, unless the prescribed displacement components of
// `problem` restrain both translations and the rotation.
void check_rigid_motions(const BoundaryProblem& problem, const BoundaryGeometry& geometry);

}  // namespace contact::bem

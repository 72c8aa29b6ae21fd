// 2D elastostatic boundary element method: the FEM-BEM error indicator's independent solution of one body
// (docs/bem.md; docs/algorithm.md, "h-adaptivity"; the paper's section 3).
//
// Direct collocation BEM with straight two-node elements: displacements continuous and linear, tractions linear
// on each element and free to jump between elements; Kelvin fundamental solution of plane strain (plane stress
// through effective constants). Depends on Eigen only.
//
// Conventions (stated once, here):
// - Units are the caller's. Plane strain is per unit thickness; plane stress uses no thickness either (tractions
//   are forces per unit length of boundary, stresses are stresses), so the results never depend on a thickness.
// - Traction t = sigma n, n the OUTWARD unit normal of the body; a pressure p on a side is t = -p n.
// - Stress vectors are (sxx, syy, sxy).
// - The boundary is one closed polygon traversed counter-clockwise (body on the left). Element e joins node e and
//   node (e + 1) % n; its outward normal is the tangent turned clockwise, n = (t_y, -t_x).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <vector>

namespace contact::bem {

// Isotropic material. Plane strain uses (E, nu) directly. Plane stress is solved as plane strain with the
// effective constants nu' = nu / (1 + nu), E' = E (1 + 2 nu) / (1 + nu)^2: they keep the shear modulus
// (E' / (2 (1 + nu')) = E / (2 (1 + nu))) and turn the plane-strain Lame constant into the plane-stress one
// (lambda' = 2 mu nu' / (1 - 2 nu') = 2 mu nu / (1 - nu)), so in-plane stresses and displacements are exact.
struct Material {
  double E;
  double nu;
  bool plane_strain = true;
};

// Boundary data of one element, per component c (0 = x, 1 = y): either the displacement or the traction is
// prescribed. value(c, end): end 0 = the element's start node, end 1 = its end node. Prescribed displacements
// are nodal values (adjacent elements that both prescribe component c must agree at their common node);
// prescribed tractions are linear along the element and may jump between elements.
struct ElementData {
  std::array<bool, 2> displacement_prescribed{false, false};
  Eigen::Matrix2d value = Eigen::Matrix2d::Zero();
};

// One body: its boundary as a closed counter-clockwise polygon (hanging nodes of an FE mesh are simply extra,
// collinear nodes), one ElementData per element (elements.size() == nodes.size()), and its material.
// The prescribed displacements must restrain all three rigid motions (see solve()).
struct BoundaryProblem {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<ElementData> elements;
  Material material{1.0, 0.0};
};

// The complete boundary state: every node's displacement and every element's traction(c, end), prescribed
// values copied from the problem, the rest solved for.
struct BoundarySolution {
  Eigen::MatrixX2d displacement;
  std::vector<Eigen::Matrix2d> traction;
};

// Solves the boundary integral equation by collocation (docs/bem.md): nodal collocation, the free terms and
// the strongly singular integrals by the rigid-body-motion identity, weakly singular integrals in closed form,
// and at corners whose traction is unknown on both sides two collocation points shifted into the elements.
// Dense PartialPivLU: memory 8 (2n)^2 bytes and O(n^3) time for n nodes (docs/bem.md has timings).
// Throws std::invalid_argument, naming the fault, for: fewer than 3 nodes, sizes that disagree, non-finite
// data, a bad material, a zero-length element, a clockwise or self-intersecting polygon, prescribed
// displacements that disagree at a node, or prescribed displacements that leave a rigid motion free (a body
// loaded by tractions only is refused even when they are in equilibrium: its solution is not unique).
// Throws std::runtime_error if the collocation matrix is numerically singular.
BoundarySolution solve(const BoundaryProblem& problem);

// Stresses (sxx, syy, sxy) at a point strictly inside the body by Somigliana's identity for stresses
// (kernels D and S). Nearly singular element integrals are split adaptively towards the point (the pieces are
// no longer than their distance to it), so points a small fraction of an element size from the boundary stay
// accurate. Throws std::invalid_argument if x is not inside the body or the solution does not fit the problem
// (the problem is assumed to be one that solve() accepted: the O(n^2) self-overlap test is not repeated).
Eigen::Vector3d interior_stress(const BoundaryProblem& problem, const BoundarySolution& solution,
                                const Eigen::Vector2d& x);

// Displacement at a point strictly inside the body by Somigliana's identity (tests and diagnostics).
Eigen::Vector2d interior_displacement(const BoundaryProblem& problem, const BoundarySolution& solution,
                                      const Eigen::Vector2d& x);

// Many interior points at once (the FEM-BEM indicator evaluates every Gauss point of a mesh): checks the input
// once. Row k of the result holds point k's (sxx, syy, sxy).
Eigen::MatrixX3d interior_stresses(const BoundaryProblem& problem, const BoundarySolution& solution,
                                   const std::vector<Eigen::Vector2d>& points);

// ---- The hierarchical BEM (docs/bem.md, "Hierarchical BEM") -------------------------------------------------
// The same collocation equations as solve() and the same Somigliana sums as interior_stresses(), evaluated
// through a cluster tree on the boundary nodes: far-field blocks by adaptive cross approximation (recompressed),
// near-field blocks exactly, the system solved by restarted GMRES preconditioned by the near-field diagonal
// blocks. Time and memory O(N log N) in the boundary nodes instead of O(N^3) and O(N^2).

// Thrown when HierarchicalOptions::cancelled() returns true (checked between blocks and GMRES iterations).
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("bem: cancelled") {}
};

struct HierarchicalOptions {
  // Relative accuracy of every compressed block (ACA stop and recompression, Frobenius norm). The solve
  // amplifies it (by ~20 at 2k nodes, more on larger boundaries); 1e-8 keeps the hierarchical result within
  // ~1e-6 of the dense one, far below the 1e-4 of the stresses the indicator resolves (docs/bem.md).
  double tolerance = 1e-8;
  double eta = 1.0;                 // admissibility: min(diam) <= eta dist
  int leaf_size = 32;               // boundary nodes (or targets) per leaf cluster at most
  double solver_tolerance = 1e-10;  // GMRES: relative residual
  int restart = 60;                 // GMRES Krylov dimension
  int max_iterations = 2000;        // GMRES matrix products
  std::function<bool()> cancelled;  // polled between blocks and per GMRES iteration; true throws Cancelled
  // Interior evaluation: a far block of P points x E elements is compressed only if P E > break_even (P + E)
  // (ACA costs ~20 (P + E) kernel evaluations, the exact sum P E); smaller ones are summed exactly. 0: always ACA.
  double break_even = 20.0;
};

// What a hierarchical solve or evaluation did (for benchmarks and logs).
struct HierarchicalStats {
  int unknowns = 0;
  int near_blocks = 0, far_blocks = 0;
  int interpolated_blocks = 0;  // interior evaluation: far blocks through Chebyshev interpolation (in far_blocks)
  int largest_rank = 0;
  double mean_rank = 0.0;
  std::size_t matrix_bytes = 0;          // the compressed matrix (near + far blocks)
  std::size_t preconditioner_bytes = 0;  // the LU factors of the diagonal blocks
  int iterations = 0;                    // GMRES matrix products
  double relative_residual = 0.0;
  double setup_seconds = 0.0, solve_seconds = 0.0;
};

// solve() through the hierarchical matrix. The same checks as solve() (the self-overlap test by the cluster
// tree in O(N log N)); throws std::runtime_error if GMRES does not reach options.solver_tolerance.
BoundarySolution solve_hierarchical(const BoundaryProblem& problem, const HierarchicalOptions& options = {},
                                    HierarchicalStats* stats = nullptr);

// interior_stresses() through a second cluster tree, on the points; the inside test by the boundary's tree.
Eigen::MatrixX3d interior_stresses_hierarchical(const BoundaryProblem& problem, const BoundarySolution& solution,
                                                const std::vector<Eigen::Vector2d>& points,
                                                const HierarchicalOptions& options = {},
                                                HierarchicalStats* stats = nullptr);

// The automatic choice: the dense path below this many boundary nodes (exact to round-off and faster there),
// the hierarchical one from there on (docs/bem.md, "Which path"). The dense interior evaluation costs
// ~0.2 us per (node, point) pair, so above kDenseInteriorPairs pairs (~0.04 s) the points go through the tree too
// (with many points per node its interpolated far field costs a few us per point: docs/bem.md).
constexpr std::size_t kHierarchicalFromNodes = 1000;
constexpr double kDenseInteriorPairs = 2e5;
BoundarySolution solve_auto(const BoundaryProblem& problem, const HierarchicalOptions& options = {});
Eigen::MatrixX3d interior_stresses_auto(const BoundaryProblem& problem, const BoundarySolution& solution,
                                        const std::vector<Eigen::Vector2d>& points,
                                        const HierarchicalOptions& options = {});

}  // namespace contact::bem

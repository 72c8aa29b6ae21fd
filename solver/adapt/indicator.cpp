#include "indicator.hpp"

#include "../common/scoped_timer.hpp"

#include "../bem/bem.hpp"
#include "../bem/boundary.hpp"
#include "../fem/element.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <chrono>
#include <array>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <stdexcept>

namespace contact::adapt {

namespace {

std::pair<int, int> key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

// The relative accuracy of the interior evaluation (its far field; the solve keeps the default 1e-8, which the
// conditioning amplifies): the stresses to ~5e-6 (docs/bem.md, "Many points, few nodes"), well below the 1e-4
// that would change which cells are marked, with 9 x 9 interpolation nodes per box instead of 12 x 12.
constexpr double kEvaluationTolerance = 1e-6;

double squared_norm(const Eigen::Vector3d& s) { return s[0] * s[0] + s[1] * s[1] + 2 * s[2] * s[2]; }

// Stresses at the quadrature points of every cell (fem/element.hpp: 2x2 Gauss on a quadrilateral, 3 points on a
// triangle), one 3 x points block per cell.
using CellStresses = std::vector<fem::PointStresses>;

// eta from FE and reference stresses at the quadrature points of every cell.
// Also fills result.error2 and result.reference2 (the global estimate's parts).
Eigen::VectorXd normalised(const mesh::Mesh& m, const CellStresses& fe, const CellStresses& ref,
                           Normalization normalization, IndicatorResult& result) {
  const int n = m.num_cells();
  Eigen::VectorXd diff2(n), area(n);
  double ref2 = 0.0, total_area = 0.0;
  for (int c = 0; c < n; ++c) {
    const fem::CellQuadrature q = fem::cell_quadrature(m, c);
    const auto& f = fe[static_cast<size_t>(c)];
    const auto& r = ref[static_cast<size_t>(c)];
    diff2[c] = 0.0;
    area[c] = 0.0;
    for (int p = 0; p < q.size; ++p) {
      const double w = q.weight[static_cast<size_t>(p)];
      diff2[c] += w * squared_norm(r.col(p) - f.col(p));
      ref2 += w * squared_norm(r.col(p));
      area[c] += w;
    }
    total_area += area[c];
  }
  result.error2 = diff2.sum();
  result.error2_cell = diff2;
  result.reference2 = ref2;
  const bool rms = normalization == Normalization::rms;
  const double scale = std::sqrt(ref2) / (rms ? std::sqrt(total_area) : total_area);
  Eigen::VectorXd eta(n);
  for (int c = 0; c < n; ++c)
    eta[c] = scale > 0 ? (std::sqrt(diff2[c]) / (rms ? std::sqrt(area[c]) : area[c])) / scale : 0.0;
  return eta;
}

CellStresses fe_point_stresses(const Body& body, const fem::BodySolver& solver, const Eigen::VectorXd& u) {
  const auto& m = body.mesh;
  CellStresses out(static_cast<size_t>(m.num_cells()));
  for (int c = 0; c < m.num_cells(); ++c)
    out[static_cast<size_t>(c)] = fem::cell_point_stresses(m, c, fem::cell_values(m, c, u), solver.elasticity());
  return out;
}

// The cells' centres: the centroids of their quadrature points (inside every convex cell).
std::vector<Eigen::Vector2d> cell_centres(const mesh::Mesh& m) {
  std::vector<Eigen::Vector2d> centres(static_cast<size_t>(m.num_cells()));
  for (int c = 0; c < m.num_cells(); ++c) {
    const fem::CellQuadrature q = fem::cell_quadrature(m, c);
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double area = 0.0;
    for (int p = 0; p < q.size; ++p) {
      sum += q.weight[static_cast<size_t>(p)] * q.point[static_cast<size_t>(p)];
      area += q.weight[static_cast<size_t>(p)];
    }
    centres[static_cast<size_t>(c)] = sum / area;
  }
  return centres;
}

// A smooth field known at the cell centres (one row per cell), at every cell's quadrature points: per cell the
// linear field through its centre value whose gradient fits, by least squares, the centre values of the cells
// sharing a node with it. Exact for linear fields; O(h^2) for smooth ones (the boundary-element stress is smooth
// inside the body), far below the O(h) error of the FE stresses it is compared with.
CellStresses linear_fit_at_points(const mesh::Mesh& m, const std::vector<Eigen::Vector2d>& centres,
                                  const Eigen::MatrixX3d& values) {
  std::vector<std::vector<int>> cells_of_node(static_cast<size_t>(m.num_nodes()));
  for (int c = 0; c < m.num_cells(); ++c)
    for (int node : m.cells[static_cast<size_t>(c)]) cells_of_node[static_cast<size_t>(node)].push_back(c);
  CellStresses out(static_cast<size_t>(m.num_cells()));
  std::vector<int> neighbours;
  for (int c = 0; c < m.num_cells(); ++c) {
    neighbours.clear();
    for (int node : m.cells[static_cast<size_t>(c)])
      for (int n : cells_of_node[static_cast<size_t>(node)])
        if (n != c) neighbours.push_back(n);
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    const Eigen::Vector2d xc = centres[static_cast<size_t>(c)];
    const Eigen::Vector3d vc = values.row(c).transpose();
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Matrix<double, 3, 2> moments = Eigen::Matrix<double, 3, 2>::Zero();
    for (int n : neighbours) {
      const Eigen::Vector2d d = centres[static_cast<size_t>(n)] - xc;
      normal += d * d.transpose();
      moments += (values.row(n).transpose() - vc) * d.transpose();
    }
    // Neighbours on one line (or none) leave the gradient undetermined: the centre value alone then.
    const bool determined = normal.determinant() > 1e-6 * normal.squaredNorm();
    const Eigen::Matrix<double, 3, 2> gradient =
        determined ? Eigen::Matrix<double, 3, 2>(moments * normal.inverse()) : Eigen::Matrix<double, 3, 2>::Zero();
    const fem::CellQuadrature q = fem::cell_quadrature(m, c);
    auto& r = out[static_cast<size_t>(c)];
    r.resize(3, q.size);
    for (int p = 0; p < q.size; ++p) r.col(p) = vc + gradient * (q.point[static_cast<size_t>(p)] - xc);
  }
  return out;
}

}  // namespace

std::vector<int> boundary_loop(const mesh::Mesh& m) {
  // Sides seen once are boundary, except the two sides of a hanging node's split edge and the coarse side
  // itself (both are interior: the neighbour is refined). Hashed: this runs on every adaptive step's mesh.
  const auto edge_key = [&](int a, int b) {
    return static_cast<long long>(std::min(a, b)) * m.num_nodes() + std::max(a, b);
  };
  std::unordered_map<long long, int> count;
  count.reserve(static_cast<size_t>(m.num_cells()) * 4);
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      count[edge_key(n[0], n[1])]++;
    }
  std::unordered_set<long long> interior;
  for (const auto& [edge, mid] : m.edge_midpoint) {
    interior.insert(edge_key(edge.first, edge.second));
    interior.insert(edge_key(edge.first, mid));
    interior.insert(edge_key(mid, edge.second));
  }
  std::map<int, int> next;  // boundary side a -> b in the cells' counter-clockwise direction
  size_t sides = 0;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      if (count[edge_key(n[0], n[1])] != 1 || interior.count(edge_key(n[0], n[1]))) continue;
      if (next.count(n[0])) return {};  // a node starting two boundary sides: not a simple loop
      next[n[0]] = n[1];
      ++sides;
    }
  if (next.empty()) return {};
  std::vector<int> loop;
  int cur = next.begin()->first;
  for (size_t i = 0; i < sides; ++i) {
    loop.push_back(cur);
    auto it = next.find(cur);
    if (it == next.end()) return {};
    cur = it->second;
  }
  if (cur != loop.front()) return {};  // more than one loop (a hole) or an open chain
  return loop;
}

IndicatorResult zz_indicator(const Body& body, const fem::BodySolver& solver, const Eigen::VectorXd& u,
                             Normalization normalization) {
  const auto t0 = Clock::now();
  const auto& m = body.mesh;
  const CellStresses fe = fe_point_stresses(body, solver, u);
  const auto recovered = solver.stresses(u).node;  // nodal averages of the cells' values at their nodes
  CellStresses ref(fe.size());
  for (int c = 0; c < m.num_cells(); ++c) {
    const auto& cell = m.cells[static_cast<size_t>(c)];
    const fem::CellQuadrature q = fem::cell_quadrature(m, c);
    auto& r = ref[static_cast<size_t>(c)];
    r = fem::PointStresses::Zero(3, q.size);
    for (int p = 0; p < q.size; ++p)
      for (int k = 0; k < cell.size(); ++k)
        r.col(p) += q.shape(p, k) * recovered.row(cell[static_cast<size_t>(k)]).head<3>().transpose();
  }
  IndicatorResult r;
  r.eta = normalised(m, fe, ref, normalization, r);
  r.seconds = seconds_since(t0);  // (a ScopedTimer would add after the return's copy)
  return r;
}

namespace {

// The body's edge conditions per boundary side (vertex conditions hold no side; several loads may share an edge:
// they add) and each condition's edge length (for a total force spread over its edge).
struct SideConditions {
  std::map<std::pair<int, int>, std::vector<const BoundaryCondition*>> condition;
  std::map<const BoundaryCondition*, double> edge_length;
};

SideConditions side_conditions(const Body& body) {
  const auto& m = body.mesh;
  SideConditions out;
  for (const auto& bc : body.boundary) {
    if (!bc.vertex.empty()) continue;
    auto it = m.edge_sets.find(bc.edge);
    if (it == m.edge_sets.end()) continue;
    for (const auto& e : it->second) {
      const auto n = m.edge_nodes(e);
      out.condition[key(n[0], n[1])].push_back(&bc);
      out.edge_length[&bc] += (m.nodes[static_cast<size_t>(n[1])] - m.nodes[static_cast<size_t>(n[0])]).norm();
    }
  }
  return out;
}

// The boundary-element problem on the boundary loop: on each side the prescribed displacement components take the
// FE displacement, the others the applied traction plus the contact and point forces (nodal forces lumped over
// the sides next to their node), all at load point `at`.
bem::BoundaryProblem boundary_problem(const Body& body, const Model& model, const fem::BodySolver& solver,
                                      const Eigen::VectorXd& u, const Eigen::VectorXd& contact_load,
                                      const fem::LoadPoint& at, const std::vector<int>& loop, SideConditions& sides) {
  const auto& m = body.mesh;
  // Each condition at its own factor now: the loading's, or its history's (BoundaryCondition::history).
  // Point loads join the contact forces: both are nodal forces, lumped over the sides next to their node.
  Eigen::VectorXd nodal_load = contact_load.size() ? contact_load : Eigen::VectorXd::Zero(2 * m.num_nodes());
  for (const auto& bc : body.boundary)
    if (!bc.vertex.empty() && bc.kind == BoundaryCondition::Kind::force)
      for (int node : condition_nodes(m, bc))
        nodal_load.segment<2>(2 * node) += solver.condition_factor(bc, at) * bc.force;
  const size_t nb = loop.size();
  // Nodal forces to tractions, lumped over the boundary sides next to their node. Where one of the two sides has
  // a condition of its own and the other none (a contact edge meeting a symmetry line or a loaded edge), the
  // force goes to the free side alone: spread over both, a contact force would push on the symmetry face, and
  // the boundary-element solution would carry that spurious load at the corner (it set a mesh-independent
  // pressure correction of -22 at the paper's test's symmetry corner; pressure_estimate.hpp).
  auto side_free = [&](size_t i) {
    return sides.condition.find(key(loop[i], loop[(i + 1) % nb])) == sides.condition.end();
  };
  std::vector<double> half_length(nb, 0.0);
  std::vector<std::array<bool, 2>> takes(nb, {true, true});  // side i takes the load of its start / end node
  for (size_t i = 0; i < nb; ++i) {
    const size_t before = (i + nb - 1) % nb;
    if (side_free(i) != side_free(before)) {
      takes[i][0] = side_free(i);
      takes[before][1] = side_free(before);
    }
  }
  for (size_t i = 0; i < nb; ++i) {
    const double L = (m.nodes[static_cast<size_t>(loop[(i + 1) % nb])] - m.nodes[static_cast<size_t>(loop[i])]).norm();
    if (takes[i][0]) half_length[i] += 0.5 * L;
    if (takes[i][1]) half_length[(i + 1) % nb] += 0.5 * L;
  }
  bem::BoundaryProblem bp;
  bp.material = {body.material.E, body.material.nu, model.plane == Plane::strain};
  const double thickness = model.plane == Plane::stress ? model.thickness : 1.0;
  for (int n : loop) bp.nodes.push_back(m.nodes[static_cast<size_t>(n)]);
  bp.elements.resize(nb);
  for (size_t i = 0; i < nb; ++i) {
    const int a = loop[i], b = loop[(i + 1) % nb];
    auto& el = bp.elements[i];
    const auto c = sides.condition.find(key(a, b));
    static const std::vector<const BoundaryCondition*> none;
    const auto& conditions = c == sides.condition.end() ? none : c->second;
    const Eigen::Vector2d pa = m.nodes[static_cast<size_t>(a)], pb = m.nodes[static_cast<size_t>(b)];
    const Eigen::Vector2d outward((pb - pa).y(), -(pb - pa).x());
    Eigen::Vector2d traction = Eigen::Vector2d::Zero();
    std::array<bool, 2> held = {false, false};
    for (const BoundaryCondition* bc : conditions) {
      Eigen::Vector2d t = Eigen::Vector2d::Zero();
      if (bc->kind == BoundaryCondition::Kind::traction)
        t = bc->normal_pressure ? Eigen::Vector2d(-bc->pressure * outward.normalized()) : bc->traction;
      if (bc->kind == BoundaryCondition::Kind::force) t = bc->force / (sides.edge_length[bc] * thickness);
      traction += solver.condition_factor(*bc, at) * t;
      held[0] = held[0] || bc->ux.has_value();
      held[1] = held[1] || bc->uy.has_value();
    }
    for (int comp = 0; comp < 2; ++comp) {
      const bool prescribed = held[static_cast<size_t>(comp)];
      el.displacement_prescribed[static_cast<size_t>(comp)] = prescribed;
      if (prescribed) {
        el.value(comp, 0) = u[2 * a + comp];
        el.value(comp, 1) = u[2 * b + comp];
      } else {
        // Contact forces are per thickness-weighted length: divide the lumped force by length x thickness.
        const double ta = takes[i][0] ? nodal_load[2 * a + comp] / (half_length[i] * thickness) : 0.0;
        const double tb = takes[i][1] ? nodal_load[2 * b + comp] / (half_length[(i + 1) % nb] * thickness) : 0.0;
        el.value(comp, 0) = traction[comp] + ta;
        el.value(comp, 1) = traction[comp] + tb;
      }
    }
  }
  return bp;
}

// Where the body's edge conditions leave the boundary-element problem a rigid motion (a body held at a vertex, or
// only by its contacts' friction, or floating), the FE solution fixes it as the FE problem fixed it: the sides at
// each vertex support take the FE displacement in the components the vertex prescribes, and if motion is still
// free, the side farthest from the contact takes the FE displacement in both. A pinned side gives up its traction
// data (zero on a free side; that side then carries the FE's reaction, zero in equilibrium, as a boundary-element
// traction), so the comparison is the same problem's, not a different one's.
void pin_rigid_motions(const Body& body, const Eigen::VectorXd& u, const Eigen::VectorXd& contact_load,
                       const std::vector<int>& loop, bem::BoundaryProblem& bp) {
  if (bem::free_rigid_motions(bp).empty()) return;
  const auto& m = body.mesh;
  const size_t nb = loop.size();
  auto prescribe = [&](size_t i, int comp) {
    auto& el = bp.elements[i];
    el.displacement_prescribed[static_cast<size_t>(comp)] = true;
    el.value(comp, 0) = u[2 * loop[i] + comp];
    el.value(comp, 1) = u[2 * loop[(i + 1) % nb] + comp];
  };
  std::unordered_map<int, size_t> at;
  for (size_t i = 0; i < nb; ++i) at[loop[i]] = i;
  for (const auto& bc : body.boundary) {
    if (bc.vertex.empty() || !prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(m, bc)) {
      const auto it = at.find(node);
      if (it == at.end()) continue;
      for (int comp = 0; comp < 2; ++comp)
        if (comp == 0 ? bc.ux.has_value() : bc.uy.has_value()) {
          prescribe(it->second, comp);
          prescribe((it->second + nb - 1) % nb, comp);
        }
    }
  }
  if (bem::free_rigid_motions(bp).empty()) return;
  std::vector<Eigen::Vector2d> contact;
  for (int n : loop)
    if (contact_load.size() && contact_load.segment<2>(2 * n).squaredNorm() > 0.0)
      contact.push_back(m.nodes[static_cast<size_t>(n)]);
  size_t farthest = 0;
  double best = -1.0;
  for (size_t i = 0; i < nb; ++i) {
    const Eigen::Vector2d mid = 0.5 * (bp.nodes[i] + bp.nodes[(i + 1) % nb]);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& c : contact) nearest = std::min(nearest, (mid - c).norm());
    if (nearest > best) best = nearest, farthest = i;
  }
  prescribe(farthest, 0);
  prescribe(farthest, 1);
}

// Solves the boundary-element problem, evaluates its stresses at the cell centres and compares them with the FE
// stresses there (a cancel gives a cancelled result; a failed solve the zz indicator).
IndicatorResult compare_with_bem(const Body& body, const fem::BodySolver& solver, const Eigen::VectorXd& u,
                                 const bem::BoundaryProblem& bp, const std::vector<int>& loop,
                                 Normalization normalization, const std::function<bool()>& cancelled) {
  const auto& m = body.mesh;
  IndicatorResult r;
  try {
    bem::HierarchicalOptions options;
    options.cancelled = cancelled;
    const bem::BoundarySolution sol = bem::solve_auto(bp, options);
    const std::vector<Eigen::Vector2d> centres = cell_centres(m);
    bem::HierarchicalOptions evaluation = options;
    evaluation.tolerance = kEvaluationTolerance;
    const Eigen::MatrixX3d sb = bem::interior_stresses_auto(bp, sol, centres, evaluation);
    r.eta = normalised(m, fe_point_stresses(body, solver, u), linear_fit_at_points(m, centres, sb), normalization, r);
    r.bem_displacement = u;
    for (size_t i = 0; i < loop.size(); ++i)
      r.bem_displacement.segment<2>(2 * loop[i]) = sol.displacement.row(static_cast<Eigen::Index>(i)).transpose();
  } catch (const bem::Cancelled&) {
    r = IndicatorResult{};
    r.cancelled = true;
    r.note = "body '" + body.name + "': the boundary-element estimate was cancelled";
  } catch (const std::exception& e) {
    r = zz_indicator(body, solver, u, normalization);
    r.note = "body '" + body.name + "': the boundary-element solve failed (" + e.what() + "); zz indicator used";
  }
  return r;
}

}  // namespace

IndicatorResult fem_bem_indicator(const Body& body, const Model& model, const fem::BodySolver& solver,
                                  const Eigen::VectorXd& u, const Eigen::VectorXd& contact_load,
                                  const fem::LoadPoint& at, Normalization normalization,
                                  const std::function<bool()>& cancelled) {
  const auto t0 = Clock::now();
  const std::vector<int> loop = boundary_loop(body.mesh);
  if (loop.size() < 3) {
    IndicatorResult r = zz_indicator(body, solver, u, normalization);
    r.note = "body '" + body.name + "': its boundary is not one closed polygon; zz indicator used instead of fem_bem";
    return r;
  }
  SideConditions sides = side_conditions(body);
  bem::BoundaryProblem bp = boundary_problem(body, model, solver, u, contact_load, at, loop, sides);
  pin_rigid_motions(body, u, contact_load, loop, bp);
  IndicatorResult r = compare_with_bem(body, solver, u, bp, loop, normalization, cancelled);
  r.seconds = seconds_since(t0);  // (r is replaced on the way: not a ScopedTimer)
  return r;
}

Marking mark(const mesh::Mesh& mesh, const Eigen::VectorXd& eta, double delta, int max_level, long max_dofs,
             const std::vector<char>& graded) {
  Marking out;
  std::vector<int> candidates;
  for (int c = 0; c < mesh.num_cells(); ++c) {
    if (!(eta[c] > delta)) continue;
    if (!graded.empty() && graded[static_cast<size_t>(c)]) {
      ++out.graded_out;
      continue;
    }
    if (mesh.level[static_cast<size_t>(c)] >= max_level) {
      out.level_limit_hit = true;
      continue;
    }
    candidates.push_back(c);
  }
  std::sort(candidates.begin(), candidates.end(), [&](int a, int b) { return eta[a] > eta[b]; });
  // A split adds at most 5 nodes (a quadrilateral's 4 midpoints and centre; a triangle's 3 midpoints), 10 dofs; the
  // 1-irregularity closure can add more, so keep a margin of one extra split per marked cell.
  const long dofs = 2L * mesh.num_nodes();
  const long room = (max_dofs - dofs) / 20;
  if (static_cast<long>(candidates.size()) > room) {
    out.dof_limit_hit = true;
    candidates.resize(static_cast<size_t>(std::max(0L, room)));
  }
  out.cells = std::move(candidates);
  return out;
}

}  // namespace contact::adapt

#include "goal_marking.hpp"

#include <algorithm>
#include <cmath>

namespace contact::adapt {

namespace {

// The cells of the edge's two bodies (those that adapt) that reach within `radius` of it (the centre within
// radius plus the cell's own reach: a master cell coarser than the slave's segments at the edge is among them);
// the slave's around its last node in contact, the master's around the master nodes that node's row couples to
// (the bodies' meshes are undeformed: the master's edge lies a displacement away from the slave's).
std::vector<std::pair<size_t, int>> cells_near(const Problem& problem, const std::vector<Eigen::VectorXd>& goal,
                                               const PressureEstimate::EdgeShare& edge, double radius) {
  std::vector<std::pair<size_t, int>> out;
  for (const int body : {edge.slave_body, edge.master_body}) {
    const size_t a = static_cast<size_t>(body);
    if (body < 0 || a >= goal.size() || goal[a].size() == 0) continue;
    const Eigen::Vector2d x = body == edge.slave_body ? edge.at : edge.master_at;
    const mesh::Mesh& m = problem.bodies[a].mesh;
    for (int c = 0; c < m.num_cells(); ++c) {
      const mesh::Cell& cell = m.cells[static_cast<size_t>(c)];
      Eigen::Vector2d centre = Eigen::Vector2d::Zero();
      for (const int v : cell) centre += m.nodes[static_cast<size_t>(v)];
      centre /= cell.size();
      double reach = 0.0;
      for (const int v : cell) reach = std::max(reach, (m.nodes[static_cast<size_t>(v)] - centre).norm());
      if ((centre - x).norm() <= radius + reach) out.emplace_back(a, c);
    }
  }
  return out;
}

// The edges' share (goal_indicator): each edge's part of edges^2, scaled by total / defect^2, spread evenly over
// the cells near it.
void add_edge_shares(const Problem& problem, const PressureEstimate& pe, std::vector<Eigen::VectorXd>& goal) {
  double total = 0.0;
  for (const auto& g : goal) total += g.sum();
  if (!(total > 0.0) || !(pe.defect > 0.0)) return;
  for (const auto& edge : pe.edge_shares) {
    const auto near = cells_near(problem, goal, edge, edge.length);
    if (near.empty()) continue;
    const double each = total * edge.relative2 / (pe.defect * pe.defect) / static_cast<double>(near.size());
    for (const auto& [a, c] : near) goal[a][c] += each;
  }
}

}  // namespace

std::vector<Eigen::VectorXd> goal_indicator(const Problem& problem, const ddm::ContactSystem& system,
                                            const PressureEstimate& pe, const std::vector<IndicatorResult>& eta,
                                            parallel::TaskRunner& runner) {
  const ddm::Pressures& dz = pe.correction;
  const size_t n = problem.bodies.size();
  std::vector<Eigen::VectorXd> goal(n);
  const ddm::Displacements loads = system.loads_from_pressures(dz);
  const parallel::BodyShare share{[&](size_t a, parallel::Packer& p) { p.put(goal[a]); },
                                  [&](size_t a, parallel::Unpacker& in) { goal[a] = in.get_vector(); }};
  runner.run_bodies(
      n,
      [&](size_t a) {
        if (a >= eta.size() || eta[a].error2_cell.size() != problem.bodies[a].mesh.num_cells()) return;
        const Body& body = problem.bodies[a];
        // phi: the body's response to dz's contact traction alone (prescribed values 0, no loads of its own).
        const Eigen::VectorXd phi = system.body(a).solve_homogeneous(loads[a]);
        const IndicatorResult dual = zz_indicator(body, system.body(a), phi);
        const double nu = body.material.nu;
        const double modulus = problem.model.plane == Plane::strain ? body.material.E / (1 - nu * nu) : body.material.E;
        goal[a] = (eta[a].error2_cell.cwiseProduct(dual.error2_cell)).cwiseSqrt() / modulus;
      },
      share);
  add_edge_shares(problem, pe, goal);
  return goal;
}

BulkMarking bulk_marking(const Problem& problem, const std::vector<Eigen::VectorXd>& goal, double theta,
                         int max_level) {
  struct Term {
    double value;
    size_t body;
    int cell;
  };
  BulkMarking out;
  out.cells.resize(goal.size());
  std::vector<Term> terms;
  double total = 0.0;
  for (size_t a = 0; a < goal.size(); ++a)
    for (Eigen::Index c = 0; c < goal[a].size(); ++c) {
      if (!(goal[a][c] > 0.0)) continue;
      terms.push_back({goal[a][c], a, static_cast<int>(c)});
      total += goal[a][c];
    }
  // Ties (the cells sharing an edge's share) in body and cell order, so that the marking does not depend on the
  // sort's implementation.
  std::sort(terms.begin(), terms.end(), [](const Term& x, const Term& y) {
    if (x.value != y.value) return x.value > y.value;
    return x.body != y.body ? x.body < y.body : x.cell < y.cell;
  });
  double sum = 0.0;
  for (const Term& t : terms) {
    if (sum >= theta * total) break;
    sum += t.value;
    if (problem.bodies[t.body].mesh.level[static_cast<size_t>(t.cell)] >= max_level)
      out.level_limit_hit = true;  // its share stays unrefined: the set is the one without the limit
    else
      out.cells[t.body].push_back(t.cell);
  }
  return out;
}

}  // namespace contact::adapt

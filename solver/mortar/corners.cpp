#include "corners.hpp"

#include <cmath>
#include <string>

namespace contact::mortar {

namespace {

// Whether the pair between bodies a and b (either its slave) has a slave edge ending at x where that end drops its
// multiplier altogether (a corner against a master edge facing a third body): the loop of three bodies at x is then
// broken there, and the other two pairs keep all their rows.
bool crosspoint_between(const Problem& problem, const ContactIndex& index, int a, int b, const Eigen::Vector2d& x,
                        double tolerance) {
  for (const int k : index.touching(a, b)) {
    const ContactPair& q = problem.contacts[static_cast<size_t>(k)];
    if (!((q.slave_body == a && q.master_body == b) || (q.slave_body == b && q.master_body == a))) continue;
    const auto& mesh = problem.bodies[static_cast<size_t>(q.slave_body)].mesh;
    const std::vector<int> nodes = mesh.edge_set_nodes(q.slave_edge);
    if (nodes.size() < 2 || mesh.edge_set_closed(q.slave_edge)) continue;  // a closed loop has no ends
    for (int end : {nodes.front(), nodes.back()}) {
      if ((mesh.nodes[static_cast<size_t>(end)] - x).norm() > tolerance) continue;
      const auto corners = slave_corners(problem, index, q, nodes, false);
      const auto c = corners.find(end);
      if (c != corners.end() && c->second.third_body && c->second.friction) return true;
    }
  }
  return false;
}

}  // namespace

std::map<int, std::array<bool, 2>> prescribed_components(const Body& body) {
  std::map<int, std::array<bool, 2>> out;
  for (const auto& bc : body.boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(body.mesh, bc)) {
      auto& p = out[node];
      p[0] = p[0] || bc.ux.has_value();
      p[1] = p[1] || bc.uy.has_value();
    }
  }
  return out;
}

bool normal_is_prescribed(const std::array<bool, 2>& p, const Eigen::Vector2d& n) {
  if (p[0] && p[1]) return true;
  const double cos10 = 0.984807753;
  return (p[0] && std::abs(n.x()) >= cos10) || (p[1] && std::abs(n.y()) >= cos10);
}

std::map<int, Corner> slave_corners(const Problem& problem, const ContactIndex& index, const ContactPair& pair,
                                    const std::vector<int>& nodes, bool look_for_broken_loops) {
  std::map<int, Corner> out;
  const auto& mesh = problem.bodies[static_cast<size_t>(pair.slave_body)].mesh;
  // A closed loop has no ends, so no corners: it meets another edge only where that edge ends on it, and there
  // the boundary runs on along the loop.
  if (nodes.size() < 2 || mesh.edge_set_closed(pair.slave_edge)) return out;
  auto meet = [&](const std::string& edge, bool third_body, bool friction, int other_master) {
    const std::vector<int> others = mesh.edge_set_nodes(edge);
    if (others.size() < 2 || mesh.edge_set_closed(edge)) return;
    for (size_t end : {size_t{0}, nodes.size() - 1})
      for (size_t j : {size_t{0}, others.size() - 1}) {
        if (others[j] != nodes[end]) continue;
        const size_t next = j == 0 ? 1 : j - 1;
        const Eigen::Vector2d x = mesh.nodes[static_cast<size_t>(others[j])];
        const double h = (mesh.nodes[static_cast<size_t>(others[next])] - x).norm();
        // Two slave edges of this body at a corner: the loop through the two masters is broken already where the
        // pair between those masters drops its multiplier at this point (the top of a head joint seen from the
        // brick on the other side: the brick's bed joint keeps its friction row at its toe, where the pressure is).
        if (!third_body && look_for_broken_loops && other_master >= 0 &&
            crosspoint_between(problem, index, pair.master_body, other_master, x, 1e-6 * h))
          continue;
        Corner& c = out[nodes[end]];
        c.tangent = (mesh.nodes[static_cast<size_t>(others[next])] - x).normalized();
        c.third_body = c.third_body || third_body;
        c.friction = c.friction || friction || pair.friction.active();
      }
  };
  // The pairs with this slave body on either side, in the job's order (as every pair was asked before the index).
  for (const int k : index.touching(pair.slave_body, pair.slave_body)) {
    const ContactPair& other = problem.contacts[static_cast<size_t>(k)];
    if (other.slave_body == pair.slave_body && other.slave_edge != pair.slave_edge)
      meet(other.slave_edge, false, other.friction.active(), other.master_body);
    if (other.master_body == pair.slave_body && other.master_edge != pair.slave_edge)
      meet(other.master_edge, other.slave_body != pair.master_body, other.friction.active(), -1);
  }
  return out;
}

bool turns(const Eigen::Vector2d& own, const Eigen::Vector2d& other) {
  return std::abs(own.x() * other.y() - own.y() * other.x()) > 0.17364817766;  // sin 10 degrees
}

}  // namespace contact::mortar

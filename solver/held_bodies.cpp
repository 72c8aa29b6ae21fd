#include "held_bodies.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <vector>

namespace contact {

namespace {

// The rows n . m(x) of the three rigid motions m about `center` (translation in x, in y, rotation scaled by
// `radius`) for a point x held along the direction n.
Eigen::RowVector3d held_row(const Eigen::Vector2d& x, const Eigen::Vector2d& n, const Eigen::Vector2d& center,
                            double radius) {
  const Eigen::Vector2d r = (x - center) / radius;
  return {n.x(), n.y(), r.x() * n.y() - r.y() * n.x()};
}

// The rows of body b's prescribed displacement components and of its contact nodes in contact.
std::vector<Eigen::RowVector3d> held_rows(const Problem& problem, const Step& step, size_t b, double radius) {
  const BodyField& body = step.bodies[b];
  std::vector<Eigen::RowVector3d> rows;
  for (const auto& bc : problem.bodies[b].boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(body.mesh, bc)) {
      const Eigen::Vector2d x = body.mesh.nodes[static_cast<size_t>(node)];
      if (bc.ux) rows.push_back(held_row(x, {1, 0}, body.rigid_center, radius));
      if (bc.uy) rows.push_back(held_row(x, {0, 1}, body.rigid_center, radius));
    }
  }
  for (const auto& pair : step.pairs) {
    if (pair.slave_body != body.name && pair.master_body != body.name) continue;
    for (Eigen::Index i = 0; i < pair.active.size(); ++i) {
      if (pair.active[i] == 0 || !(pair.normal.row(i).squaredNorm() > 0)) continue;
      rows.push_back(
          held_row(pair.position.row(i).transpose(), pair.normal.row(i).transpose(), body.rigid_center, radius));
      // A node whose friction carries a force holds along its tangent too: one that sticks, and one that slips
      // pressed (its friction force balances the loads though its slip is free: a brick that slides at both its
      // bed joints is in equilibrium at any slip, and the monolithic reference takes the least motion).
      const bool sticks = pair.stick.size() == pair.active.size() && pair.stick[i] != 0;
      const bool rubs = pair.tangential_traction.size() == pair.active.size() && pair.tangential_traction[i] != 0.0;
      if (sticks || rubs)
        rows.push_back(
            held_row(pair.position.row(i).transpose(), pair.tangent.row(i).transpose(), body.rigid_center, radius));
    }
  }
  return rows;
}

// Whether the rows leave a rigid motion free: fewer than three independent ones.
bool leaves_a_motion_free(const std::vector<Eigen::RowVector3d>& rows) {
  if (rows.size() < 3) return true;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t k = 0; k < rows.size(); ++k) A.row(static_cast<Eigen::Index>(k)) = rows[k];
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::MatrixXd>(A).singularValues();
  return !(s[2] > 1e-8 * s[0]);
}

std::string refusal(const Problem& problem, const BodyField& body) {
  std::string motions, pairs;
  for (const auto& m : body.free_motions) motions += (motions.empty() ? "" : ", ") + m;
  for (const auto& c : problem.contacts) {
    const auto& slave = problem.bodies[static_cast<size_t>(c.slave_body)].name;
    const auto& master = problem.bodies[static_cast<size_t>(c.master_body)].name;
    if (slave == body.name || master == body.name) pairs += (pairs.empty() ? "'" : ", '") + c.name + "'";
  }
  return "body '" + body.name + "' floats (" + motions + " free) and no contact holds it: its contact" +
         (pairs.find(',') != std::string::npos ? "s " : " ") + pairs +
         " would have to pull (the loads move it away), or it is open at the solution; give it displacement "
         "conditions that hold it, or load it towards its contacts";
}

}  // namespace

std::string unheld_floating_bodies(const Problem& problem, const Step& step) {
  std::string text;
  for (size_t b = 0; b < step.bodies.size() && b < problem.bodies.size(); ++b) {
    const BodyField& body = step.bodies[b];
    if (body.free_motions.empty()) continue;
    double radius = 0;
    for (const auto& x : body.mesh.nodes) radius = std::max(radius, (x - body.rigid_center).norm());
    if (!(radius > 0)) continue;
    if (leaves_a_motion_free(held_rows(problem, step, b, radius)))
      text += (text.empty() ? "" : "; ") + refusal(problem, body);
  }
  return text;
}

}  // namespace contact

#include "large_motion.hpp"

#include "figures.hpp"

#include <cmath>
#include <string>

namespace contact::check {

namespace {

struct Motion {
  double size = 0.0;     // bounding box diagonal
  double largest = 0.0;  // the largest nodal displacement
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  double rotation = 0.0;  // the least-squares rigid rotation of the nodes about their centroid (radians)
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();  // the nodes' mean displacement
};

Motion motion_of(const BodyField& b) {
  Motion m;
  const auto& nodes = b.mesh.nodes;
  const Eigen::Index n = std::min<Eigen::Index>(static_cast<Eigen::Index>(nodes.size()), b.displacement.rows());
  if (n == 0) return m;
  Eigen::Vector2d lo = nodes.front(), hi = nodes.front(), centre = Eigen::Vector2d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d& x = nodes[static_cast<size_t>(i)];
    lo = lo.cwiseMin(x), hi = hi.cwiseMax(x), centre += x;
    m.translation += b.displacement.row(i).transpose();
    const double u = b.displacement.row(i).norm();
    if (u > m.largest) m.largest = u, m.at = x;
  }
  m.size = (hi - lo).norm();
  centre /= static_cast<double>(n);
  m.translation /= static_cast<double>(n);
  // Rotation: minimises sum |u_i - t - theta k x r_i|^2, r_i = x_i - centre: theta = sum r x (u - t) / sum |r|^2.
  double moment = 0.0, inertia = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d r = nodes[static_cast<size_t>(i)] - centre;
    const Eigen::Vector2d u = b.displacement.row(i).transpose() - m.translation;
    moment += r.x() * u.y() - r.y() * u.x();
    inertia += r.squaredNorm();
  }
  m.rotation = inertia > 0 ? moment / inertia : 0.0;
  return m;
}

constexpr const char* kVoid =
    ": the model is linear and small-displacement (strains from the displacements' first derivatives, contact on "
    "the drawn geometry), so this answer is not to be trusted there. Check the units of the loads and of E, the "
    "supports, and that the body is drawn where it rests; a body that rolls or tips (a mechanism its contacts do not "
    "stop) moves this far in a linear model";

}  // namespace

std::vector<Warning> motion_warnings(const Problem& problem, const Step& step) {
  std::vector<Warning> out;
  for (size_t a = 0; a < step.bodies.size() && a < problem.bodies.size(); ++a) {
    const BodyField& b = step.bodies[a];
    const Motion m = motion_of(b);
    if (!(m.size > 0)) continue;
    const std::string pointer = "/bodies/" + std::to_string(a), name = "body '" + b.name + "'";
    std::string what;
    if (!std::isfinite(m.largest) || m.largest > kLargeDisplacement * m.size)
      what = "moves by up to " + number(m.largest) + " (at " + point(m.at) + "), " + number(m.largest / m.size) +
             " of its size " + number(m.size) + " (more than " + number(kLargeDisplacement) + ")";
    if (std::abs(m.rotation) > kLargeRotation)
      what += (what.empty() ? "" : ", and ") + std::string("turns by ") + number(m.rotation) + " rad (more than " +
              number(kLargeRotation) + ")";
    if (!what.empty()) {
      out.push_back({pointer, name + " " + what + kVoid});
      continue;
    }
    if (!b.free_motions.empty() && m.translation.norm() > kLargeRigidTranslation * m.size)
      out.push_back({pointer, name + " is held by its contacts alone and moved as a rigid body by " +
                                  number(m.translation.norm()) + ", " + number(m.translation.norm() / m.size) +
                                  " of its size " + number(m.size) + " (more than " + number(kLargeRigidTranslation) +
                                  "): more than its deformation explains, so it closed a gap or fell onto its "
                                  "support. The linear model takes that motion at face value; draw the body where it "
                                  "rests"});
  }
  return out;
}

}  // namespace contact::check

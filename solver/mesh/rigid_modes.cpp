#include "rigid_modes.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace contact::mesh {

namespace {

constexpr double kNullTolerance = 1e-10;  // relative to the largest singular value
constexpr double kNegligible = 1e-8;      // a component of a unit vector this small counts as zero

// Four significant digits; values that are round-off next to `scale` print as 0.
std::string format_coordinate(double v, double scale) {
  std::ostringstream os;
  os << std::setprecision(4) << (std::abs(v) < 1e-9 * scale ? 0.0 : v);
  return os.str();
}

// A unit translation (a, b) in words, sign chosen so the first non-zero component is positive.
std::string describe_translation(Eigen::Vector2d d) {
  d.normalize();
  if (std::abs(d.y()) < kNegligible) return "translation in x";
  if (std::abs(d.x()) < kNegligible) return "translation in y";
  if (d.x() < 0) d = -d;
  return "translation along (" + format_coordinate(d.x(), 1.0) + ", " + format_coordinate(d.y(), 1.0) + ")";
}

}  // namespace

std::vector<std::string> free_rigid_motions(const Mesh& mesh, const std::vector<PrescribedDof>& prescribed) {
  return free_rigid_modes(mesh, prescribed).names;
}

namespace {

// The body's centroid (area-weighted cell centres) and the distance to its farthest node, which scales the
// rotation mode to unit size so that the three modes are comparable in the SVD.
void centroid_and_radius(const Mesh& mesh, Eigen::Vector2d& centroid, double& radius) {
  centroid = Eigen::Vector2d::Zero();
  double area = 0.0;
  for (int c = 0; c < mesh.num_cells(); ++c) {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    const auto& cell = mesh.cells[static_cast<size_t>(c)];
    for (int node : cell) centre += mesh.nodes[static_cast<size_t>(node)] / cell.size();
    const double a = std::abs(mesh.cell_area(c));
    centroid += a * centre;
    area += a;
  }
  if (area > 0) centroid /= area;
  radius = 0.0;
  for (const auto& p : mesh.nodes) radius = std::max(radius, (p - centroid).norm());
  if (!(radius > 0)) radius = 1.0;
}

}  // namespace

RigidModes free_rigid_modes(const Mesh& mesh, const std::vector<PrescribedDof>& prescribed) {
  std::vector<HeldDirection> held;
  for (const auto& p : prescribed) held.push_back({p[0], p[1] == 0 ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 1)});
  return free_rigid_modes_along(mesh, held);
}

RigidModes free_rigid_modes_along(const Mesh& mesh, const std::vector<HeldDirection>& held) {
  Eigen::Vector2d centroid;
  double radius = 1.0;
  centroid_and_radius(mesh, centroid, radius);
  // Rows: the held directions; columns: the modes tx, ty, rot evaluated there along them.
  Eigen::MatrixXd modes(static_cast<Eigen::Index>(held.size()), 3);
  for (size_t k = 0; k < held.size(); ++k) {
    const Eigen::Vector2d r = (mesh.nodes[static_cast<size_t>(held[k].node)] - centroid) / radius;
    const Eigen::Vector2d rotation(-r.y(), r.x());
    const Eigen::Vector2d d = held[k].direction;
    modes.row(static_cast<Eigen::Index>(k)) << d.x(), d.y(), rotation.dot(d);
  }
  const bool none_held = held.empty();
  Eigen::MatrixXd null_space;  // 3 x k, orthonormal columns
  if (none_held) {
    null_space = Eigen::MatrixXd::Identity(3, 3);
  } else {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(modes, Eigen::ComputeFullV);
    const auto& sigma = svd.singularValues();
    Eigen::Index rank = 0;
    while (rank < sigma.size() && sigma(rank) > kNullTolerance * sigma(0)) ++rank;
    null_space = svd.matrixV().rightCols(3 - rank);
  }
  if (null_space.cols() == 0) return {};
  RigidModes out;
  out.modes.resize(2 * mesh.num_nodes(), null_space.cols());
  for (int node = 0; node < mesh.num_nodes(); ++node) {
    const Eigen::Vector2d r = (mesh.nodes[static_cast<size_t>(node)] - centroid) / radius;
    Eigen::Matrix<double, 2, 3> at;  // the three modes at this node
    at << 1.0, 0.0, -r.y(), 0.0, 1.0, r.x();
    out.modes.middleRows(2 * node, 2) = at * null_space;
  }

  // Describe the null space in a canonical basis (the SVD's own basis mixes modes arbitrarily): its part with
  // no rotation is spanned by translations, and at most one further direction rotates.
  std::vector<std::string> free;
  const Eigen::RowVectorXd rotation_part = null_space.row(2);
  Eigen::MatrixXd translations = null_space;  // columns spanning the rotation-free part (after projection)
  std::string rotation_text;
  if (rotation_part.norm() > kNegligible) {
    const Eigen::Vector3d w = null_space * rotation_part.transpose() / rotation_part.norm();
    translations = null_space - w * (w.transpose() * null_space);
    if (null_space.cols() == 1) {
      // The only free motion: a rotation about the point where its displacement vanishes.
      const Eigen::Vector2d pivot = centroid + radius * Eigen::Vector2d(-w(1), w(0)) / w(2);
      const double scale = radius + centroid.norm();
      rotation_text =
          "rotation about (" + format_coordinate(pivot.x(), scale) + ", " + format_coordinate(pivot.y(), scale) + ")";
    } else {
      rotation_text = "rotation";
    }
  }
  // The translation part has dimension 0, 1 or 2 (columns are dependent after the projection above).
  Eigen::JacobiSVD<Eigen::MatrixXd> tsvd(translations.topRows(2), Eigen::ComputeFullU);
  Eigen::Index tdim = 0;
  while (tdim < tsvd.singularValues().size() && tsvd.singularValues()(tdim) > 1e-6) ++tdim;
  if (tdim == 2) {
    free.push_back("translation in x");
    free.push_back("translation in y");
  } else if (tdim == 1) {
    free.push_back(describe_translation(tsvd.matrixU().col(0)));
  }
  if (!rotation_text.empty()) free.push_back(rotation_text);
  out.names = std::move(free);
  return out;
}

}  // namespace contact::mesh

#include "rigid_modes.hpp"

#include <Eigen/SVD>

#include <cmath>
#include <sstream>

namespace contact::fem {

std::vector<std::string> free_rigid_modes(const mesh::Mesh& mesh, const std::vector<bool>& prescribed) {
  // Rigid modes about the centroid, scaled to unit size: t_x, t_y and the rotation (-(y - cy), x - cx) / L.
  const Eigen::Vector2d lo = mesh.bbox_min(), hi = mesh.bbox_max();
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  const double size = std::max((hi - lo).norm(), 1e-300);
  std::vector<Eigen::RowVector3d> rows;
  for (size_t dof = 0; dof < prescribed.size(); ++dof) {
    if (!prescribed[dof]) continue;
    const Eigen::Vector2d p = mesh.nodes[dof / 2] - centre;
    if (dof % 2 == 0)
      rows.emplace_back(1.0, 0.0, -p.y() / size);
    else
      rows.emplace_back(0.0, 1.0, p.x() / size);
  }
  Eigen::Matrix3d null_basis = Eigen::Matrix3d::Identity();
  int n_null = 3;
  if (!rows.empty()) {
    Eigen::MatrixXd R(static_cast<Eigen::Index>(rows.size()), 3);
    for (size_t i = 0; i < rows.size(); ++i) R.row(static_cast<Eigen::Index>(i)) = rows[i];
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
    const auto& sv = svd.singularValues();
    const double tol = 1e-10 * std::max(sv[0], 1e-300);
    int rank = 0;
    for (int i = 0; i < sv.size(); ++i)
      if (sv[i] > tol) ++rank;
    n_null = 3 - rank;
    null_basis = svd.matrixV();
    // Null vectors are V's last columns.
    Eigen::Matrix3d tmp = Eigen::Matrix3d::Zero();
    for (int k = 0; k < n_null; ++k) tmp.col(k) = null_basis.col(rank + k);
    null_basis = tmp;
  }
  std::vector<std::string> modes;
  if (n_null == 3) return {"translation in x", "translation in y", "rotation"};
  for (int k = 0; k < n_null; ++k) {
    const Eigen::Vector3d v = null_basis.col(k).normalized();
    if (std::abs(v[2]) > 1e-6) {
      modes.emplace_back("rotation");
    } else if (std::abs(v[1]) < 1e-9) {
      modes.emplace_back("translation in x");
    } else if (std::abs(v[0]) < 1e-9) {
      modes.emplace_back("translation in y");
    } else {
      std::ostringstream os;
      os << "translation along (" << v[0] << ", " << v[1] << ")";
      modes.push_back(os.str());
    }
  }
  return modes;
}

}  // namespace contact::fem

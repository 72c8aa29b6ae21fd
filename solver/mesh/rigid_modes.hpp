// Which rigid motions a body's prescribed displacement components leave free.
//
// Why it matters: the DDM solves each body on its own with contact forces as loads, so each body's stiffness
// matrix must be non-singular by its own displacement conditions; contact never restrains a body. A body that
// can still translate or rotate would only fail later, inside the factorisation, with a message no user can act
// on; this check names the free motion instead.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "contact/mesh.hpp"

#include <Eigen/Core>

namespace contact::mesh {

// One prescribed displacement component: node index and component (0 = x, 1 = y).
using PrescribedDof = std::array<int, 2>;

// The free rigid motions of `mesh` under the prescribed components, described in words: "translation in x",
// "translation in y", "translation along (0.6, 0.8)", "rotation" or, when it is the only free motion,
// "rotation about (x, y)". Empty when the body is restrained. Method: the three rigid modes about the
// centroid (two unit translations and a rotation scaled to unit size at the farthest node) evaluated at the
// prescribed components; their null space, by SVD with a relative tolerance of 1e-10, holds the free motions.
std::vector<std::string> free_rigid_motions(const Mesh& mesh, const std::vector<PrescribedDof>& prescribed);

// The same free motions as vectors: `modes` is n_dofs x k (dof = 2 node + component), its columns an orthonormal
// basis (in the coefficients of the three modes about the centroid, the rotation scaled to unit size at the
// farthest node) of the rigid motions that vanish at every prescribed component; `names` describes them as above.
// k = 0 for a restrained body. Each column vanishes, to round-off, at the prescribed components.
struct RigidModes {
  Eigen::MatrixXd modes;
  std::vector<std::string> names;
};
RigidModes free_rigid_modes(const Mesh& mesh, const std::vector<PrescribedDof>& prescribed);

// The same for motions held along arbitrary directions at nodes (a support's component, or a frictionless
// contact's normal, which stops a node only along it).
struct HeldDirection {
  int node = 0;
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
};
RigidModes free_rigid_modes_along(const Mesh& mesh, const std::vector<HeldDirection>& held);

}  // namespace contact::mesh

// Which rigid motions a body's prescribed displacement components leave free. Each body is solved alone in
// the Neumann DDM (paper eq. (16)), so each must be restrained by its own supports: a free rigid mode makes
// the body's stiffness singular.
#pragma once

#include "../mesh/mesh.hpp"

#include <string>
#include <vector>

namespace contact::fem {

// prescribed[dof] is true where the displacement component dof = 2 node + c is prescribed. Returns one
// description per free rigid mode ("translation in x", "translation in y", "translation along (a, b)",
// "rotation"); empty if the body is restrained.
std::vector<std::string> free_rigid_modes(const mesh::Mesh& mesh, const std::vector<bool>& prescribed);

}  // namespace contact::fem

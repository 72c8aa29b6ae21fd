// The library's version, the one recorded in result files and reported by the programs. Included by
// contact/solve.hpp.
#pragma once

namespace contact {

// The version string recorded in result files.
const char* solver_version();

}  // namespace contact

// The friction rows of a system's contact pairs (linalg::FrictionRow: a tangential multiplier paired with its
// normal one), built in one place for every frictional solver: one per contact node of each friction pair, except
// where there may be none (q = 0 there):
//   * a row that pair.cpp dropped at a corner where friction would tie three bodies in a loop
//     (PairDiscretization::tangential_dropped);
//   * a row no body can move (`movable` false: both sides' tangential motion prescribed, on a symmetry line), whose
//     traction goes into the supports.
#pragma once

#include <functional>
#include <vector>

#include "../linalg/friction_sets.hpp"
#include "contact_system.hpp"

namespace contact::ddm {

// normal_offset(k), tangential_offset(k): where pair k's normal and tangential rows start in the solver's
// multipliers (tangential_offset < 0: the pair has none); movable(t): whether the tangential unknown t can move.
std::vector<linalg::FrictionRow> friction_rows(const ContactSystem& system,
                                               const std::function<Eigen::Index(size_t)>& normal_offset,
                                               const std::function<Eigen::Index(size_t)>& tangential_offset,
                                               const std::function<bool(Eigen::Index)>& movable);

// Every tangential unknown of the friction pairs (size: the solver's multipliers), those without a friction row
// included: the Newton fixes those at q = 0 rather than taking them for normal rows.
std::vector<char> tangential_unknowns(const ContactSystem& system, Eigen::Index size,
                                      const std::function<Eigen::Index(size_t)>& tangential_offset);

}  // namespace contact::ddm

// Where a pair's contact zone begins and ends along the slave edge, between nodes.
//
// The zone's edge lies between the last node in contact and the first open one. Near a smooth edge (Hertz, any
// curved contact) the pressure falls like the square root of the distance to the edge, so p^2 is linear there:
// the line through (s_{j-1}, p_{j-1}^2) and (s_j, p_j^2) of the last two nodes in contact reaches zero at the edge,
// taken within [s_j, s_{j+1}]. Where the pressure does not fall towards the edge (a punch's corner, a single node in
// contact) nothing is extrapolated: the edge is the last node in contact. With no open node beyond (the contact
// reaches the end of the slave edge) the edge is that end node.
//
// A reading of a pair's nodal pressures, not part of the mortar discretisation: the step summary (result.cpp,
// StepSummary's contact_begin and contact_end) and the iteration reports (ddm/system_fields.cpp, PairReport's
// extent_begin and extent_end) both take it.
#pragma once

#include <Eigen/Core>

namespace contact {

struct ContactExtent {
  double begin = 0.0, end = 0.0;  // arc lengths along the slave edge (both 0 without contact)
  bool any = false;
};

// On a closed slave edge (loop_length > 0: the loop's length, its closing segment included; arc from its start)
// there are no ends: the zone is the shortest stretch of the loop that holds every node in contact, the loop less
// its longest open stretch, extrapolated at both edges as above with the neighbours taken round the loop. A zone
// across the start has begin > end (it runs from begin through the start to end); a loop in contact all round is
// [0, loop_length].
//
// arc: the slave nodes' arc lengths in order; pressure: their nodal pressures (> 0 in contact).
ContactExtent contact_extent(const Eigen::VectorXd& arc, const Eigen::VectorXd& pressure, double loop_length = 0.0);

}  // namespace contact

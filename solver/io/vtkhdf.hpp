// Internal to solver/io: the /VTKHDF group, the ParaView view of a result file's final step.
#pragma once

#include "contact/result.hpp"

#include <hdf5.h>

namespace contact::io {

// The final step as a VTKHDF 1.0 UnstructuredGrid (what ParaView 5.11 reads): one partition per body (quadrilaterals
// and triangles), then one per contact pair (the slave polyline as line cells, with pressure, gap and active per
// point).
void write_vtkhdf(hid_t file, const Step& last);

}  // namespace contact::io

// /collapse: a collapse analysis's answer (Result::collapse; docs/results-format.md, "/collapse"), written only for
// a job that asks for one and read back into ResultFile::collapse (analysed false when the group is absent).
#pragma once

#include "contact/result.hpp"

#include <hdf5.h>

namespace contact::io {

void write_collapse(hid_t file, const CollapseResult& c);
void read_collapse(hid_t file, CollapseResult& c);

}  // namespace contact::io

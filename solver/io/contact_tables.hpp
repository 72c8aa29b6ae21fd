// Internal to solver/io: a step's contact pairs as tables (/steps/<k>/contacts, format version 3,
// docs/results-format.md): every pair's slave nodes one after the other in one dataset per quantity, with the
// pairs' row offsets, and every pair's scalars in one dataset each.
//
// Why tables: a wall of 4,129 bricks has 12,192 pairs. As a group per pair (format version 2) with its 16 datasets
// and 12 attributes, a step was 200,000 HDF5 objects and took 4.5 s to write, a fifth of the whole frictional run;
// HDF5 spends some 15 us of bookkeeping on each object whatever its size (measured with dense and compact
// attribute storage, compact datasets, larger metadata caches: no setting changes it). As tables it is 40 datasets.
#pragma once

#include "contact/result.hpp"

#include <hdf5.h>

#include <string>
#include <vector>

namespace contact::io {

// Writes /steps/<k>/contacts into the step group `step`; `where` ("step 3") prefixes the errors, which name the
// pair and the field whose row count is wrong.
void write_contact_tables(hid_t step, const Step& s, const std::string& where);

// Reads the pairs `names` (in that order) of a step's contacts group: the tables of version 3, or a group per pair
// (version 2 and before).
std::vector<PairField> read_contact_tables(hid_t contacts, const std::vector<std::string>& names, int format_version);

}  // namespace contact::io

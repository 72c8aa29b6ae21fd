// What of an internal error message a client may see.
#pragma once

#include <string>

namespace contactd {

// A public version of an error message: hexadecimal addresses (HDF5 prints "buf = 0x7fb8...") are masked and
// `data_dir` is written "<data-dir>". The full text goes to the log only.
std::string public_message(const std::string& text, const std::string& data_dir);

}  // namespace contactd

// Internal to solver/io: the XDMF sidecar built a step at a time, so that a result file written as the steps are
// solved (ResultStream) gets its sidecar without keeping the steps' fields. write_xdmf builds one from a Result.
#pragma once

#include "contact/result.hpp"

#include <string>
#include <vector>

namespace contact::io::detail {

class XdmfSeries {
 public:
  // `hdf_file_name`: the result file as the sidecar names it (normally the bare name: both lie side by side).
  explicit XdmfSeries(std::string hdf_file_name);
  // The grids of `step` (one per body and per contact pair), as /steps/<the number of steps added before>.
  void add(const Step& step);
  // Writes the sidecar atomically (contact::replace_file_atomically); throws std::runtime_error naming it.
  void write(const std::string& xmf_path) const;

 private:
  std::string hdf_;                   // escaped
  std::vector<std::string> grids_;    // per step: its body and pair grids
  std::vector<double> load_factors_;  // per step
};

}  // namespace contact::io::detail

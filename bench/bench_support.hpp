// Helpers shared by the benchmark programs: wall time, and parsing a job with a large DOF limit (exiting with
// the validation errors if the job is bad).
#pragma once

#include "contact/job.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace contact::bench {

inline double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

inline Problem parse_or_exit(const nlohmann::json& job) {
  job::Limits limits;
  limits.max_dofs = 10'000'000;
  limits.mesh_directory = std::string(CONTACT_SOURCE_DIR) + "/api/examples";  // the examples' Gmsh files
  auto r = job::parse(job, limits);
  if (!r.ok()) {
    std::fprintf(stderr, "%s", job::format_errors(r.errors).c_str());
    std::exit(2);
  }
  return std::move(*r.problem);
}

// "128,256,512" -> {128, 256, 512} (a command-line list).
inline std::vector<int> parse_int_list(const std::string& list) {
  std::vector<int> out;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::stoi(item));
  return out;
}

}  // namespace contact::bench

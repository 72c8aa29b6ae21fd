#include "contact/result_file.hpp"

namespace contact::io {

namespace {
constexpr double kPerNode = 280, kPerBody = 25e3, kPerPair = 2e3;  // bytes a step (result_file.hpp)
}

double estimated_result_bytes(double nodes, double bodies, double pairs, double kept_steps) {
  return (kept_steps + 1) * (kPerNode * nodes + kPerBody * bodies + kPerPair * pairs);
}

double kept_nodes_within(double bytes, double bodies, double pairs, double kept_steps) {
  const double metadata = (kept_steps + 1) * (kPerBody * bodies + kPerPair * pairs);
  return bytes > metadata ? (bytes - metadata) / (2 * kPerNode) : 0.0;
}

}  // namespace contact::io

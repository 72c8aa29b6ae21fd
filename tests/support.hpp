// Helpers shared by the tests that run whole jobs: the job examples and a quiet solve.
#pragma once

#include "job/job.hpp"
#include "solve.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace contact::testing {

// api/examples/<name> as JSON.
inline nlohmann::json example(const std::string& name) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/" + name);
  EXPECT_TRUE(in.good()) << name;
  return nlohmann::json::parse(in);
}

// Parses (the test fails on validation errors) and solves without observer or cancellation. Gmsh mesh files are
// read from api/examples/, where the examples' are.
inline Result run(const nlohmann::json& job) {
  job::Limits limits;
  limits.mesh_directory = std::string(CONTACT_SOURCE_DIR) + "/api/examples";
  auto parsed = job::parse(job, limits);
  EXPECT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  if (!parsed.ok()) return {};
  Observer quiet;
  CancelToken cancel;
  return solve(*parsed.problem, quiet, cancel);
}

// The half-width of a Hertz contact from its nodal pressures: p^2 = p0^2 - (p0/a)^2 x^2 is linear in x^2, so a
// least-squares line through (x^2, p^2) of the nodes in contact, the last two at the edge (where the discrete
// profile rounds off) left out, gives a = sqrt(-intercept / slope). x is the distance from the symmetry line x = 0.
inline double hertz_half_width(const PairField& pair) {
  std::vector<std::pair<double, double>> points;
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j)
    if (pair.pressure[j] > 0) points.emplace_back(pair.position(j, 0), pair.pressure[j]);
  std::sort(points.begin(), points.end());
  EXPECT_GT(points.size(), 8u);
  if (points.size() < 3) return std::nan("");
  points.resize(points.size() - 2);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& [x, p] : points) {
    const double X = x * x, Y = p * p;
    sx += X, sy += Y, sxx += X * X, sxy += X * Y;
  }
  const double n = static_cast<double>(points.size());
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), intercept = (sy - slope * sx) / n;
  return std::sqrt(-intercept / slope);
}

}  // namespace contact::testing

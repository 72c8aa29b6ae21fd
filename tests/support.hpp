// Helpers shared by the tests that run whole jobs: the job examples and a quiet solve.
#pragma once

#include "contact/job.hpp"
#include "contact/solve.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>
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

// Parses a job (the test fails on validation errors; an empty Problem then). Gmsh mesh files are read from
// api/examples/, where the examples' are.
inline Problem parse_or_fail(const nlohmann::json& job) {
  job::Limits limits;
  limits.mesh_directory = std::string(CONTACT_SOURCE_DIR) + "/api/examples";
  auto parsed = job::parse(job, limits);
  EXPECT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  return parsed.ok() ? std::move(*parsed.problem) : Problem{};
}

// Solves without observer or cancellation.
inline Result solve_quietly(const Problem& problem) {
  Observer quiet;
  CancelToken cancel;
  return solve(problem, quiet, cancel);
}

// Parses (the test fails on validation errors) and solves quietly.
inline Result run(const nlohmann::json& job) {
  const Problem problem = parse_or_fail(job);
  return problem.bodies.empty() ? Result{} : solve_quietly(problem);
}

// A cap held sideways at one corner and pulled off a base held at its bottom: a valid job (its flat contact could
// hold it), but the load pulls it away, so nothing holds it at the solution (a floating body that ends unheld).
inline nlohmann::json cap_pulled_off_base() {
  return nlohmann::json::parse(R"({
    "name": "cap",
    "bodies": [
      {"name": "cap", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 1], [1, 1], [1, 2], [0, 2]], "nx": 4, "ny": 4}},
       "boundary": [{"vertex": "bottom_left", "displacement": {"x": 0}}, {"edge": "top", "force": [0, 10]}]},
      {"name": "base", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "nx": 4, "ny": 4}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}
    ],
    "contacts": [{"slave": "cap.bottom", "master": "base.top"}]
  })");
}

// The largest absolute entry (0 for an empty matrix).
inline double max_abs(const Eigen::MatrixXd& m) { return m.size() ? m.cwiseAbs().maxCoeff() : 0.0; }

// The body of a step by name (throws if it has none).
inline const BodyField& body(const Step& s, const std::string& name) {
  for (const auto& b : s.bodies)
    if (b.name == name) return b;
  throw std::runtime_error("no body " + name);
}

// The Hertz half-width from a contact profile centred at x = 0: p^2 is linear in x^2
// (p^2 = p0^2 - (p0/a)^2 x^2), so a least-squares line of p^2 against x^2 through the nodes in contact, the last
// two (at the edge, where the discrete profile rounds off) left out, crosses zero at x = a. NaN with fewer than
// six nodes in contact.
inline double hertz_half_width(const PairField& pair) {
  std::vector<std::pair<double, double>> points;
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j)
    if (pair.pressure[j] > 0) points.emplace_back(pair.position(j, 0), pair.pressure[j]);
  std::sort(points.begin(), points.end());
  if (points.size() < 6) return std::nan("");
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

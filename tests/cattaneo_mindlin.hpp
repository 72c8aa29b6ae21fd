// Cattaneo-Mindlin (a cylinder pressed on a block, then pushed sideways: partial slip) for the friction tests and
// bench_adaptivity: the job, its meshes, and the measures against the theory (the stick zone's half-width, the
// tangential traction against Mindlin's, the pressure against Hertz's). Header-only, public headers only.
#pragma once

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace contact::testing {

// A cylinder (radius R = 60, arc from x = -30 to 30) on a block of the same material, both 60 wide and 30 deep,
// mirror images as nearly as a cylinder and a block can be, so that pressing them together makes no tangential
// traction (a half-space pair of one material does not slip under normal load; bodies of different shapes
// would). The cylinder's top is held at y = -0.05 (its rotation too); the tangential load is two point loads at
// its top corners, scaled per step by their history. The block's slave nodes (spacing 0.046) are as coarse as
// the cylinder's (0.041), so that every slave node carries a multiplier.
inline nlohmann::json cattaneo_job(const std::vector<double>& tangential) {
  const double y0 = 60 - std::sqrt(3600.0 - 900.0);
  nlohmann::json job = nlohmann::json::parse(R"({
    "name": "cattaneo",
    "bodies": [
      {"name": "block", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-30, -30], [30, -30], [30, 0], [-30, 0]], "nx": 1300, "ny": 40,
                          "grading": {"top": 60}}},
       "boundary": [{"edge": "bottom", "displacement": {"y": 0}}, {"vertex": "bottom_left", "displacement": {"x": 0}}]},
      {"name": "cylinder", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"nx": 1500, "ny": 40, "edges": {"bottom": {"arc": {"center": [0, 60], "radius": 60}}},
                          "grading": {"bottom": 60}}},
       "boundary": [{"edge": "top", "displacement": {"y": -0.05}},
                    {"vertex": "top_left", "force": [0.5, 0]}, {"vertex": "top_right", "force": [0.5, 0]}]}
    ],
    "contacts": [{"slave": "block.top", "master": "cylinder.bottom", "friction": {"coefficient": 0.3}}]
  })");
  job["bodies"][1]["mesh"]["block"]["corners"] = {{-30, y0}, {30, y0}, {30, 30}, {-30, 30}};
  job["loading"] = {{"factors", std::vector<double>(tangential.size(), 1.0)}};
  job["bodies"][1]["boundary"][1]["history"] = tangential;
  job["bodies"][1]["boundary"][2]["history"] = tangential;
  return job;
}

// Half the length of the stick zone: from the middle of the last sticking and the first slipping node on each side.
inline double stick_half_width(const PairField& p) {
  std::vector<std::pair<double, int>> nodes;
  for (Eigen::Index j = 0; j < p.position.rows(); ++j) nodes.emplace_back(p.position(j, 0), p.stick[j]);
  std::sort(nodes.begin(), nodes.end());
  size_t lo = nodes.size(), hi = 0;
  for (size_t j = 0; j < nodes.size(); ++j)
    if (nodes[j].second) lo = std::min(lo, j), hi = std::max(hi, j);
  if (lo > hi || lo == 0 || hi + 1 >= nodes.size()) return 0.0;
  return 0.25 * (nodes[hi].first + nodes[hi + 1].first - nodes[lo].first - nodes[lo - 1].first);
}

// The Cattaneo-Mindlin job on nx x ny cells per body (the cylinder's nx scaled by 15/13 as in cattaneo_job), graded
// towards the contact as cattaneo_job's or uniform, with the tangential load Q in a second load step.
inline nlohmann::json cattaneo_mesh(int nx, int ny, bool graded, double Q) {
  nlohmann::json job = cattaneo_job({0.0, Q});
  for (int b = 0; b < 2; ++b) {
    auto& block = job["bodies"][b]["mesh"]["block"];
    block["nx"] = b == 0 ? nx : nx * 15 / 13;
    block["ny"] = ny;
    if (!graded) block.erase("grading");
  }
  return job;
}

// The relative L2 error over |x| <= 1.5 a of a nodal profile (values at the slave nodes' x, piecewise linear
// between them, constant past the ends) against `exact`, on 15,000 intervals: the norm of the function the nodal
// values stand for, so that a node counts by the length it covers and the profile between nodes is measured too.
template <class Exact>
double profile_error(const PairField& p, const Eigen::VectorXd& values, double a, Exact exact) {
  std::vector<std::pair<double, double>> nodes;  // (x, value), sorted
  for (Eigen::Index j = 0; j < values.size(); ++j) nodes.emplace_back(p.position(j, 0), values[j]);
  std::sort(nodes.begin(), nodes.end());
  auto at = [&](double x) {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), std::make_pair(x, -HUGE_VAL));
    if (it == nodes.begin()) return nodes.front().second;
    if (it == nodes.end()) return nodes.back().second;
    const auto& [x1, v1] = *it;
    const auto& [x0, v0] = *(it - 1);
    return v0 + (v1 - v0) * (x - x0) / (x1 - x0);
  };
  double e2 = 0, r2 = 0;
  const int n = 15000;
  for (int i = 0; i <= n; ++i) {
    const double x = -1.5 * a + 3 * a * i / n, w = (i == 0 || i == n) ? 0.5 : 1.0, v = exact(x);
    e2 += w * std::pow(at(x) - v, 2);
    r2 += w * v * v;
  }
  return std::sqrt(e2 / r2);
}

// A Cattaneo-Mindlin step against the theory, with the step's own normal force P and tangential load Q: the stick
// zone's half-width c over a (c / a = sqrt(1 - Q / (mu P))) and the error of the tangential traction against
// Mindlin's (mu p(x) less the stick zone's mu p0 (c / a) sqrt(1 - x^2 / c^2)):
//  - traction_error: the relative L2 error of the nodal tractions' piecewise-linear profile (profile_error), as
//    the pressure's against Hertz's (hertz_pressure_error);
//  - nodal_traction_error: the root sum of squares at the nodes only, the measure until 2026-11-27. It samples
//    Mindlin's profile where the nodes happen to be, and the profile falls with an infinite slope just inside c:
//    a mesh with no node there misses that fall. So the nodal measure does not converge with the mesh. Graded
//    meshes: 400 x 12 2.1 % nodal, 7.7 % in L2; 1300 x 40 2.6 % and 3.4 %. The L2 error falls steadily: 7.7, 6.8,
//    6.0, 5.2, 4.1, 3.4 % from 400 x 12 to 1300 x 40.
struct MindlinFit {
  double ratio = 0, c_over_a = 0, theory = 0, traction_error = 0, nodal_traction_error = 0;
};

inline MindlinFit mindlin_fit(const PairField& p, double Q) {
  const double mu = 0.3, R = 60, E = 2.1e5, nu = 0.3;
  const double E_star = E / (2 * (1 - nu * nu));  // plane strain, both bodies alike
  MindlinFit fit;
  const double P = p.force;
  fit.ratio = Q / (mu * P);
  const double a = std::sqrt(4 * P * R / (M_PI * E_star)), p0 = 2 * P / (M_PI * a);
  const double c = a * std::sqrt(1 - fit.ratio);
  fit.c_over_a = stick_half_width(p) / a;
  fit.theory = c / a;
  const auto mindlin = [&](double x) {
    double q = mu * p0 * std::sqrt(std::max(0.0, 1 - x * x / (a * a)));
    if (std::abs(x) < c) q -= mu * p0 * (c / a) * std::sqrt(1 - x * x / (c * c));
    return q;
  };
  const Eigen::VectorXd traction = -p.tangential_traction;
  fit.traction_error = profile_error(p, traction, a, mindlin);
  double error = 0, norm = 0;
  for (Eigen::Index j = 0; j < p.position.rows(); ++j) {
    const double q = mindlin(p.position(j, 0));
    error += std::pow(traction[j] - q, 2);
    norm += q * q;
  }
  fit.nodal_traction_error = std::sqrt(error / norm);
  return fit;
}

// The relative L2 error of a step's contact pressure against Hertz's at the step's own normal force (the geometry
// of cattaneo_job), over |x| <= 1.5 a (past the edge the pressure is 0).
inline double hertz_pressure_error(const PairField& p) {
  const double R = 60, E_star = 2.1e5 / (2 * (1 - 0.3 * 0.3));
  const double a = std::sqrt(4 * p.force * R / (M_PI * E_star)), p0 = 2 * p.force / (M_PI * a);
  return profile_error(p, p.pressure, a, [&](double x) { return p0 * std::sqrt(std::max(0.0, 1 - x * x / (a * a))); });
}

}  // namespace contact::testing

// The Gmsh examples solved with the defaults, against mathematics: the flat patch on non-matching triangles (the
// exact linear field, also with hanging nodes), the cylinder on a mixed mesh against Hertz and against the
// quadrilateral version of the same problem, and the rounded punch (equilibrium, symmetry, refinement onto arcs).
#include "fem/body_solver.hpp"
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;  // the shared helpers (support.hpp)

namespace {

// flat_patch_gmsh: E = 2.1e5, nu = 0.3, plane strain, both blocks 1 high, the top pressed down by 0.001, the
// bottom held in y and the left in x. Exact: eps_yy = -0.0005 everywhere (s_xx = 0, eps_zz = 0), so
// u_y = eps_yy (y + 1), u_x = -nu / (1 - nu) eps_yy x, and the pressure is E / (1 - nu^2) * 0.0005.
void expect_exact_flat_patch(const Result& r, const std::string& what) {
  ASSERT_TRUE(r.converged) << what << ": " << r.message;
  const double E = 2.1e5, nu = 0.3, eyy = -0.0005, exx = -nu / (1 - nu) * eyy, p = E / (1 - nu * nu) * 0.0005;
  const Step& s = r.steps.back();
  for (const auto& b : s.bodies)
    for (int n = 0; n < b.mesh.num_nodes(); ++n) {
      const Eigen::Vector2d x = b.mesh.nodes[static_cast<size_t>(n)];
      const Eigen::Vector2d exact(exx * x.x(), eyy * (x.y() + 1));
      EXPECT_LE((b.displacement.row(n).transpose() - exact).norm(), 1e-12 * 0.001) << what << ", " << b.name << " node " << n;
    }
  const PairField& pair = s.pairs.at(0);
  int carrying = 0;
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j) {
    if (pair.status[j] != 0) continue;
    ++carrying;
    EXPECT_NEAR(pair.pressure[j], p, 1e-9 * p) << what << ", slave node " << j;
  }
  EXPECT_GT(carrying, 5) << what;
  EXPECT_NEAR(pair.force, 2.0 * p, 1e-9 * p) << what;
}

// Refines the cells of every body whose nodes lie within `radius` of `centre` (hanging nodes where they stop).
void refine_near(Problem& problem, const Eigen::Vector2d& centre, double radius) {
  for (auto& body : problem.bodies) {
    std::vector<int> marked;
    for (int c = 0; c < body.mesh.num_cells(); ++c)
      for (int n : body.mesh.cells[static_cast<size_t>(c)])
        if ((body.mesh.nodes[static_cast<size_t>(n)] - centre).norm() < radius) {
          marked.push_back(c);
          break;
        }
    mesh::refine(body.mesh, marked);
  }
}

}  // namespace

TEST(GmshProblems, FlatPatchOnNonMatchingTrianglesIsExactAlsoWithHangingNodes) {
  const json job = example("flat_patch_gmsh.json");
  expect_exact_flat_patch(run(job), "as meshed");
  json swapped = job;
  swapped["contacts"][0] = {{"slave", "lower.lower_top"}, {"master", "upper.upper_bottom"}};
  expect_exact_flat_patch(run(swapped), "lower as slave");
  // Local refinement at the interface and inside both bodies: hanging nodes on the contact edges too.
  Problem problem = parse_or_fail(job);
  refine_near(problem, Eigen::Vector2d(0.7, 0.0), 0.4);
  refine_near(problem, Eigen::Vector2d(0.6, 0.05), 0.15);
  size_t hanging = 0;
  for (const auto& b : problem.bodies) hanging += mesh::hanging_nodes(b.mesh).size();
  ASSERT_GT(hanging, 10u);
  expect_exact_flat_patch(solve_quietly(problem), "refined");
}

TEST(GmshProblems, CylinderOnAMixedMeshMatchesHertzAndTheQuadrilateralVersion) {
  // hertz_cylinder_gmsh: the problem of hertz_cylinder.json (test_mortar_problems.cpp) meshed by Gmsh, the
  // cylinder in triangles and the block in quadrangles and triangles.
  const Result r = run(example("hertz_cylinder_gmsh.json"));
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LE(r.iterations, 10);
  for (const auto& b : r.steps.back().bodies) EXPECT_TRUE(b.mesh.has_triangles()) << b.name;
  const PairField& pair = r.steps.back().pairs.at(0);
  const double P = 2.0 * pair.force, R = 10.0, inv_E_star = 2 * (1 - 0.3 * 0.3) / 2.1e5;
  const double a = std::sqrt(4 * P * R * inv_E_star / M_PI), p0 = 2 * P / (M_PI * a);
  EXPECT_NEAR(contact::testing::hertz_half_width(pair), a, 0.01 * a);  // measured 0.02 %; p0 0.01 %
  EXPECT_NEAR(pair.pressure.maxCoeff(), p0, 0.01 * p0);
  EXPECT_LE(pair.penetration.maxCoeff(), 1e-12);
  // The same problem on the quadrilateral block meshes: the same force.
  const Result quads = run(example("hertz_cylinder.json"));
  ASSERT_TRUE(quads.converged) << quads.message;
  EXPECT_NEAR(pair.force, quads.steps.back().pairs.at(0).force, 0.005 * pair.force);
}

TEST(GmshProblems, RoundedPunchIsInEquilibriumSymmetricAndRefinesOntoItsArcs) {
  json job = example("punch_rounded_gmsh.json");
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  const PairField& pair = r.steps.back().pairs.at(0);
  EXPECT_LE(pair.penetration.maxCoeff(), 1e-12);
  // Equilibrium: the contact force is what the supports of each body carry (in y).
  for (const auto& b : r.steps.back().bodies) {
    const double reaction = b.reaction.col(1).sum();
    EXPECT_NEAR(std::abs(reaction), pair.force, 1e-8 * pair.force) << b.name;
  }
  // The contact zone: the flat part (|x| <= 0.4) and a little of each rounded corner, symmetric about x = 0.
  double lo = 1, hi = -1;
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j)
    if (pair.pressure[j] > 0) lo = std::min(lo, pair.position(j, 0)), hi = std::max(hi, pair.position(j, 0));
  EXPECT_LT(hi, 0.45);
  EXPECT_GT(hi, 0.4);
  EXPECT_NEAR(lo, -hi, 0.011);  // one element of the block's top
  // The pressure profile is symmetric (the meshes are not): p(x) against p(-x) in the middle.
  const double mean = pair.force / (hi - lo);
  std::vector<std::pair<double, double>> v;
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j) v.emplace_back(pair.position(j, 0), pair.pressure[j]);
  std::sort(v.begin(), v.end());
  auto at = [&](double x) {
    for (size_t j = 0; j + 1 < v.size(); ++j)
      if (x >= v[j].first && x <= v[j + 1].first)
        return v[j].second + (x - v[j].first) / (v[j + 1].first - v[j].first) * (v[j + 1].second - v[j].second);
    return std::nan("");
  };
  for (double x = 0.0; x <= 0.3; x += 0.05) EXPECT_NEAR(at(x), at(-x), 0.01 * mean) << "x = " << x;
  // Adaptive refinement (zz, 3 steps): the punch's corners stay on their arcs (centres (+-0.4, 0.1), radius 0.1),
  // and the force changes by less than 1 %.
  job["adaptivity"] = {{"indicator", "zz"}, {"max_steps", 3}};
  const Result adaptive = run(job);
  ASSERT_TRUE(adaptive.converged) << adaptive.message;
  ASSERT_GE(adaptive.step_history.size(), 3u);
  ASSERT_EQ(adaptive.steps.size(), 1u);  // an adaptive job keeps the last step's fields by default
  const auto& punch = adaptive.steps.back().bodies.at(1);
  ASSERT_EQ(punch.name, "punch");
  const PairField& last = adaptive.steps.back().pairs.at(0);
  EXPECT_NEAR(last.force, pair.force, 0.01 * pair.force);
  int on_arcs = 0;
  for (const auto& x : punch.mesh.nodes) {
    if (x.y() >= 0.1 - 1e-12 || std::abs(x.x()) <= 0.4 + 1e-12) continue;
    const Eigen::Vector2d centre(x.x() > 0 ? 0.4 : -0.4, 0.1);
    const double d = (x - centre).norm();
    if (std::abs(d - 0.1) < 2e-4) {  // on a corner (a chord's midpoint would be 1.25e-4 inside; interior nodes farther)
      ++on_arcs;
      EXPECT_NEAR(d, 0.1, 1e-12) << x.transpose();
    }
  }
  EXPECT_GT(on_arcs, 32);  // more than the initial 2 x 16
}

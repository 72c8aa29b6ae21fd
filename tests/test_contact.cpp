// Contact and DDM on problems with known answers, built in code (independent of the job parser).
#include "contact/pair.hpp"
#include "solve.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace contact;

namespace {

Body block_body(const std::string& name, double E, double nu, double x0, double y0, double x1, double y1, int nx, int ny) {
  Body b;
  b.name = name;
  b.material = {E, nu};
  mesh::BlockSpec s;
  s.corners = {mesh::Point(x0, y0), mesh::Point(x1, y0), mesh::Point(x1, y1), mesh::Point(x0, y1)};
  s.nx = nx;
  s.ny = ny;
  b.mesh = mesh::make_block(s);
  return b;
}

BoundaryCondition displacement(const std::string& edge, std::optional<double> ux, std::optional<double> uy) {
  BoundaryCondition bc{edge, BoundaryCondition::Kind::displacement};
  bc.ux = ux;
  bc.uy = uy;
  return bc;
}

// TEST_PROBLEMS.md section 2: lower [0,2]x[-1,0], upper [0,2]x[0,1], zero gap, pressed by delta.
Problem flat_patch(int n_upper, int n_lower, double E_upper, double E_lower, double delta) {
  Problem p;
  p.name = "flat_patch";
  Body lower = block_body("lower", E_lower, 0.3, 0, -1, 2, 0, n_lower, 3);
  lower.boundary = {displacement("left", 0.0, std::nullopt), displacement("bottom", std::nullopt, 0.0)};
  Body upper = block_body("upper", E_upper, 0.3, 0, 0, 2, 1, n_upper, 2);
  upper.boundary = {displacement("left", 0.0, std::nullopt), displacement("top", std::nullopt, -delta)};
  p.bodies = {lower, upper};
  ContactPair pair;
  pair.name = "upper.bottom-lower.top";
  pair.slave_body = 1;
  pair.slave_edge = "bottom";
  pair.master_body = 0;
  pair.master_edge = "top";
  p.contacts = {pair};
  p.solver.penalty.c = 1.0;  // theta = h / E: a soft penalty lets gamma be large (see ALGORITHM.md section 2)
  p.solver.gamma = 0.5;
  p.solver.gamma_auto = false;
  p.solver.acceleration = Acceleration::none;      // the paper's plain relaxation
  p.solver.enforcement = Enforcement::penalty;     // the formula below has the penalty's theta in it
  p.solver.criterion = Criterion::residual;
  p.solver.tolerance = 1e-12;
  p.solver.max_iterations = 500;
  return p;
}

double plane_strain_modulus(double E, double nu) { return E / (1 - nu * nu); }

}  // namespace

TEST(Projection, FootsInsideSegmentsAndNoPartnerBeyondTheEnds) {
  const std::vector<Eigen::Vector2d> line = {{2, 0}, {1, 0}, {0, 0}};  // a "top" edge: runs right to left
  auto p = interface::project(line, Eigen::Vector2d(0.25, 0.1));
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->segment, 1);
  EXPECT_NEAR(p->t, 0.75, 1e-15);
  EXPECT_NEAR(p->normal.y(), 1.0, 1e-15);  // outward normal of a top edge points up
  EXPECT_FALSE(interface::project(line, Eigen::Vector2d(2.5, 0.1)).has_value());
  // Outside a convex corner the closest point is the vertex, with the mean of the two normals.
  const std::vector<Eigen::Vector2d> corner = {{1, 0}, {0, 0}, {0, -1}};  // top then left side of a square
  auto v = interface::project(corner, Eigen::Vector2d(-0.2, 0.3));
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->segment, 1);
  EXPECT_NEAR(v->normal.x(), -std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(v->normal.y(), std::sqrt(0.5), 1e-15);
}

class FlatPatch : public ::testing::TestWithParam<std::tuple<int, int, double, Method>> {};

TEST_P(FlatPatch, PressureIsUniformAndEqualsTheLayerFormula) {
  const auto [n_upper, n_lower, E_lower, method] = GetParam();
  const double delta = 1e-3, E_upper = 2.1e5;
  Problem p = flat_patch(n_upper, n_lower, E_upper, E_lower, delta);
  p.solver.method = method;
  Observer quiet;
  CancelToken cancel;
  const Result r = solve(p, quiet, cancel);
  ASSERT_TRUE(r.converged) << r.message;
  const auto& pair = r.steps.back().pairs.at(0);
  const double theta = 1.0 * 1.0 / (2 * E_upper * E_lower / (E_upper + E_lower));
  EXPECT_DOUBLE_EQ(pair.theta, theta);
  const double exact = delta / (1.0 / plane_strain_modulus(E_upper, 0.3) + 1.0 / plane_strain_modulus(E_lower, 0.3) + theta);
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j)
    EXPECT_NEAR(pair.pressure[j], exact, 1e-8 * exact) << "slave node " << j;
  EXPECT_NEAR(pair.force, exact * 2.0, 1e-8 * exact * 2.0);
  // Equilibrium: the supports of each body carry the contact force.
  for (const auto& body : r.steps.back().bodies)
    EXPECT_NEAR(std::abs(body.reaction.col(1).sum()), pair.force, 1e-8 * pair.force) << body.name;
}

INSTANTIATE_TEST_SUITE_P(
    MatchingNonMatchingUnequal, FlatPatch,
    ::testing::Values(std::make_tuple(4, 4, 2.1e5, Method::neumann), std::make_tuple(5, 8, 2.1e5, Method::neumann),
                      std::make_tuple(5, 8, 7.0e4, Method::neumann), std::make_tuple(8, 5, 7.0e4, Method::neumann),
                      std::make_tuple(5, 8, 7.0e4, Method::monolithic)),
    [](const auto& info) {
      return "upper" + std::to_string(std::get<0>(info.param)) + "_lower" + std::to_string(std::get<1>(info.param)) +
             "_Elower" + std::to_string(static_cast<int>(std::get<2>(info.param))) +
             (std::get<3>(info.param) == Method::monolithic ? "_monolithic" : "_neumann");
    });

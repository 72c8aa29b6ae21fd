// The dual mortar discretisation (solver/mortar/) and the patch tests of contact, built in code (independent of
// the job parser). Every expected number is a mathematical fact of the method or an exact solution.
#include "mortar/dual_basis.hpp"
#include "mortar/pair.hpp"
#include "mortar/segments.hpp"
#include "contact/solve.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

ContactPair pair_of(int slave, const std::string& slave_edge, int master, const std::string& master_edge) {
  ContactPair pair;
  pair.name = "pair";
  pair.slave_body = slave;
  pair.slave_edge = slave_edge;
  pair.master_body = master;
  pair.master_edge = master_edge;
  return pair;
}

// ../shared/design/TEST_PROBLEMS.md section 2: lower [0,2]x[-1,0], upper [0,2]x[0,1] (the slave), zero gap,
// pressed by delta.
Problem flat_patch(int n_upper, int n_lower, double E_upper, double E_lower, double delta) {
  Problem p;
  p.name = "flat_patch";
  Body lower = block_body("lower", E_lower, 0.3, 0, -1, 2, 0, n_lower, 3);
  lower.boundary = {displacement("left", 0.0, std::nullopt), displacement("bottom", std::nullopt, 0.0)};
  Body upper = block_body("upper", E_upper, 0.3, 0, 0, 2, 1, n_upper, 2);
  upper.boundary = {displacement("left", 0.0, std::nullopt), displacement("top", std::nullopt, -delta)};
  p.bodies = {lower, upper};
  p.contacts = {pair_of(1, "bottom", 0, "top")};
  p.solver.penalty.c = 1.0;  // theta = h / E
  p.solver.gamma = 0.5;
  p.solver.gamma_auto = false;
  p.solver.acceleration = Acceleration::none;
  p.solver.criterion = Criterion::residual;
  p.solver.tolerance = 1e-13;
  p.solver.max_iterations = 2000;
  return p;
}

double plane_strain_modulus(double E, double nu) { return E / (1 - nu * nu); }

Result run(const Problem& p) {
  Observer quiet;
  CancelToken cancel;
  return solve(p, quiet, cancel);
}

// Integral over [a, b] of f by 5-point Gauss (exact for the polynomials of degree <= 9 used here).
template <class F>
double integrate(double a, double b, F f) {
  const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
  double s = 0;
  for (int i = 0; i < 5; ++i) s += w[i] * f(0.5 * (a + b) + 0.5 * (b - a) * x[i]);
  return 0.5 * (b - a) * s;
}

}  // namespace

// ---- dual basis ------------------------------------------------------------------------------------------

TEST(DualBasis, FullSegmentGivesTheClassicalCoefficients) {
  const auto b = mortar::dual_basis({{0.0, 1.0}}, 3.0);
  ASSERT_TRUE(b.has_value());
  EXPECT_NEAR(b->A(0, 0), 2.0, 1e-14);
  EXPECT_NEAR(b->A(0, 1), -1.0, 1e-14);
  EXPECT_NEAR(b->A(1, 0), -1.0, 1e-14);
  EXPECT_NEAR(b->A(1, 1), 2.0, 1e-14);
  EXPECT_NEAR(b->D[0], 1.5, 1e-14);
  EXPECT_NEAR(b->D[1], 1.5, 1e-14);
}

TEST(DualBasis, IsBiorthogonalOnAnyCoveredPartAndSumsToOne) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    // One or two random intervals.
    double a = unit(rng), b = unit(rng);
    if (a > b) std::swap(a, b);
    std::vector<std::pair<double, double>> covered = {{a * 0.5, 0.5 * a + 0.5 * b}};
    if (trial % 2) covered.emplace_back(0.6 + 0.3 * a, 0.6 + 0.3 * b + 0.05);
    const auto basis = mortar::dual_basis(covered, 1.0);
    ASSERT_TRUE(basis.has_value());
    for (int i = 0; i < 2; ++i)
      for (int l = 0; l < 2; ++l) {
        double phi_n = 0, n_only = 0;
        for (const auto& [x0, x1] : covered) {
          phi_n += integrate(x0, x1, [&](double x) { return basis->phi(i, x) * (l == 0 ? 1 - x : x); });
          n_only += integrate(x0, x1, [&](double x) { return l == 0 ? 1 - x : x; });
        }
        EXPECT_NEAR(phi_n, i == l ? n_only : 0.0, 1e-12 * std::max(1.0, std::abs(basis->A(i, i)))) << trial;
        if (i == l) EXPECT_NEAR(basis->D[i], n_only, 1e-13) << trial;
      }
    for (double x : {0.0, 0.3, 1.0}) EXPECT_NEAR(basis->phi(0, x) + basis->phi(1, x), 1.0, 1e-11) << trial;
  }
}

TEST(DualBasis, ADroppedNodesFunctionIsAddedToTheOtherWhichThenIsOne) {
  const auto b = mortar::drop_node(*mortar::dual_basis({{0.0, 1.0}}, 1.0), 0);
  for (double x : {0.0, 0.25, 1.0}) {
    EXPECT_NEAR(b.phi(1, x), 1.0, 1e-14);
    EXPECT_EQ(b.phi(0, x), 0.0);
  }
  EXPECT_EQ(b.D[0], 0.0);
  EXPECT_NEAR(b.D[1], 0.5, 1e-14);
}

// ---- segment mesh ----------------------------------------------------------------------------------------

TEST(SegmentMesh, CutsAtTheMasterNodesAndMeasuresTheGapAlongTheSlaveNormal) {
  // Slave: a bottom edge (runs left to right, outward normal -y) at y = 0; master: a top edge (runs right to
  // left) at y = -0.1 - 0.05 x, nodes at x = 1.5, 0.7, -0.2.
  const mortar::Polyline slave = {{0, 0}, {1, 0}, {2, 0}};
  const mortar::Polyline master = {{1.5, -0.175}, {0.7, -0.135}, {-0.2, -0.09}};
  const auto m = mortar::build_segment_mesh(slave, master);
  EXPECT_NEAR(m.slave_normal[0].y(), -1.0, 1e-15);
  ASSERT_EQ(m.segments.size(), 3u);  // [0, 0.7] and [0.7, 1] on segment 0, [1, 1.5] on segment 1
  EXPECT_EQ(m.segments[0].slave, 0);
  EXPECT_NEAR(m.segments[0].xi1, 0.7, 1e-14);
  EXPECT_EQ(m.segments[2].slave, 1);
  EXPECT_NEAR(m.segments[2].xi1, 0.5, 1e-14);
  for (const auto& s : m.segments)
    for (double xi : {s.xi0, s.xi1}) {
      const double x = s.slave + xi, t = xi == s.xi0 ? s.gap0 : s.gap1;
      EXPECT_NEAR(t, 0.1 + 0.05 * x, 1e-14) << "x = " << x;
    }
  // The part of the slave beyond x = 1.5 is not opposite the master.
  EXPECT_NEAR(m.segments.back().xi1, 0.5, 1e-14);
}

TEST(SegmentMesh, AMasterSegmentThatDoesNotFaceTheSlaveIsIgnored) {
  const mortar::Polyline slave = {{0, 0}, {1, 0}};
  const mortar::Polyline facing_away = {{0, -0.1}, {1, -0.1}};  // runs left to right: outward normal -y, like the slave
  EXPECT_TRUE(mortar::build_segment_mesh(slave, facing_away).segments.empty());
}

// ---- pair discretisation ---------------------------------------------------------------------------------

namespace {

// Upper body [0,2]x[0,1] with a curved (parabolic) bottom as the slave against a flat lower body.
Problem curved_pair(int n_upper, int n_lower) {
  Problem p = flat_patch(n_upper, n_lower, 2.1e5, 2.1e5, 1e-3);
  mesh::BlockSpec s;
  s.corners = {mesh::Point(0, 0.02), mesh::Point(2, 0.02 + 0.1 * 4), mesh::Point(2, 1.5), mesh::Point(0, 1.5)};
  s.nx = n_upper;
  s.ny = 3;
  mesh::Curve c;
  c.kind = mesh::Curve::Kind::parabola;
  c.a = 0.1;
  EXPECT_FALSE(mesh::fit_curve(c, s.corners[0], s.corners[1]).has_value());
  s.curves["bottom"] = c;
  p.bodies[1].mesh = mesh::make_block(s);
  return p;
}

}  // namespace

TEST(MortarPair, EveryRowOfMSumsToItsAreaAndTheForcesBalanceOnNonMatchingCurvedMeshes) {
  for (const auto& [nu, nl] : std::vector<std::pair<int, int>>{{5, 8}, {8, 5}, {7, 3}, {13, 4}}) {
    const Problem p = curved_pair(nu, nl);
    const auto d = mortar::discretize_pair(p, 0, 1.0);
    ASSERT_GT(d.n_rows(), 0);
    const Eigen::VectorXd row_sums = d.M * Eigen::VectorXd::Ones(d.M.cols());
    for (Eigen::Index r = 0; r < d.n_rows(); ++r) EXPECT_NEAR(row_sums[r], d.area[r], 1e-13) << nu << "/" << nl;
    EXPECT_NEAR(d.area.sum(), d.covered_length, 1e-12);
    // Any pressures: the slave and master forces are equal and opposite (linear momentum, to round-off).
    std::mt19937 rng(nu);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Eigen::VectorXd z(d.n_rows());
    for (Eigen::Index r = 0; r < z.size(); ++r) z[r] = 100 * unit(rng);
    Eigen::VectorXd fs = Eigen::VectorXd::Zero(2 * p.bodies[1].mesh.num_nodes());
    Eigen::VectorXd fm = Eigen::VectorXd::Zero(2 * p.bodies[0].mesh.num_nodes());
    d.add_forces(z, fs, fm);
    for (int c = 0; c < 2; ++c) {
      double total = 0, scale = 0;
      for (Eigen::Index i = c; i < fs.size(); i += 2) total += fs[i], scale += std::abs(fs[i]);
      for (Eigen::Index i = c; i < fm.size(); i += 2) total += fm[i];
      EXPECT_NEAR(total, 0.0, 1e-13 * scale) << "component " << c;
    }
  }
}

TEST(MortarPair, DIsDiagonalAndTheNodalGapOfALinearGapIsItsNodeValue) {
  // Flat slave at y = 0 over a tilted master y = -(0.1 + 0.05 x): the gap along the slave normal is linear.
  Problem p = flat_patch(6, 9, 2.1e5, 2.1e5, 1e-3);
  mesh::BlockSpec s;
  s.corners = {mesh::Point(-0.5, -1), mesh::Point(2.5, -1), mesh::Point(2.5, -0.225), mesh::Point(-0.5, -0.075)};
  s.nx = 9;
  s.ny = 2;
  p.bodies[0].mesh = mesh::make_block(s);
  const auto d = mortar::discretize_pair(p, 0, 1.0);
  ASSERT_EQ(d.n_rows(), 7);  // every slave node: the master extends beyond the slave at both ends
  const Eigen::VectorXd g = d.nodal_gap(Eigen::VectorXd::Zero(2 * p.bodies[1].mesh.num_nodes()),
                                        Eigen::VectorXd::Zero(2 * p.bodies[0].mesh.num_nodes()));
  for (Eigen::Index r = 0; r < d.n_rows(); ++r) {
    const double x = p.bodies[1].mesh.nodes[static_cast<size_t>(d.slave_nodes[static_cast<size_t>(d.node_of_row[static_cast<size_t>(r)])])].x();
    EXPECT_NEAR(g[r], 0.1 + 0.05 * x, 1e-14) << "row " << r;
    EXPECT_NEAR(d.D[r], d.area[r], 1e-15);
    // Gs touches the row's own slave node only: D is diagonal.
    for (mortar::SparseRows::InnerIterator it(d.Gs, static_cast<int>(r)); it; ++it)
      EXPECT_EQ(it.col() / 2, d.slave_nodes[static_cast<size_t>(d.node_of_row[static_cast<size_t>(r)])]);
  }
}

TEST(MortarPair, AClampedSlaveEndIsACrosspointWhoseNeighbourTakesItsShare) {
  Problem p = flat_patch(4, 7, 2.1e5, 2.1e5, 1e-3);
  p.bodies[1].boundary.push_back(displacement("right", 0.0, 0.0));  // the slave's right end is clamped
  p.contacts[0].gap.constant = 0.01;
  const auto d = mortar::discretize_pair(p, 0, 1.0);
  ASSERT_EQ(d.status.size(), 5u);
  EXPECT_EQ(d.status.back(), mortar::NodeStatus::crosspoint);
  EXPECT_EQ(d.status.front(), mortar::NodeStatus::contact);  // u_x = 0 only: the normal (y) is free
  EXPECT_EQ(d.n_rows(), 4);
  // The last row's dual function is 1 on the last segment: its area is that segment plus its own half.
  EXPECT_NEAR(d.area[3], 0.5 * 0.5 + 0.5, 1e-14);
  EXPECT_NEAR(d.D[3], 0.5, 1e-14);
  EXPECT_NEAR(d.area.sum(), 2.0, 1e-13);
  // A constant gap is the constant at every row, the modified one included.
  const Eigen::VectorXd g = d.nodal_gap(Eigen::VectorXd::Zero(2 * p.bodies[1].mesh.num_nodes()),
                                        Eigen::VectorXd::Zero(2 * p.bodies[0].mesh.num_nodes()));
  for (Eigen::Index r = 0; r < g.size(); ++r) EXPECT_NEAR(g[r], 0.01, 1e-15);
}

TEST(MortarPair, SlaveNodesBeyondTheMasterCarryNoMultiplier) {
  // A short master (lower body [0.5, 1.5]) under the slave [0, 2].
  Problem p = flat_patch(8, 4, 2.1e5, 2.1e5, 1e-3);
  p.bodies[0] = block_body("lower", 2.1e5, 0.3, 0.5, -1, 1.5, 0, 4, 2);
  p.bodies[0].boundary = {displacement("bottom", 0.0, 0.0)};
  const auto d = mortar::discretize_pair(p, 0, 1.0);
  // Slave nodes at x = 0, 0.25, ..., 2: those at x < 0.25 and x > 1.75 see nothing; 0.25 and 1.75 touch the
  // master's end with a zero-length overlap and are dropped too.
  for (size_t i = 0; i < d.status.size(); ++i) {
    const double x = 0.25 * static_cast<double>(i);
    if (x > 0.3 && x < 1.7)
      EXPECT_EQ(d.status[i], mortar::NodeStatus::contact) << x;
    else
      EXPECT_NE(d.status[i], mortar::NodeStatus::contact) << x;
  }
  EXPECT_NEAR(d.covered_length, 1.0, 1e-13);
  EXPECT_NEAR(d.area.sum(), 1.0, 1e-13);
}

TEST(MortarPair, MultipliersAreCoarseGrainedToTheMasterWhereTheSlaveIsFiner) {
  // Slave h = 2/12 on the left part, master h = 2/3: runs of 4 slave segments (the nearest to 2/3) carry one
  // multiplier segment each; a finer master leaves every slave node a multiplier node.
  Problem p = flat_patch(12, 3, 2.1e5, 2.1e5, 1e-3);
  auto d = mortar::discretize_pair(p, 0, 1.0);
  EXPECT_EQ(d.multiplier_nodes, (std::vector<size_t>{0, 4, 8, 12}));
  EXPECT_EQ(d.n_rows(), 4);
  for (size_t i = 0; i < d.status.size(); ++i)
    EXPECT_EQ(d.status[i], i % 4 == 0 ? mortar::NodeStatus::contact : mortar::NodeStatus::inner) << i;
  // Still a partition of unity and a conservative coupling: the rows cover the slave exactly once.
  EXPECT_NEAR(d.area.sum(), 2.0, 1e-13);
  const Eigen::VectorXd row_sums = d.M * Eigen::VectorXd::Ones(d.M.cols());
  for (Eigen::Index r = 0; r < d.n_rows(); ++r) EXPECT_NEAR(row_sums[r], d.area[r], 1e-13);
  // An inner node's value is the linear interpolation of its run's ends.
  const Eigen::VectorXd nodes = d.to_nodes(Eigen::Vector4d(0, 4, 8, 12), -1);
  for (Eigen::Index i = 0; i < nodes.size(); ++i) EXPECT_NEAR(nodes[i], static_cast<double>(i), 1e-13);
  p = flat_patch(3, 12, 2.1e5, 2.1e5, 1e-3);
  d = mortar::discretize_pair(p, 0, 1.0);
  EXPECT_EQ(d.multiplier_nodes, (std::vector<size_t>{0, 1, 2, 3}));
}

// ---- flat patch: uniform pressure on matching and non-matching meshes -------------------------------------

struct PatchCase {
  int n_upper, n_lower;
  double E_lower;
  Method method;
  Enforcement enforcement;
};

class FlatPatch : public ::testing::TestWithParam<PatchCase> {};

TEST_P(FlatPatch, PressureIsUniformAndEqualsTheLayerFormula) {
  const PatchCase c = GetParam();
  const double delta = 1e-3, E_upper = 2.1e5;
  Problem p = flat_patch(c.n_upper, c.n_lower, E_upper, c.E_lower, delta);
  p.solver.method = c.method;
  p.solver.enforcement = c.enforcement;
  const Result r = run(p);
  ASSERT_TRUE(r.converged) << r.message;
  const auto& pair = r.steps.back().pairs.at(0);
  const double theta = 1.0 * 1.0 / (2 * E_upper * c.E_lower / (E_upper + c.E_lower));
  const double compliance = 1.0 / plane_strain_modulus(E_upper, 0.3) + 1.0 / plane_strain_modulus(c.E_lower, 0.3);
  const double exact = delta / (compliance + (c.enforcement == Enforcement::exact ? 0.0 : theta));
  for (Eigen::Index j = 0; j < pair.pressure.size(); ++j)
    EXPECT_NEAR(pair.pressure[j], exact, 1e-10 * exact) << "slave node " << j;
  EXPECT_NEAR(pair.force, exact * 2.0, 1e-10 * exact * 2.0);
  // Equilibrium: the supports of each body carry the contact force.
  for (const auto& body : r.steps.back().bodies)
    EXPECT_NEAR(std::abs(body.reaction.col(1).sum()), pair.force, 1e-10 * pair.force) << body.name;
}

INSTANTIATE_TEST_SUITE_P(
    MatchingNonMatchingUnequal, FlatPatch,
    ::testing::Values(PatchCase{4, 4, 2.1e5, Method::interface_newton, Enforcement::exact},
                      PatchCase{5, 8, 2.1e5, Method::interface_newton, Enforcement::exact},
                      PatchCase{8, 5, 7.0e4, Method::interface_newton, Enforcement::exact},
                      PatchCase{7, 3, 7.0e4, Method::interface_newton, Enforcement::exact},
                      PatchCase{7, 3, 7.0e4, Method::interface_newton, Enforcement::penalty},
                      PatchCase{4, 4, 2.1e5, Method::neumann, Enforcement::penalty},
                      PatchCase{5, 8, 7.0e4, Method::neumann, Enforcement::penalty},
                      PatchCase{8, 5, 7.0e4, Method::neumann, Enforcement::penalty},
                      PatchCase{7, 3, 7.0e4, Method::neumann, Enforcement::penalty},
                      PatchCase{5, 8, 7.0e4, Method::monolithic, Enforcement::penalty},
                      PatchCase{7, 3, 7.0e4, Method::monolithic, Enforcement::exact}),
    [](const auto& info) {
      const PatchCase& c = info.param;
      const char* m = c.method == Method::monolithic ? "monolithic" : c.method == Method::neumann ? "neumann" : "interface";
      return "upper" + std::to_string(c.n_upper) + "_lower" + std::to_string(c.n_lower) + "_Elower" +
             std::to_string(static_cast<int>(c.E_lower)) + "_" + m + (c.enforcement == Enforcement::exact ? "_exact" : "_penalty");
    });

// ---- patch test with a curved (polyline) interface ---------------------------------------------------------

namespace {

// The hydrostatic state sigma = -p I, u = -a (x, y) with a = p / (2 (lambda + mu)) (plane strain), in two bodies
// that meet along y = f(x): the exact contact pressure is p everywhere, along any interface. Conditions that
// the exact field satisfies: u_x = 0 on both left edges (x = 0), u_y = -a y on the bottom (y = -1) and top (y = 1),
// normal pressure p on both right edges.
Problem hydrostatic_pair(int n_upper, int n_lower, const std::function<double(double)>& f, double p_exact) {
  const double E = 2.1e5, nu = 0.3;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double a = p_exact / (2 * (lambda + mu));
  Problem p;
  p.name = "hydrostatic";
  Body lower = block_body("lower", E, nu, 0, -1, 2, 0, n_lower, 4);
  Body upper = block_body("upper", E, nu, 0, 0, 2, 1, n_upper, 3);
  // Map the blocks so that they meet on y = f(x): lower y -> y + f(x) (y + 1), upper y -> y + f(x) (1 - y).
  for (auto& x : lower.mesh.nodes) x.y() += f(x.x()) * (x.y() + 1);
  for (auto& x : upper.mesh.nodes) x.y() += f(x.x()) * (1 - x.y());
  BoundaryCondition pressure{"right", BoundaryCondition::Kind::traction};
  pressure.normal_pressure = true;
  pressure.pressure = p_exact;
  lower.boundary = {displacement("left", 0.0, std::nullopt), displacement("bottom", std::nullopt, a), pressure};
  upper.boundary = {displacement("left", 0.0, std::nullopt), displacement("top", std::nullopt, -a), pressure};
  p.bodies = {lower, upper};
  p.contacts = {pair_of(1, "bottom", 0, "top")};
  return p;
}

// The piecewise-linear interpolant of an arc y = sqrt(R^2 - (x - 1)^2) - sqrt(R^2 - 1) (R = 2) on n uniform
// segments of [0, 2]: the chords of the arc between the nodes of the coarser side.
std::function<double(double)> arc_chords(int n) {
  return [n](double x) {
    auto arc = [](double t) { return std::sqrt(4.0 - (t - 1) * (t - 1)) - std::sqrt(3.0); };
    const double h = 2.0 / n;
    const int k = std::min(n - 1, static_cast<int>(std::floor(x / h)));
    const double t = (x - k * h) / h;
    return (1 - t) * arc(k * h) + t * arc((k + 1) * h);
  };
}

}  // namespace

class CurvedChordPatch : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(CurvedChordPatch, HydrostaticContactPressureIsExactAlongAPolylineInterface) {
  // The interface is the chord polyline of an arc through the coarser side's nodes; the finer side's nodes lie
  // on it (3 per coarse segment), so both sides describe the same polyline with non-matching nodes.
  const auto [n_upper, n_lower] = GetParam();
  const double p_exact = 50.0;
  const Problem p = hydrostatic_pair(n_upper, n_lower, arc_chords(std::min(n_upper, n_lower)), p_exact);
  for (Enforcement e : {Enforcement::exact}) {
    Problem q = p;
    q.solver.enforcement = e;
    const Result r = run(q);
    ASSERT_TRUE(r.converged) << r.message;
    const auto& pair = r.steps.back().pairs.at(0);
    // Every slave node: a multiplier node's multiplier, or (a finer slave, coarse-grained multipliers) the
    // interpolation of the multipliers around it.
    for (Eigen::Index j = 0; j < pair.pressure.size(); ++j) {
      EXPECT_TRUE(pair.status[j] == 0 || pair.status[j] == 4) << "slave node " << j << " status " << pair.status[j];
      EXPECT_NEAR(pair.pressure[j], p_exact, 1e-9 * p_exact) << "slave node " << j;
    }
    // Both bodies are in the exact hydrostatic state: u_y = -a y at every node.
    const double a = q.bodies[0].boundary[1].uy.value();  // u_y = a on the lower body's bottom (y = -1)
    for (const auto& b : r.steps.back().bodies)
      for (Eigen::Index i = 0; i < b.displacement.rows(); ++i)
        EXPECT_NEAR(b.displacement(i, 1), -a * b.mesh.nodes[static_cast<size_t>(i)].y(), 1e-9 * a) << b.name << " node " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(FinerSlaveAndFinerMaster, CurvedChordPatch,
                         ::testing::Values(std::make_pair(6, 18), std::make_pair(18, 6), std::make_pair(8, 8)),
                         [](const auto& info) {
                           return "upper" + std::to_string(info.param.first) + "_lower" + std::to_string(info.param.second);
                         });

// The two interface solvers (solver/ddm/interface/): the sparse direct active set and the iterative FETI solver
// (projected MPRGP in SMALBE) give the discrete solution of the monolithic reference, an independent algebra, on
// every example and on brick walls of many floating bodies; MPRGP alone solves bound-constrained QPs like the
// active-set QP method; the iterative solver's iterations do not grow with the number of bodies (the FETI property).
// With friction the iterative solver (MPRGP on the box, Coulomb's outer iteration) gives the direct friction
// solver's discrete solution (semismooth Newton, an independent method) under Coulomb and Tresca.
#include "contact/result_file.hpp"
#include "ddm/interface/interface_problem.hpp"
#include "linalg/active_set.hpp"
#include "linalg/mprgp.hpp"
#include "support.hpp"

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;  // the shared helpers (support.hpp)

namespace {

void expect_same_solution(const Result& a, const Result& b, double rel, const std::string& what) {
  ASSERT_FALSE(a.steps.empty()) << what << ": " << a.message;
  ASSERT_FALSE(b.steps.empty()) << what << ": " << b.message;
  const Step& sa = a.steps.back();
  const Step& sb = b.steps.back();
  double u_scale = 0, p_scale = 0;
  for (const auto& body : sb.bodies) u_scale = std::max(u_scale, max_abs(body.displacement));
  for (const auto& pair : sb.pairs) p_scale = std::max(p_scale, max_abs(pair.pressure));
  for (size_t i = 0; i < sa.bodies.size(); ++i)
    EXPECT_LE(max_abs(sa.bodies[i].displacement - sb.bodies[i].displacement), rel * u_scale)
        << what << ", body " << sa.bodies[i].name;
  for (size_t k = 0; k < sa.pairs.size(); ++k)
    EXPECT_LE(max_abs(sa.pairs[k].pressure - sb.pairs[k].pressure), rel * p_scale) << what << ", pair " << sa.pairs[k].name;
}

json with_solver(json job, const std::string& interface_solver) {
  job["solver"] = {{"method", "interface_newton"}, {"interface", {{"solver", interface_solver}}}};
  return job;
}

json monolithic(json job) {
  job["solver"] = {{"method", "monolithic"}};
  return job;
}

// A wall from the project's generator (scripts/make_brick_wall.py).
json wall(int rows, int bricks, int cells, bool abutments) {
  const std::string path = std::string(CONTACT_BINARY_DIR) + "/test_wall_" + std::to_string(rows) + "x" +
                           std::to_string(bricks) + "_" + std::to_string(cells) + (abutments ? "_a" : "") + ".json";
  const std::string command = "/usr/bin/python3 " + std::string(CONTACT_SOURCE_DIR) + "/scripts/make_brick_wall.py --rows " +
                              std::to_string(rows) + " --bricks " + std::to_string(bricks) + " --cells " +
                              std::to_string(cells) + (abutments ? " --abutments" : "") + " -o " + path + " > /dev/null 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  std::ifstream in(path);
  json job = json::parse(in);
  std::remove(path.c_str());
  return job;
}

// The largest relative difference of the last step's displacements, pressures and tangential tractions (each
// relative to its own largest value in `b`).
double friction_difference(const Result& a, const Result& b) {
  const Step& sa = a.steps.back();
  const Step& sb = b.steps.back();
  double u_scale = 0, p_scale = 0, worst = 0;
  for (const auto& body : sb.bodies) u_scale = std::max(u_scale, max_abs(body.displacement));
  for (const auto& pair : sb.pairs) p_scale = std::max({p_scale, max_abs(pair.pressure), max_abs(pair.tangential_traction)});
  for (size_t i = 0; i < sa.bodies.size(); ++i)
    worst = std::max(worst, max_abs(sa.bodies[i].displacement - sb.bodies[i].displacement) / u_scale);
  for (size_t k = 0; k < sa.pairs.size(); ++k) {
    worst = std::max(worst, max_abs(sa.pairs[k].pressure - sb.pairs[k].pressure) / p_scale);
    worst = std::max(worst, max_abs(sa.pairs[k].tangential_traction - sb.pairs[k].tangential_traction) / p_scale);
  }
  return worst;
}

// Every contact of `job` with `friction` (Coulomb {"coefficient": mu} or Tresca {"bound": g}).
json with_friction(json job, const json& friction) {
  for (auto& c : job["contacts"]) c["friction"] = friction;
  return job;
}

// The iterative solver with a tight tolerance against the direct friction solver (semismooth Newton, exact on its
// sets): the same discrete solution, reached to `rel`; the iterative answer's own complementarity is reported by
// its last iteration.
void expect_iterative_equals_direct(const json& job, double rel, const std::string& what) {
  const Result direct = run(with_solver(job, "direct"));
  ASSERT_TRUE(direct.converged) << what << " direct: " << direct.message;
  json tight = with_solver(job, "iterative");
  tight["solver"]["interface"]["tolerance"] = 1e-13;
  const Result iterative = run(tight);
  ASSERT_TRUE(iterative.converged) << what << " iterative: " << iterative.message;
  EXPECT_EQ(iterative.interface_solver, "iterative");
  ASSERT_EQ(iterative.steps.size(), direct.steps.size()) << what;
  const double difference = friction_difference(iterative, direct);
  EXPECT_LE(difference, rel) << what;
  ASSERT_FALSE(iterative.history.empty());
  EXPECT_LE(iterative.history.back().complementarity, 1e-9) << what;
  std::printf("[ friction ] %s: iterative = direct to %.2e (%ld MPRGP iterations, %d outer)\n", what.c_str(),
              difference, iterative.interface_iterations, iterative.iterations);
}

}  // namespace

TEST(Mprgp, SolvesBoundConstrainedQpsLikeTheActiveSetQpMethod) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 12; ++trial) {
    const int n = 10 + 7 * trial;
    Eigen::MatrixXd A(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) A(i, j) = normal(rng);
    const Eigen::MatrixXd H = A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd g(n);
    for (int i = 0; i < n; ++i) g[i] = normal(rng);
    const Eigen::VectorXd reference = linalg::solve_nonnegative_qp(H.sparseView(), g);
    for (bool jacobi : {false, true}) {
      linalg::BoundQp qp;
      qp.apply = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
        y = H * x;
        return false;
      };
      if (jacobi)
        qp.precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& y) {
          y = r.cwiseQuotient(H.diagonal());
          return false;
        };
      qp.b = -g;
      qp.lower = Eigen::VectorXd::Zero(n);
      linalg::MprgpSettings settings;
      settings.alpha_bar = 1.9 / H.eigenvalues().real().maxCoeff();
      const auto r = linalg::solve_mprgp(qp, Eigen::VectorXd::Zero(n), settings,
                                         [&](const linalg::MprgpResult& state) { return state.projected_gradient() <= 1e-12 * g.norm(); });
      ASSERT_TRUE(r.report.converged()) << trial;
      EXPECT_GE(r.x.minCoeff(), 0.0);
      EXPECT_LE((r.x - reference).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, reference.cwiseAbs().maxCoeff()))
          << "trial " << trial << (jacobi ? " (Jacobi)" : "");
    }
  }
}

TEST(InterfaceSolvers, BothAgreeWithTheMonolithicReferenceOnEveryExample) {
  for (const char* name : {"stack3.json", "stack3_floating.json", "flat_patch.json", "flat_patch_nonmatching.json",
                           "hertz.json", "hertz_force.json", "hertz_cylinder.json", "punch.json", "punch_force.json",
                           "seed_layers.json", "seed_layers_curved.json", "seed_layers_steps.json", "brick_wall.json",
                           "flat_patch_gmsh.json", "hertz_cylinder_gmsh.json", "punch_rounded_gmsh.json"}) {
    const json job = example(name);
    const Result reference = run(monolithic(job));
    ASSERT_TRUE(reference.converged) << name << ": " << reference.message;
    for (const char* solver : {"direct", "iterative"}) {
      const Result r = run(with_solver(job, solver));
      ASSERT_TRUE(r.converged) << name << " " << solver << ": " << r.message;
      EXPECT_EQ(r.interface_solver, solver);
      expect_same_solution(r, reference, 1e-8, std::string(name) + " " + solver);
      for (const auto& pair : r.steps.back().pairs) EXPECT_LE(pair.penetration.maxCoeff(), 1e-10 * max_abs(pair.pressure));
    }
  }
}

TEST(InterfaceSolvers, BothAgreeWithTheMonolithicReferenceOnDowelledAndAbutmentWalls) {
  for (bool abutments : {false, true})
    for (int n : {8, 16}) {
      const json job = wall(n, n, 4, abutments);
      const std::string what = std::to_string(n) + " x " + std::to_string(n) + (abutments ? " abutments" : " dowelled");
      const Result reference = run(monolithic(job));
      ASSERT_TRUE(reference.converged) << what << ": " << reference.message;
      for (const char* solver : {"direct", "iterative"}) {
        const Result r = run(with_solver(job, solver));
        ASSERT_TRUE(r.converged) << what << " " << solver << ": " << r.message;
        expect_same_solution(r, reference, 1e-8, what + " " + solver);
      }
    }
}

TEST(InterfaceSolvers, TheAutomaticChoiceTakesTheDirectSolverForFewBodiesAndTheIterativeOneForMany) {
  json few = example("stack3.json");
  few["solver"] = {{"method", "interface_newton"}};
  EXPECT_EQ(run(few).interface_solver, "direct");
  json many = wall(16, 16, 2, false);
  many["solver"] = {{"method", "interface_newton"}};
  const Result r = run(many);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.interface_solver, "iterative");
  EXPECT_GT(r.interface_iterations, 0);
  ASSERT_FALSE(r.history.empty());
  EXPECT_NE(r.history.front().note.find("interface solver iterative"), std::string::npos) << r.history.front().note;
}

TEST(InterfaceSolvers, TheAutomaticPreconditionerIsDirichletForFewBodiesAndNoneForMany) {
  // preconditioner "auto" (the default; interface_solver.cpp, resolved_settings): three bodies keep Dirichlet, a
  // wall of 265 floating bricks runs without it. The iterative solver forced on both; the first step's note says
  // which ran, and an explicit choice is kept.
  json few = with_solver(example("stack3.json"), "iterative");
  const Result f = run(few);
  ASSERT_TRUE(f.converged) << f.message;
  ASSERT_FALSE(f.history.empty());
  EXPECT_NE(f.history.front().note.find("interface solver iterative, preconditioner dirichlet"), std::string::npos)
      << f.history.front().note;
  json many = with_solver(wall(16, 16, 2, false), "iterative");
  const Result m = run(many);
  ASSERT_TRUE(m.converged) << m.message;
  EXPECT_NE(m.history.front().note.find("interface solver iterative, preconditioner none"), std::string::npos)
      << m.history.front().note;
  many["solver"]["interface"]["preconditioner"] = "dirichlet";
  const Result d = run(many);
  ASSERT_TRUE(d.converged) << d.message;
  EXPECT_NE(d.history.front().note.find("preconditioner dirichlet"), std::string::npos) << d.history.front().note;
}

TEST(InterfaceSolvers, IterationsOfTheIterativeSolverDoNotGrowWithTheNumberOfBricks) {
  // The same bricks (same H/h) in walls of 69 to 4,129 bodies: FETI's iterations are bounded by H/h.
  std::vector<long> iterations;
  for (int n : {8, 16, 32, 64}) {
    const Problem problem = contact::testing::parse_or_fail(with_solver(wall(n, n, 4, false), "iterative"));
    const Result r = contact::testing::solve_quietly(problem);
    ASSERT_TRUE(r.converged) << n << ": " << r.message;
    iterations.push_back(r.interface_iterations);
    if (n == 64) {  // thousands of names: more than an HDF5 object header holds (64 KiB) in one attribute
      const std::string path = std::string(CONTACT_BINARY_DIR) + "/test_wall_64.hdf";
      io::write_result(path, problem, r);
      const io::ResultFile file = io::read_result(path);
      EXPECT_EQ(file.history.body_names.size(), problem.bodies.size());
      EXPECT_EQ(file.history.pair_names.size(), problem.contacts.size());
      std::remove(path.c_str());
    }
  }
  EXPECT_LE(static_cast<double>(iterations.back()), 1.5 * static_cast<double>(iterations.front()))
      << iterations[0] << ", " << iterations[1] << ", " << iterations[2] << ", " << iterations[3];
  for (long k : iterations) EXPECT_GT(k, 0);
}

TEST(InterfaceSolvers, TheProductWithFIsTheSameOnOneTwoAndThreeThreads) {
  // The iterative solver's product with F splits the bodies' blocks over the process's threads, each summing into
  // a vector of its own: against the assembled sparse F, on a wall of 265 bodies (enough blocks for three threads).
  const auto parsed = job::parse(with_solver(wall(16, 16, 4, false), "iterative"));
  ASSERT_TRUE(parsed.ok());
  parallel::ThreadTaskRunner one(1);
  ddm::ContactSystem system(*parsed.problem, one, ddm::ContactSystem::Factorization::interface);
  ASSERT_TRUE(system.ok()) << system.error();
  const ddm::InterfaceProblem interface(system, one);
  const linalg::SparseMatrix F = interface.assemble();
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd x(interface.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = normal(rng);
  const Eigen::VectorXd expected = F * x;
  for (unsigned threads : {1u, 2u, 3u}) {
    parallel::ThreadTaskRunner runner(threads);
    Eigen::VectorXd y;
    EXPECT_FALSE(interface.apply(x, y, runner));
    ASSERT_EQ(y.size(), expected.size());
    EXPECT_LE((y - expected).cwiseAbs().maxCoeff(), 1e-13 * expected.cwiseAbs().maxCoeff()) << threads << " threads";
  }
}

TEST(InterfaceSolvers, AnUnheldFloatingBodyIsNamedByTheIterativeSolverToo) {
  json job = with_solver(example("punch_force.json"), "iterative");
  job["bodies"][1]["boundary"][1]["force"] = {0, 200};  // upwards: nothing holds the punch
  Result r = run(job);
  EXPECT_EQ(r.stop_reason, StopReason::error);
  EXPECT_NE(r.message.find("body 'punch' floats (translation in y"), std::string::npos) << r.message;
  // A cap held sideways at a corner and pulled off a base: valid (its flat contact could hold it), unheld at the
  // solution.
  job = with_solver(contact::testing::cap_pulled_off_base(), "iterative");
  r = run(job);
  EXPECT_EQ(r.stop_reason, StopReason::error) << r.message;
  EXPECT_NE(r.message.find("body 'cap' floats (translation in y, rotation free) and no contact holds it"),
            std::string::npos) << r.message;
}

TEST(InterfaceSolvers, WithFrictionTheIterativeSolverEqualsTheDirectOneOnTheFrictionExamples) {
  // roller_friction: Coulomb mu = 0.2 over three load steps (the push grows): friction alone holds the floating
  // roller and plate; the same job under Tresca with a bound that lets the contact zones' edges slip.
  const json roller = example("roller_friction.json");
  expect_iterative_equals_direct(roller, 1e-8, "roller_friction Coulomb");
  expect_iterative_equals_direct(with_friction(roller, {{"bound", 3000.0}}), 1e-8, "roller_friction Tresca");
}

TEST(InterfaceSolvers, WithFrictionTheIterativeSolverEqualsTheDirectOneOnAFrictionalBrickWall) {
  // The dowelled wall with friction in every bed joint (Coulomb mu = 0.6 as asked, and a low mu = 0.05 where
  // more nodes slip), and Tresca with a bound of a fifth of the top pressure.
  const json job = wall(8, 8, 4, false);
  expect_iterative_equals_direct(with_friction(job, {{"coefficient", 0.6}}), 1e-8, "wall 8x8 Coulomb 0.6");
  expect_iterative_equals_direct(with_friction(job, {{"coefficient", 0.05}}), 1e-8, "wall 8x8 Coulomb 0.05");
  double pressure = 0;
  for (const auto& body : job["bodies"])
    for (const auto& c : body["boundary"])
      if (c.contains("traction")) pressure = std::abs(c["traction"]["normal"].get<double>());
  ASSERT_GT(pressure, 0);
  expect_iterative_equals_direct(with_friction(job, {{"bound", 0.2 * pressure}}), 1e-8, "wall 8x8 Tresca");
}

TEST(InterfaceSolvers, WithFrictionTheAutomaticChoiceFollowsTheSameSizeRule) {
  // The rule counts floating-body rows and contact rows, not friction: few bodies take the direct solver, the
  // 16 x 16 wall (264 dowelled bricks, 528 floating-body rows) the iterative one, with friction as without.
  json few = example("roller_friction.json");
  few["solver"] = {{"method", "interface_newton"}};
  EXPECT_EQ(run(few).interface_solver, "direct");
  json many = with_friction(wall(16, 16, 2, false), {{"coefficient", 0.6}});
  many["solver"] = {{"method", "interface_newton"}};
  const Result r = run(many);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.interface_solver, "iterative");
  EXPECT_GT(r.interface_iterations, 0);
}

TEST(InterfaceSolvers, WithFrictionACancelAtTheFirstOuterIterationStopsTheIterativeSolverThere) {
  // The report of every outer iteration on the slip bounds is where the solve asks the token (besides every
  // product with F): a cancel set while the first one is reported ends the solve before a second.
  const Problem problem =
      contact::testing::parse_or_fail(with_solver(with_friction(wall(8, 8, 4, false), {{"coefficient", 0.6}}), "iterative"));
  CancelToken cancel;
  struct CancelAtFirst : Observer {
    CancelToken* token = nullptr;
    int reports = 0;
    void on_iteration(const IterationReport&) override {
      ++reports;
      token->cancel();
    }
  } observer;
  observer.token = &cancel;
  const Result r = solve(problem, observer, cancel);
  EXPECT_EQ(r.stop_reason, StopReason::cancelled) << r.message;
  EXPECT_EQ(observer.reports, 1);
}

// Benchmark of the hierarchical BEM against the dense one (prints a table; never pass/fail):
//   build/bench/bench_hbem [--nodes 1024,2048,...] [--dense-up-to 4096] [--tolerance 1e-6]
// A disc of radius 1 with n boundary nodes and the exact quadratic field of tests/bem_problems.hpp: displacements
// prescribed on the first quarter of the boundary, tractions on the rest (mixed data, like docs/bem.md's
// timings). Per size: the hierarchical solve (setup = checks, ACA, near field, preconditioner; GMRES) and its
// memory (compressed matrix + preconditioner factors), the Somigliana stresses at n interior points (the cell
// centres of a mesh with as many cells as boundary nodes, roughly), and, as far as it fits, the dense solve and
// dense evaluation with their difference to the hierarchical results. The growth exponents are the slopes of
// log(time) against log(n) between successive sizes.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "../tests/bem_problems.hpp"
#include "bem/bem.hpp"
#include "bench_support.hpp"

using namespace contact::bem;
using namespace contact::bem::test_problems;
using contact::bench::now;

namespace {

double largest_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

struct Row {
  int nodes = 0;
  double h_solve = 0, h_eval = 0, h_mb = 0, d_solve = -1, d_eval = -1, d_mb = 0, diff_u = -1, diff_s = -1;
  HierarchicalStats stats;
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes{1024, 2048, 4096, 8192, 16384, 32768, 65536};
  int dense_up_to = 4096;
  HierarchicalOptions options;
  for (int a = 1; a + 1 < argc; a += 2) {
    if (!std::strcmp(argv[a], "--nodes")) sizes = contact::bench::parse_int_list(argv[a + 1]);
    if (!std::strcmp(argv[a], "--dense-up-to")) dense_up_to = std::stoi(argv[a + 1]);
    if (!std::strcmp(argv[a], "--tolerance")) options.tolerance = std::stod(argv[a + 1]);
    if (!std::strcmp(argv[a], "--gmres")) options.solver_tolerance = std::stod(argv[a + 1]);
  }
  std::printf("hierarchical BEM: tolerance %.0e, eta %.1f, leaf %d nodes, GMRES %.0e\n", options.tolerance,
              options.eta, options.leaf_size, options.solver_tolerance);
  std::printf("%7s %8s | %9s %7s %7s %9s %8s %5s %5s %6s | %9s %9s %9s | %9s %9s\n", "nodes", "unknowns",
              "H solve s", "setup", "GMRES", "H eval s", "H MB", "iter", "rank", "maxrk", "D solve s", "D eval s",
              "D MB", "diff u", "diff sigma");
  std::vector<Row> rows;
  for (const int n : sizes) {
    Row row;
    row.nodes = n;
    const BoundaryProblem problem = disc_problem(n);
    const std::vector<Vector2d> points = interior_points(n);
    double t0 = now();
    const BoundarySolution h = solve_hierarchical(problem, options, &row.stats);
    row.h_solve = now() - t0;
    row.h_mb = static_cast<double>(row.stats.matrix_bytes + row.stats.preconditioner_bytes) / 1048576.0;
    t0 = now();
    const Eigen::MatrixX3d h_sigma = interior_stresses_hierarchical(problem, h, points, options);
    row.h_eval = now() - t0;
    if (n <= dense_up_to) {
      t0 = now();
      const BoundarySolution d = solve(problem);
      row.d_solve = now() - t0;
      row.d_mb = 8.0 * row.stats.unknowns * static_cast<double>(row.stats.unknowns) / 1048576.0;
      t0 = now();
      const Eigen::MatrixX3d d_sigma = interior_stresses(problem, d, points);
      row.d_eval = now() - t0;
      row.diff_u = largest_difference(h.displacement, d.displacement);
      row.diff_s = largest_difference(h_sigma, d_sigma);
    }
    std::printf("%7d %8d | %9.2f %7.2f %7.2f %9.2f %8.1f %5d %5.1f %6d | ", n, row.stats.unknowns, row.h_solve,
                row.stats.setup_seconds, row.stats.solve_seconds, row.h_eval, row.h_mb, row.stats.iterations,
                row.stats.mean_rank, row.stats.largest_rank);
    if (row.d_solve >= 0)
      std::printf("%9.2f %9.2f %9.1f | %9.1e %9.1e\n", row.d_solve, row.d_eval, row.d_mb, row.diff_u, row.diff_s);
    else
      std::printf("%9s %9s %9s | %9s %9s\n", "-", "-", "-", "-", "-");
    std::fflush(stdout);
    rows.push_back(row);
  }
  std::printf("\ngrowth exponents (slope of log time, log memory against log nodes):\n");
  std::printf("%15s | %8s %8s %8s | %8s %8s\n", "nodes", "H solve", "H eval", "H mem", "D solve", "D eval");
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const Row &a = rows[k - 1], &b = rows[k];
    const double ln = std::log(static_cast<double>(b.nodes) / a.nodes);
    const auto slope = [&](double x, double y) { return x > 0 && y > 0 ? std::log(y / x) / ln : NAN; };
    std::printf("%7d->%-7d | %8.2f %8.2f %8.2f | %8.2f %8.2f\n", a.nodes, b.nodes, slope(a.h_solve, b.h_solve),
                slope(a.h_eval, b.h_eval), slope(a.h_mb, b.h_mb), slope(a.d_solve, b.d_solve),
                slope(a.d_eval, b.d_eval));
  }
  return 0;
}

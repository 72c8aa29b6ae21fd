// The hierarchical BEM (solver/bem: cluster_tree, aca, gmres, hmatrix, hierarchical_*): its parts against their
// definitions, and the whole against the dense BEM (the reference) on the Lame ring and on exact polynomial fields,
// on quadrilateral and triangular boundaries, graded and adaptively refined ones. docs/bem.md quotes the numbers.
// The leaf size is 8 here (32 by default) so that boundaries of a few hundred nodes already have a far field, and
// every admissible block of the interior evaluation is compressed (by default leaf-sized ones are summed exactly).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "bem/aca.hpp"
#include "bem/bem.hpp"
#include "bem/cluster_tree.hpp"
#include "bem/gmres.hpp"
#include "bem/interpolation.hpp"
#include "bem_problems.hpp"

using namespace contact::bem;
using namespace contact::bem::test_problems;

namespace {

HierarchicalOptions small_leaves() {
  HierarchicalOptions options;
  options.leaf_size = 8;
  options.break_even = 0.0;  // compress every admissible block of the evaluation too
  return options;
}

// The agreement of the hierarchical with the dense results, each relative to the largest value of its kind.
struct Agreement {
  double displacement = 0.0, traction = 0.0, stress = 0.0;
  HierarchicalStats solve_stats, evaluation_stats;
};

double relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& reference) {
  return (a - reference).cwiseAbs().maxCoeff() / reference.cwiseAbs().maxCoeff();
}

Eigen::MatrixXd tractions(const BoundarySolution& s) {
  Eigen::MatrixXd t(static_cast<Eigen::Index>(s.traction.size()), 4);
  for (std::size_t e = 0; e < s.traction.size(); ++e)
    t.row(static_cast<Eigen::Index>(e)) = Eigen::Map<const Eigen::RowVector4d>(s.traction[e].data());
  return t;
}

Agreement compare_with_dense(const BoundaryProblem& problem, const std::vector<Vector2d>& points,
                             const HierarchicalOptions& options = small_leaves()) {
  Agreement a;
  const BoundarySolution dense = solve(problem);
  const BoundarySolution hierarchical = solve_hierarchical(problem, options, &a.solve_stats);
  a.displacement = relative(hierarchical.displacement, dense.displacement);
  a.traction = relative(tractions(hierarchical), tractions(dense));
  a.stress = relative(interior_stresses_hierarchical(problem, hierarchical, points, options, &a.evaluation_stats),
                      interior_stresses(problem, dense, points));
  return a;
}

void expect_agreement(const Agreement& a, const std::string& what) {
  std::printf("  %-40s u %.1e  t %.1e  sigma %.1e  (far blocks %d + %d, rank <= %d, %d iterations)\n", what.c_str(),
              a.displacement, a.traction, a.stress, a.solve_stats.far_blocks, a.evaluation_stats.far_blocks,
              a.solve_stats.largest_rank, a.solve_stats.iterations);
  // The compression is what is tested: the far field must be there.
  EXPECT_GT(a.solve_stats.far_blocks, 0) << what;
  EXPECT_GT(a.evaluation_stats.far_blocks, 0) << what;
  // Blocks to 1e-8 (the default tolerance), the GMRES residual to 1e-10: the solve amplifies both by the
  // conditioning, measured below 30 here; 1e-6 leaves a margin.
  EXPECT_LE(a.displacement, 1e-6) << what;
  EXPECT_LE(a.traction, 1e-6) << what;
  EXPECT_LE(a.stress, 1e-6) << what;
}

// Points of a regular n x n grid over the box [lo, hi] that lie inside the polygon, at least `margin` from it.
std::vector<Vector2d> grid_inside(const std::vector<Vector2d>& polygon, Vector2d lo, Vector2d hi, int n,
                                  double margin) {
  std::vector<Vector2d> points;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vector2d x = lo + Vector2d((i + 0.5) / n * (hi - lo).x(), (j + 0.5) / n * (hi - lo).y());
      bool inside = false;
      double distance = HUGE_VAL;
      for (std::size_t k = 0; k < polygon.size(); ++k) {
        const Vector2d a = polygon[k], b = polygon[(k + 1) % polygon.size()];
        const double s = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        distance = std::min(distance, (x - (a + s * (b - a))).norm());
        if ((a.y() > x.y()) != (b.y() > x.y()) && x.x() < a.x() + (x.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x()))
          inside = !inside;
      }
      if (inside && distance > margin) points.push_back(x);
    }
  return points;
}

// The exact data of `field` on a polygon given node by node; side_of_node[k] says which side node k starts.
BoundaryProblem problem_on_nodes(const std::vector<Vector2d>& nodes, const std::vector<std::size_t>& side_of_node,
                                 const std::vector<SideCondition>& sides, const Field& field) {
  BoundaryProblem problem;
  problem.material = kSteel;
  problem.nodes = nodes;
  const std::size_t n = nodes.size();
  for (std::size_t e = 0; e < n; ++e) {
    const Vector2d x0 = nodes[e], x1 = nodes[(e + 1) % n];
    const Vector2d t = (x1 - x0).normalized(), normal(t.y(), -t.x());
    ElementData data;
    data.displacement_prescribed = sides[side_of_node[e]];
    for (int c = 0; c < 2; ++c) {
      const bool u = data.displacement_prescribed[static_cast<std::size_t>(c)];
      data.value(c, 0) = u ? field.displacement(x0)(c) : field.traction(x0, normal)(c);
      data.value(c, 1) = u ? field.displacement(x1)(c) : field.traction(x1, normal)(c);
    }
    problem.elements.push_back(data);
  }
  return problem;
}

}  // namespace

TEST(HBemClusterTree, LeavesPartitionThePointsAndTheBlocksCoverEveryPairOnce) {
  std::vector<Vector2d> points;
  for (int k = 0; k < 500; ++k) points.emplace_back(std::cos(0.01 * k * k), std::sin(0.37 * k) * (1 + 0.001 * k));
  const ClusterTree tree(points, 16);
  std::vector<int> seen(points.size(), 0);
  for (const auto& c : tree.clusters()) {
    if (!c.leaf()) continue;
    EXPECT_LE(c.size(), 16);
    for (int p = c.begin; p < c.end; ++p) ++seen[static_cast<std::size_t>(tree.order()[static_cast<std::size_t>(p)])];
  }
  for (int s : seen) EXPECT_EQ(s, 1);
  std::vector<BoundingBox> boxes(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) boxes[k].extend(points[k]);
  const std::vector<BoundingBox> cluster_boxes = tree.cluster_boxes(boxes);
  long covered = 0;
  for (const BlockPair& b : block_partition(tree, cluster_boxes, tree, cluster_boxes, 1.0)) {
    const auto& r = tree.clusters()[static_cast<std::size_t>(b.row_cluster)];
    const auto& c = tree.clusters()[static_cast<std::size_t>(b.column_cluster)];
    covered += static_cast<long>(r.size()) * c.size();
    const BoundingBox &rb = cluster_boxes[static_cast<std::size_t>(b.row_cluster)],
                      &cb = cluster_boxes[static_cast<std::size_t>(b.column_cluster)];
    if (b.admissible) {
      EXPECT_GT(rb.distance(cb), 0.0);
      EXPECT_LE(std::min(rb.diameter(), cb.diameter()), rb.distance(cb));
    } else {
      EXPECT_TRUE(r.leaf() && c.leaf());
    }
  }
  EXPECT_EQ(covered, 500L * 500L);
}

TEST(HBemAca, LogarithmicKernelOfSeparatedClustersIsApproximatedToTheTolerance) {
  // ln|x - y| between two point sets one diameter apart: smooth, so ACA converges geometrically.
  const int m = 120, n = 90;
  Eigen::MatrixXd a(m, n);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) {
      const Vector2d x(std::cos(0.05 * i), std::sin(0.05 * i)), y(3.0 + 0.01 * j, 0.3 * std::sin(0.1 * j));
      a(i, j) = std::log((x - y).norm());
    }
  for (const double tolerance : {1e-4, 1e-8}) {
    LowRank block = adaptive_cross_approximation(
        m, n, [&](int i, Eigen::Ref<Eigen::VectorXd> out) { out = a.row(i).transpose(); },
        [&](int j, Eigen::Ref<Eigen::VectorXd> out) { out = a.col(j); }, tolerance, 45);
    const int aca_rank = block.rank();
    EXPECT_LT(aca_rank, 45);
    EXPECT_LE((block.U * block.V.transpose() - a).norm(), 10 * tolerance * a.norm());
    recompress(block, tolerance);
    EXPECT_LE(block.rank(), aca_rank);
    EXPECT_LE((block.U * block.V.transpose() - a).norm(), 20 * tolerance * a.norm());
  }
}

TEST(HBemGmres, SolvesANonsymmetricSystemToTheToleranceAndStopsWhenCancelled) {
  const int n = 300;
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(n, n) / std::sqrt(n) + 2.0 * Eigen::MatrixXd::Identity(n, n);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  const Eigen::VectorXd exact = a.partialPivLu().solve(b);
  const LinearOperator multiply = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = a * x; };
  const LinearOperator jacobi = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    y = x.cwiseQuotient(a.diagonal());
  };
  GmresOptions options;
  options.restart = 20;  // restarts happen
  Eigen::VectorXd x;
  const contact::SolveReport r = gmres(multiply, jacobi, b, x, options);
  EXPECT_TRUE(r.converged());
  EXPECT_LE((b - a * x).norm(), 1e-9 * b.norm());
  EXPECT_LE((x - exact).norm(), 1e-8 * exact.norm());
  int calls = 0;
  options.cancelled = [&] { return ++calls > 5; };
  x.setZero();
  const contact::SolveReport c = gmres(multiply, jacobi, b, x, options);
  EXPECT_TRUE(c.cancelled());
  EXPECT_EQ(c.iterations, 5);
}

TEST(HBemAgreesWithDense, LameQuarterRing) {
  const Lame lame;
  for (const int m : {32, 64}) {
    const BoundaryProblem problem = quarter_ring(lame, m);
    std::vector<Vector2d> points;
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) {
        const double r = 1.05 + 0.9 * i / 11.0, angle = kPi / 2 * (j + 0.5) / 12;
        points.emplace_back(r * std::cos(angle), r * std::sin(angle));
      }
    expect_agreement(compare_with_dense(problem, points), "Lame ring, m = " + std::to_string(m));
  }
}

TEST(HBemAgreesWithDense, QuadraticFieldOnASquareWithMixedDataAndClampedCorners) {
  const Field field = quadratic_field(kSteel);
  const std::vector<SideCondition> sides{kDisplacement, kTraction, kRollerY, kDisplacement};
  const BoundaryProblem problem = polygon_problem(kSquare, sides, 1.0 / 64, field, kSteel);
  expect_agreement(compare_with_dense(problem, grid_inside(kSquare, {0, 0}, {1, 1}, 14, 0.01)),
                   "square, h = 1/64 (256 nodes)");
}

TEST(HBemAgreesWithDense, QuadraticFieldOnATriangle) {
  const Field field = quadratic_field(kSteel);
  const std::vector<Vector2d> triangle{{0, 0}, {2, 0}, {0.4, 1.5}};
  const std::vector<SideCondition> sides{kDisplacement, kTraction, kRollerX};
  const BoundaryProblem problem = polygon_problem(triangle, sides, 1.0 / 40, field, kSteel);
  expect_agreement(compare_with_dense(problem, grid_inside(triangle, {0, 0}, {2, 1.5}, 16, 0.01)),
                   "triangle, h = 1/40 (" + std::to_string(problem.nodes.size()) + " nodes)");
}

TEST(HBemInterpolation, ChebyshevGridIsExactForItsDegreeAndReachesTheToleranceAtOneDiameter) {
  const ChebyshevGrid grid = ChebyshevGrid::for_tolerance(1e-8);
  const int p = grid.per_direction();
  EXPECT_EQ(p, 12);  // rho = 3 + sqrt(8): rho^-11 < 1e-8
  BoundingBox box;
  box.extend(Vector2d(1.0, 2.0));
  box.extend(Vector2d(1.6, 2.4));
  const auto values_at = [&](const std::function<double(const Vector2d&)>& f) {
    Eigen::MatrixX3d v = Eigen::MatrixX3d::Zero(grid.nodes(), 3);
    const std::vector<Vector2d> nodes = grid.nodes_in(box);
    for (int k = 0; k < grid.nodes(); ++k) v(k, 0) = f(nodes[static_cast<std::size_t>(k)]);
    return v;
  };
  // Degree p - 1 in each coordinate: exact to round-off.
  const auto polynomial = [&](const Vector2d& x) { return std::pow(x.x(), p - 1) * std::pow(x.y(), p - 1) + x.x() - 3 * x.y(); };
  // A stress-kernel-like 1/r^2 (times an angle factor) from a source one box diameter from the box.
  const Vector2d source = box.hi + box.diameter() * Vector2d(1, 1).normalized();
  const auto kernel = [&](const Vector2d& x) { return (x - source).x() * (x - source).y() / std::pow((x - source).squaredNorm(), 2); };
  const Eigen::MatrixX3d poly_values = values_at(polynomial), kernel_values = values_at(kernel);
  double poly_error = 0.0, kernel_error = 0.0, kernel_max = 0.0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Vector2d x = box.lo + Vector2d(i / 20.0 * 0.6, j / 20.0 * 0.4);
      poly_error = std::max(poly_error, std::abs(grid.at(box, poly_values, x)(0) - polynomial(x)) / std::abs(polynomial(x)));
      kernel_error = std::max(kernel_error, std::abs(grid.at(box, kernel_values, x)(0) - kernel(x)));
      kernel_max = std::max(kernel_max, std::abs(kernel(x)));
    }
  std::printf("  p = %d: polynomial %.1e, 1/r^2 kernel at one diameter %.1e (relative)\n", p, poly_error, kernel_error / kernel_max);
  EXPECT_LE(poly_error, 1e-12);
  EXPECT_LE(kernel_error, 1e-8 * kernel_max);
  // Points on a line (a zero-width box): the nodes stay distinct and a linear function is reproduced.
  BoundingBox line;
  line.extend(Vector2d(0, 0));
  line.extend(Vector2d(1, 0));
  Eigen::MatrixX3d linear = Eigen::MatrixX3d::Zero(grid.nodes(), 3);
  const std::vector<Vector2d> nodes = grid.nodes_in(line);
  for (int k = 0; k < grid.nodes(); ++k) linear(k, 0) = 2 * nodes[static_cast<std::size_t>(k)].x() + nodes[static_cast<std::size_t>(k)].y();
  EXPECT_NEAR(grid.at(line, linear, Vector2d(0.3, 0))(0), 0.6, 1e-12);
}

TEST(HBemInterpolation, ManyPointsThroughInterpolatedBoxesAgreeWithTheDenseEvaluation) {
  // The indicator's case: far more points than boundary nodes (a cell centre per cell), down to 1/500 of the
  // square from its boundary; the default leaf size, so the far field is mostly interpolated.
  const Field field = quadratic_field(kSteel);
  const std::vector<SideCondition> sides{kDisplacement, kTraction, kRollerY, kDisplacement};
  const BoundaryProblem problem = polygon_problem(kSquare, sides, 1.0 / 64, field, kSteel);
  const BoundarySolution solution = solve(problem);
  const std::vector<Vector2d> points = grid_inside(kSquare, {0, 0}, {1, 1}, 110, 0.002);
  for (const double tolerance : {1e-8, 1e-6}) {
    HierarchicalOptions options;
    options.tolerance = tolerance;
    HierarchicalStats stats;
    const double difference = relative(interior_stresses_hierarchical(problem, solution, points, options, &stats),
                                       interior_stresses(problem, solution, points));
    std::printf("  %zu points, tolerance %.0e: %d interpolated of %d far blocks, difference %.1e\n", points.size(),
                tolerance, stats.interpolated_blocks, stats.far_blocks, difference);
    EXPECT_GT(stats.interpolated_blocks, 0);
    EXPECT_LE(difference, 10 * tolerance);
  }
}

TEST(HBemAgreesWithDense, LShapeGradedTowardsTheReentrantCorner) {
  // Element sizes growing geometrically (ratio 1.15) from 1e-3 away from the re-entrant corner (0.5, 0.5) on the
  // two sides that meet there; h = 1/32 elsewhere.
  const Field field = quadratic_field(kSteel);
  const Vector2d corner(0.5, 0.5);
  std::vector<Vector2d> nodes;
  std::vector<std::size_t> side;
  for (std::size_t k = 0; k < kLShape.size(); ++k) {
    const Vector2d a = kLShape[k], b = kLShape[(k + 1) % kLShape.size()];
    const double length = (b - a).norm();
    const bool graded_at_start = (a - corner).norm() < 1e-12, graded_at_end = (b - corner).norm() < 1e-12;
    // Distances from the graded end (or from a), the last gap at least half the previous one.
    std::vector<double> d{0.0};
    double h = graded_at_start || graded_at_end ? 1e-3 : 1.0 / 32;
    while (d.back() + 1.5 * h < length) {
      d.push_back(d.back() + h);
      if (graded_at_start || graded_at_end) h *= 1.15;
    }
    std::vector<double> t;  // positions along a -> b in [0, 1), ascending
    if (graded_at_end) {
      t.push_back(0.0);
      for (std::size_t j = d.size(); j-- > 1;) t.push_back(1.0 - d[j] / length);
    } else {
      for (const double v : d) t.push_back(v / length);
    }
    for (const double v : t) {
      nodes.push_back(a + v * (b - a));
      side.push_back(k);
    }
  }
  const std::vector<SideCondition> sides{kDisplacement, kTraction, kTraction, kTraction, kTraction, kRollerY};
  const BoundaryProblem problem = problem_on_nodes(nodes, side, sides, field);
  expect_agreement(compare_with_dense(problem, grid_inside(kLShape, {0, 0}, {1, 1}, 16, 0.005)),
                   "L-shape graded, " + std::to_string(nodes.size()) + " nodes");
}

TEST(HBemAgreesWithDense, SquareAdaptivelyRefinedTowardsACorner) {
  // The boundary an adaptive FE mesh induces: h = 1/16, then six levels of bisecting every element within
  // 0.5^level of the corner (1, 1) (the new nodes are straight, "hanging", nodes).
  const Field field = quadratic_field(kSteel);
  std::vector<Vector2d> nodes;
  std::vector<std::size_t> side;
  for (std::size_t k = 0; k < kSquare.size(); ++k)
    for (int j = 0; j < 16; ++j) {
      nodes.push_back(kSquare[k] + (kSquare[(k + 1) % 4] - kSquare[k]) * (j / 16.0));
      side.push_back(k);
    }
  for (int level = 1; level <= 6; ++level) {
    std::vector<Vector2d> refined;
    std::vector<std::size_t> refined_side;
    for (std::size_t e = 0; e < nodes.size(); ++e) {
      refined.push_back(nodes[e]);
      refined_side.push_back(side[e]);
      const Vector2d middle = 0.5 * (nodes[e] + nodes[(e + 1) % nodes.size()]);
      if ((middle - Vector2d(1, 1)).norm() < std::pow(0.5, level)) {
        refined.push_back(middle);
        refined_side.push_back(side[e]);
      }
    }
    nodes = refined;
    side = refined_side;
  }
  const std::vector<SideCondition> sides{kRollerX, kTraction, kTraction, kDisplacement};
  const BoundaryProblem problem = problem_on_nodes(nodes, side, sides, field);
  expect_agreement(compare_with_dense(problem, grid_inside(kSquare, {0, 0}, {1, 1}, 14, 0.005)),
                   "square refined at a corner, " + std::to_string(nodes.size()) + " nodes");
}

TEST(HBemInput, SelfOverlapOutsidePointsAndCancellationAreReported) {
  const Field field = linear_field(kSteel);
  // A square whose fourth side runs down through the bottom one (positive area, so only the crossing is wrong).
  const std::vector<Vector2d> crossed{{0, 0}, {2, 0}, {2, 2}, {1, 2}, {1, -1}};
  const BoundaryProblem crossing =
      polygon_problem(crossed, std::vector<SideCondition>(5, kDisplacement), 0.05, field, kSteel);
  const std::vector<SideCondition> sides(4, kDisplacement);
  try {
    solve_hierarchical(crossing, small_leaves());
    ADD_FAILURE() << "a self-intersecting polygon was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("self-overlapping"), std::string::npos) << e.what();
  }
  const BoundaryProblem square = polygon_problem(kSquare, sides, 1.0 / 32, field, kSteel);
  const BoundarySolution solution = solve_hierarchical(square, small_leaves());
  EXPECT_THROW(interior_stresses_hierarchical(square, solution, {{0.5, 0.5}, {1.5, 0.5}}, small_leaves()),
               std::invalid_argument);
  EXPECT_THROW(interior_stresses_hierarchical(square, solution, {{0.5, 0.5}, {1.0, 0.5}}, small_leaves()),
               std::invalid_argument);
  HierarchicalOptions cancelled = small_leaves();
  int polls = 0;
  cancelled.cancelled = [&] { return ++polls > 3; };
  EXPECT_THROW(solve_hierarchical(square, cancelled), Cancelled);
}

TEST(HBemCancel, PollsThroughoutAndACancelStopsTheSolveAndTheEvaluationLongBeforeTheirEnd) {
  // A disc of 8192 boundary nodes (a few seconds of work). First the longest time between two polls of the
  // cancellation callback, from the call to its return, in the solve and in the evaluation at 8192 points. It is
  // checked as a share of the call's own time, not as a wall time (tests run on loaded 2-core machines, which
  // stretch both alike): normally a few hundredths of a second of several seconds; a part of the work that does not
  // poll shows as a large share.
  const BoundaryProblem problem = disc_problem(8192);
  const std::vector<Vector2d> points = interior_points(8192);
  using Clock = std::chrono::steady_clock;
  Clock::time_point last;
  double longest = 0.0;
  HierarchicalOptions options;
  options.cancelled = [&] {
    const Clock::time_point now = Clock::now();
    longest = std::max(longest, std::chrono::duration<double>(now - last).count());
    last = now;
    return false;
  };
  const auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  last = Clock::now();
  Clock::time_point start = last;
  const BoundarySolution solution = solve_hierarchical(problem, options);
  longest = std::max(longest, seconds_since(last));
  const double solve_gap = longest, solve_seconds = seconds_since(start);
  longest = 0.0;
  last = start = Clock::now();
  interior_stresses_hierarchical(problem, solution, points, options);
  longest = std::max(longest, seconds_since(last));
  const double evaluation_gap = longest, evaluation_seconds = seconds_since(start);
  std::printf("  longest time without a poll: solve %.3f s of %.2f s, evaluation %.3f s of %.2f s\n", solve_gap,
              solve_seconds, evaluation_gap, evaluation_seconds);
  EXPECT_LT(solve_gap, std::max(0.5, solve_seconds / 4));
  EXPECT_LT(evaluation_gap, std::max(0.5, evaluation_seconds / 4));

  // Then a real cancel from another thread, 0.3 s into each call: the call throws Cancelled (it did not run to its
  // end), normally a millisecond after the cancel (printed); half the call's uncancelled time is a bound that only
  // a cancel left unheeded until the end breaks.
  for (const bool evaluation : {false, true}) {
    std::atomic<bool> flag{false};
    Clock::time_point cancelled_at;
    HierarchicalOptions cancellable;
    cancellable.cancelled = [&] { return flag.load(); };
    std::thread canceller([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      cancelled_at = Clock::now();
      flag.store(true);
    });
    try {
      if (evaluation)
        interior_stresses_hierarchical(problem, solution, points, cancellable);
      else
        solve_hierarchical(problem, cancellable);
      ADD_FAILURE() << "not cancelled";
    } catch (const Cancelled&) {
    }
    const double latency = std::chrono::duration<double>(Clock::now() - cancelled_at).count();
    canceller.join();
    std::printf("  %s stopped %.3f s after the cancel\n", evaluation ? "evaluation" : "solve", latency);
    EXPECT_LT(latency, (evaluation ? evaluation_seconds : solve_seconds) / 2);
  }
}

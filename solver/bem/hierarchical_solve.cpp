// solve_hierarchical(): the collocation system of collocation.cpp, compressed (docs/bem.md, "Hierarchical BEM").
//
// The matrix is never formed in the unknowns directly. Each element contributes to eight "element columns"
//   k = 0..3: h_m(:, j), multiplying the displacement u_j of its node m      (k = 2 m + j)
//   k = 4..7: g_m(:, j) mu / diameter, multiplying -tau_j at its end m        (t = tau mu / diameter)
// and every collocation equation reads M y = 0 plus the rigid-body diagonal, y the element-column vector of the
// boundary state. A block of M (the equations of a row cluster x the element columns of a column cluster) is
// smooth when the clusters are apart, so ACA compresses it; then its columns are contracted with the state's map:
// unknown columns go to the matrix, prescribed values to the right-hand side, and the sum of the h columns per
// component to the rigid-body sums (a collocation node's own coefficient is minus the sum of its others).
// Equations and unknowns are grouped by their home node (docs/bem.md: every node carries as many of each), so a
// leaf cluster's equations and unknowns share one range: the preconditioner's diagonal blocks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "aca.hpp"
#include "../common/scoped_timer.hpp"
#include "bem.hpp"
#include "boundary.hpp"
#include "cluster_tree.hpp"
#include "collocation.hpp"
#include "gmres.hpp"
#include "hmatrix.hpp"
#include "kelvin.hpp"

namespace contact::bem {

namespace {

constexpr int kColumnsPerElement = 8;

// The boxes of the elements (element e joins node e and node e + 1; the tree is on the nodes, so element e
// belongs where node e does).
std::vector<BoundingBox> element_boxes(const BoundaryGeometry& geometry) {
  std::vector<BoundingBox> boxes(geometry.elements.size());
  for (std::size_t e = 0; e < boxes.size(); ++e) {
    boxes[e].extend(geometry.elements[e].start);
    boxes[e].extend(geometry.elements[e].end);
  }
  return boxes;
}

// check_problem()'s self-overlap test, on the element pairs of the near field only (boxes apart cannot touch).
void check_self_overlap(const BoundaryGeometry& geometry, const ClusterTree& tree,
                        const std::vector<BoundingBox>& boxes) {
  const std::vector<BoundingBox> cluster_boxes = tree.cluster_boxes(boxes);
  for (const BlockPair& pair : block_partition(tree, cluster_boxes, tree, cluster_boxes, HUGE_VAL)) {
    if (pair.admissible) continue;
    const auto& a = tree.clusters()[static_cast<std::size_t>(pair.row_cluster)];
    const auto& b = tree.clusters()[static_cast<std::size_t>(pair.column_cluster)];
    for (int p = a.begin; p < a.end; ++p)
      for (int q = b.begin; q < b.end; ++q)
        check_elements_apart(geometry, static_cast<std::size_t>(tree.order()[static_cast<std::size_t>(p)]),
                             static_cast<std::size_t>(tree.order()[static_cast<std::size_t>(q)]));
  }
}

// Where an element column's entry goes: an unknown (position in the tree's order, with its coefficient), or a
// prescribed value (known: the element column's y), and which rigid-body sum it belongs to.
struct ColumnTarget {
  int unknown = -1;
  double coefficient = 0.0;
  double known = 0.0;
  int rigid = -1;
};

// A block contracted from element columns to unknown columns.
struct Contracted {
  std::vector<int> columns;
  Eigen::MatrixXd matrix;  // rows x columns
  Eigen::VectorXd known;   // the block times the prescribed part of y
  Eigen::MatrixX2d rigid;  // the block times the indicator of the h columns of component 0, 1
};

class HierarchicalCollocation {
 public:
  HierarchicalCollocation(const BoundaryProblem& problem, const HierarchicalOptions& options)
      : problem_(problem),
        options_(options),
        geometry_(check_problem(problem, /*self_overlap=*/false)),
        n_(static_cast<int>(problem.nodes.size())),
        tree_(problem.nodes, options.leaf_size),
        kelvin_(effective_constants(problem.material), log_scale(geometry_)),
        traction_scale_(effective_constants(problem.material).shear_modulus / geometry_.diameter) {}

  BoundarySolution run(HierarchicalStats* stats) {
    const auto t0 = Clock::now();
    const std::vector<BoundingBox> boxes = element_boxes(geometry_);
    check_self_overlap(geometry_, tree_, boxes);
    check_rigid_motions(problem_, geometry_);
    num_ = number_unknowns_and_equations(problem_, geometry_);
    order_by_tree();
    HierarchicalMatrix matrix(num_.unknowns);
    rhs_ = Eigen::VectorXd::Zero(num_.unknowns);
    rigid_ = Eigen::MatrixX2d::Zero(num_.unknowns, 2);
    assemble_blocks(matrix, boxes);
    add_rigid_body_terms(matrix);
    matrix.factorize_diagonal(leaf_ranges());
    const double setup = seconds_since(t0);
    const Eigen::VectorXd x = solve_system(matrix);
    if (stats) {
      stats->unknowns = num_.unknowns;
      stats->near_blocks = near_blocks_;
      stats->far_blocks = far_blocks_;
      stats->largest_rank = largest_rank_;
      stats->mean_rank = far_blocks_ > 0 ? static_cast<double>(rank_sum_) / far_blocks_ : 0.0;
      stats->matrix_bytes = matrix.bytes();
      stats->preconditioner_bytes = matrix.preconditioner_bytes();
      stats->iterations = static_cast<int>(gmres_.iterations);
      stats->relative_residual = gmres_.measure;
      stats->setup_seconds = setup;
      stats->solve_seconds = seconds_since(t0) - setup;
    }
    return collect_solution(problem_, num_, x, traction_scale_);
  }

 private:
  // Phase 1: equations and unknowns in the order of their home nodes along the tree.
  void order_by_tree() {
    std::vector<std::vector<int>> rows_of(static_cast<std::size_t>(n_)), unknowns_of(static_cast<std::size_t>(n_));
    std::vector<std::pair<int, int>> row_of_equation(static_cast<std::size_t>(num_.equations));
    for (std::size_t p = 0; p < num_.points.size(); ++p)
      for (int l = 0; l < 2; ++l) {
        const int equation = num_.points[p].equation[static_cast<std::size_t>(l)];
        if (equation < 0) continue;
        rows_of[static_cast<std::size_t>(num_.points[p].home_node)].push_back(equation);
        row_of_equation[static_cast<std::size_t>(equation)] = {static_cast<int>(p), l};
      }
    for (int i = 0; i < n_; ++i)
      for (int c = 0; c < 2; ++c) {
        const auto k = static_cast<std::size_t>(c);
        const auto node = static_cast<std::size_t>(i);
        for (int u : {num_.displacement[node][k], num_.traction[static_cast<std::size_t>((i + n_ - 1) % n_)][k][1],
                      num_.traction[node][k][0]})
          if (u >= 0 && std::find(unknowns_of[node].begin(), unknowns_of[node].end(), u) == unknowns_of[node].end())
            unknowns_of[node].push_back(u);
      }
    unknown_position_.assign(static_cast<std::size_t>(num_.unknowns), -1);
    node_begin_.assign(static_cast<std::size_t>(n_) + 1, 0);
    int position = 0;
    for (int p = 0; p < n_; ++p) {
      const auto node = static_cast<std::size_t>(tree_.order()[static_cast<std::size_t>(p)]);
      if (rows_of[node].size() != unknowns_of[node].size())
        throw std::logic_error("bem: node " + std::to_string(node) + " carries " +
                               std::to_string(rows_of[node].size()) + " equations but " +
                               std::to_string(unknowns_of[node].size()) + " unknowns");
      for (std::size_t k = 0; k < rows_of[node].size(); ++k) {
        const auto [point, component] = row_of_equation[static_cast<std::size_t>(rows_of[node][k])];
        row_point_.push_back(point);
        row_component_.push_back(component);
        unknown_position_[static_cast<std::size_t>(unknowns_of[node][k])] = position++;
      }
      node_begin_[static_cast<std::size_t>(p) + 1] = position;
    }
  }

  int row_begin(int cluster) const { return node_begin_[static_cast<std::size_t>(cluster_of(cluster).begin)]; }
  int row_end(int cluster) const { return node_begin_[static_cast<std::size_t>(cluster_of(cluster).end)]; }
  const ClusterTree::Cluster& cluster_of(int c) const { return tree_.clusters()[static_cast<std::size_t>(c)]; }
  int element_at(int position) const { return tree_.order()[static_cast<std::size_t>(position)]; }

  std::vector<std::pair<int, int>> leaf_ranges() const {
    std::vector<std::pair<int, int>> ranges;
    for (std::size_t c = 0; c < tree_.clusters().size(); ++c)
      if (tree_.clusters()[c].leaf()) ranges.emplace_back(row_begin(static_cast<int>(c)), row_end(static_cast<int>(c)));
    return ranges;
  }

  // The collocation boxes of the row clusters: the points carrying each node's equations.
  std::vector<BoundingBox> row_boxes() const {
    std::vector<BoundingBox> boxes(static_cast<std::size_t>(n_));
    for (const CollocationPoint& p : num_.points)
      if (p.equation[0] >= 0 || p.equation[1] >= 0) boxes[static_cast<std::size_t>(p.home_node)].extend(p.position);
    for (int i = 0; i < n_; ++i)  // a corner node's box holds the node too (its shifted points are next to it)
      boxes[static_cast<std::size_t>(i)].extend(problem_.nodes[static_cast<std::size_t>(i)]);
    return tree_.cluster_boxes(boxes);
  }

  // Phase 2: every block of the partition, near ones exactly, far ones by ACA; contracted into the matrix.
  void assemble_blocks(HierarchicalMatrix& matrix, const std::vector<BoundingBox>& boxes) {
    const std::vector<BlockPair> pairs =
        block_partition(tree_, row_boxes(), tree_, tree_.cluster_boxes(boxes), options_.eta);
    for (const BlockPair& pair : pairs) {
      if (options_.cancelled && options_.cancelled()) throw Cancelled();
      const int r0 = row_begin(pair.row_cluster), rows = row_end(pair.row_cluster) - r0;
      const auto& columns = cluster_of(pair.column_cluster);
      const int elements = columns.size();
      if (rows == 0) continue;
      LowRank low_rank;
      bool compressed = false;
      if (pair.admissible) {
        const int max_rank = std::min(rows, kColumnsPerElement * elements) / 2;
        low_rank = adaptive_cross_approximation(
            rows, kColumnsPerElement * elements,
            [&](int i, Eigen::Ref<Eigen::VectorXd> out) { element_row(r0 + i, columns.begin, columns.end, out); },
            [&](int j, Eigen::Ref<Eigen::VectorXd> out) { element_column(r0, rows, columns.begin, j, out); },
            options_.tolerance, max_rank);
        compressed = low_rank.rank() < max_rank;
      }
      MatrixBlock block;
      block.row_begin = r0;
      if (compressed) {
        recompress(low_rank, options_.tolerance);
        const Contracted c = contract(low_rank.V.transpose(), columns.begin, columns.end);
        block.columns = c.columns;
        block.U = low_rank.U;
        block.W = c.matrix;
        rhs_.segment(r0, rows) -= low_rank.U * c.known;
        rigid_.middleRows(r0, rows) += low_rank.U * c.rigid;
        ++far_blocks_;
        rank_sum_ += low_rank.rank();
        largest_rank_ = std::max(largest_rank_, low_rank.rank());
      } else {
        const Contracted c = contract(element_block(r0, rows, columns.begin, columns.end), columns.begin, columns.end);
        block.columns = c.columns;
        block.dense = c.matrix;
        rhs_.segment(r0, rows) -= c.known;
        rigid_.middleRows(r0, rows) += c.rigid;
        ++near_blocks_;
      }
      if (!block.columns.empty()) matrix.add(std::move(block));
    }
  }

  // Element column k of one element's coefficients, in equation direction l.
  double column_value(const ElementCoefficients& c, int l, int k) const {
    const auto m = static_cast<std::size_t>((k / 2) % 2);
    const int j = k % 2;
    if (k < 4) return c.skip[m] ? 0.0 : c.h[m](l, j);
    return c.g[m](l, j) * traction_scale_;
  }

  ElementCoefficients coefficients(int row, int element) const {
    const CollocationPoint& point = num_.points[static_cast<std::size_t>(row_point_[static_cast<std::size_t>(row)])];
    return element_coefficients(kelvin_, geometry_.elements[static_cast<std::size_t>(element)], point, element, n_);
  }

  void element_row(int row, int position_begin, int position_end, Eigen::Ref<Eigen::VectorXd> out) const {
    const int l = row_component_[static_cast<std::size_t>(row)];
    for (int p = position_begin; p < position_end; ++p) {
      const ElementCoefficients c = coefficients(row, element_at(p));
      for (int k = 0; k < kColumnsPerElement; ++k)
        out(kColumnsPerElement * (p - position_begin) + k) = column_value(c, l, k);
    }
  }

  void element_column(int r0, int rows, int position_begin, int j, Eigen::Ref<Eigen::VectorXd> out) const {
    const int element = element_at(position_begin + j / kColumnsPerElement);
    ElementCoefficients c;
    for (int i = 0; i < rows; ++i) {
      // Rows of one point are adjacent: its second direction reuses the coefficients.
      const auto row = static_cast<std::size_t>(r0 + i);
      if (i == 0 || row_point_[row] != row_point_[row - 1]) c = coefficients(r0 + i, element);
      out(i) = column_value(c, row_component_[row], j % kColumnsPerElement);
    }
  }

  Eigen::MatrixXd element_block(int r0, int rows, int position_begin, int position_end) const {
    const int elements = position_end - position_begin;
    Eigen::MatrixXd block(rows, kColumnsPerElement * elements);
    std::vector<ElementCoefficients> cache(static_cast<std::size_t>(elements));
    int cached_point = -1;
    for (int i = 0; i < rows; ++i) {
      const int point = row_point_[static_cast<std::size_t>(r0 + i)];
      if (point != cached_point) {  // both directions of a point from one set of coefficients
        for (int e = 0; e < elements; ++e)
          cache[static_cast<std::size_t>(e)] = coefficients(r0 + i, element_at(position_begin + e));
        cached_point = point;
      }
      const int l = row_component_[static_cast<std::size_t>(r0 + i)];
      for (int e = 0; e < elements; ++e)
        for (int k = 0; k < kColumnsPerElement; ++k)
          block(i, kColumnsPerElement * e + k) = column_value(cache[static_cast<std::size_t>(e)], l, k);
    }
    return block;
  }

  ColumnTarget column_target(int element, int k) const {
    const int m = (k / 2) % 2, j = k % 2;
    const auto e = static_cast<std::size_t>(element);
    ColumnTarget target;
    if (k < 4) {
      const int node = (element + m) % n_;
      const int u = num_.displacement[static_cast<std::size_t>(node)][static_cast<std::size_t>(j)];
      target.rigid = j;
      if (u >= 0) {
        target.unknown = unknown_position_[static_cast<std::size_t>(u)];
        target.coefficient = 1.0;
      } else {
        target.known = num_.known_displacement(node, j);
      }
      return target;
    }
    const int t = num_.traction[e][static_cast<std::size_t>(j)][static_cast<std::size_t>(m)];
    if (t >= 0) {
      target.unknown = unknown_position_[static_cast<std::size_t>(t)];
      target.coefficient = -1.0;  // y = -tau
    } else {
      target.known = -problem_.elements[e].value(j, m) / traction_scale_;
    }
    return target;
  }

  // Phase 3: element columns (of a dense block, or of V^T) to unknown columns, known values and rigid sums.
  Contracted contract(const Eigen::MatrixXd& block, int position_begin, int position_end) const {
    Contracted out;
    std::vector<ColumnTarget> targets;
    for (int p = position_begin; p < position_end; ++p)
      for (int k = 0; k < kColumnsPerElement; ++k) {
        targets.push_back(column_target(element_at(p), k));
        if (targets.back().unknown >= 0) out.columns.push_back(targets.back().unknown);
      }
    std::sort(out.columns.begin(), out.columns.end());
    out.columns.erase(std::unique(out.columns.begin(), out.columns.end()), out.columns.end());
    out.matrix = Eigen::MatrixXd::Zero(block.rows(), static_cast<Eigen::Index>(out.columns.size()));
    out.known = Eigen::VectorXd::Zero(block.rows());
    out.rigid = Eigen::MatrixX2d::Zero(block.rows(), 2);
    for (std::size_t k = 0; k < targets.size(); ++k) {
      const ColumnTarget& t = targets[k];
      const auto column = block.col(static_cast<Eigen::Index>(k));
      if (t.rigid >= 0) out.rigid.col(t.rigid) += column;
      if (t.unknown < 0) {
        out.known += t.known * column;
        continue;
      }
      const auto local = std::lower_bound(out.columns.begin(), out.columns.end(), t.unknown) - out.columns.begin();
      out.matrix.col(local) += t.coefficient * column;
    }
    return out;
  }

  // Phase 4: a collocation node's own coefficient is minus the sum of its row's others (the rigid-body identity).
  void add_rigid_body_terms(HierarchicalMatrix& matrix) {
    for (int r = 0; r < num_.unknowns; ++r) {
      const CollocationPoint& point = num_.points[static_cast<std::size_t>(row_point_[static_cast<std::size_t>(r)])];
      if (point.node < 0) continue;
      const auto node = static_cast<std::size_t>(point.node);
      for (int j = 0; j < 2; ++j) {
        const double own = -rigid_(r, j);
        const int u = num_.displacement[node][static_cast<std::size_t>(j)];
        if (u >= 0)
          matrix.add(MatrixEntry{r, unknown_position_[static_cast<std::size_t>(u)], own});
        else
          rhs_(r) -= own * num_.known_displacement(point.node, j);
      }
    }
  }

  // Phase 5: GMRES in the tree's order; the result back in the numbering's order.
  Eigen::VectorXd solve_system(const HierarchicalMatrix& matrix) {
    GmresOptions gmres_options;
    gmres_options.relative_tolerance = options_.solver_tolerance;
    gmres_options.restart = options_.restart;
    gmres_options.max_iterations = options_.max_iterations;
    gmres_options.cancelled = options_.cancelled;
    Eigen::VectorXd y = Eigen::VectorXd::Zero(num_.unknowns);
    gmres_ = gmres([&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { matrix.multiply(in, out); },
                   [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { matrix.precondition(in, out); }, rhs_, y,
                   gmres_options);
    if (gmres_.cancelled()) throw Cancelled();
    if (!gmres_.converged())
      throw std::runtime_error("bem: GMRES did not converge in " + std::to_string(gmres_.iterations) +
                               " iterations (relative residual " + std::to_string(gmres_.measure) + ")");
    Eigen::VectorXd x(num_.unknowns);
    for (int u = 0; u < num_.unknowns; ++u) x(u) = y(unknown_position_[static_cast<std::size_t>(u)]);
    return x;
  }

  const BoundaryProblem& problem_;
  const HierarchicalOptions& options_;
  BoundaryGeometry geometry_;
  int n_;
  ClusterTree tree_;
  KelvinSolution kelvin_;
  double traction_scale_;
  Numbering num_;
  std::vector<int> row_point_, row_component_;  // per row in the tree's order
  std::vector<int> unknown_position_;           // unknown -> position in the tree's order
  std::vector<int> node_begin_;                 // node position -> first row (and unknown) of that node
  Eigen::VectorXd rhs_;
  Eigen::MatrixX2d rigid_;
  int near_blocks_ = 0, far_blocks_ = 0, largest_rank_ = 0;
  long rank_sum_ = 0;
  SolveReport gmres_;
};

}  // namespace

BoundarySolution solve_hierarchical(const BoundaryProblem& problem, const HierarchicalOptions& options,
                                    HierarchicalStats* stats) {
  return HierarchicalCollocation(problem, options).run(stats);
}

BoundarySolution solve_auto(const BoundaryProblem& problem, const HierarchicalOptions& options) {
  return problem.nodes.size() >= kHierarchicalFromNodes ? solve_hierarchical(problem, options) : solve(problem);
}

}  // namespace contact::bem

// interior_stresses_hierarchical(): Somigliana's stress identity at many points through a second cluster tree,
// on the points (docs/bem.md, "Hierarchical BEM"). As in hierarchical_solve.cpp, each element has eight element
// columns, here for the stress (3 rows per point):
//   k = 0..3: int D N_m (:, j) mu / diameter, times t_j at its end m divided by mu / diameter     (k = 2 m + j)
//   k = 4..7: -int S N_m (:, j), times u_j at its node m
// A far-field block whose points' box is small against its distance to the elements (diam <= eta dist) and holds
// many points is interpolated: the block's stresses at the p x p Chebyshev nodes of the points' box, summed
// exactly, then the tensor-product polynomial through them at every point of the box (the field of elements
// that far is analytic over the box; see interpolation.hpp). Other far blocks are compressed by ACA and applied
// to the element-column values at once (nothing is stored); a near-field block is summed exactly, as
// interior_stresses() does. The inside test uses the boundary's tree: the ray crossings and the distance to the
// boundary visit only the clusters whose boxes can matter.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>

#include "aca.hpp"
#include "../common/scoped_timer.hpp"
#include "bem.hpp"
#include "boundary.hpp"
#include "cluster_tree.hpp"
#include "interpolation.hpp"
#include "kelvin.hpp"
#include "quadrature.hpp"

namespace contact::bem {

namespace {

constexpr int kColumnsPerElement = 8;
using StressColumns = Eigen::Matrix<double, 3, kColumnsPerElement>;

class HierarchicalSomigliana {
 public:
  HierarchicalSomigliana(const BoundaryProblem& problem, const BoundarySolution& solution,
                         const std::vector<Eigen::Vector2d>& points, const HierarchicalOptions& options)
      : geometry_(check_problem(problem, /*self_overlap=*/false)),
        points_(points),
        options_(options),
        kelvin_(effective_constants(problem.material), log_scale(geometry_)),
        traction_scale_(effective_constants(problem.material).shear_modulus / geometry_.diameter),
        sources_(problem.nodes, options.leaf_size),
        targets_(points, options.leaf_size),
        interpolation_(ChebyshevGrid::for_tolerance(options.tolerance)) {
    check_solution(problem, solution);
    element_values(solution);
    std::vector<BoundingBox> boxes(geometry_.elements.size());
    for (std::size_t e = 0; e < boxes.size(); ++e) {
      boxes[e].extend(geometry_.elements[e].start);
      boxes[e].extend(geometry_.elements[e].end);
    }
    source_boxes_ = sources_.cluster_boxes(boxes);
  }

  Eigen::MatrixX3d run(HierarchicalStats* stats) {
    const auto t0 = Clock::now();
    for (const Eigen::Vector2d& x : points_) check_inside(x);
    std::vector<BoundingBox> point_boxes(points_.size());
    for (std::size_t k = 0; k < points_.size(); ++k) point_boxes[k].extend(points_[k]);
    target_boxes_ = targets_.cluster_boxes(point_boxes);
    const std::vector<BlockPair> pairs =
        block_partition(targets_, target_boxes_, sources_, source_boxes_, options_.eta);
    stresses_ = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(points_.size()), 3);
    for (const BlockPair& pair : pairs) {
      if (options_.cancelled && options_.cancelled()) throw Cancelled();
      if (!pair.admissible) {
        add_near_block(pair);
      } else if (interpolates(pair) || splits_for_interpolation(pair)) {
        add_far_field(pair);
      } else if (!add_far_block(pair)) {
        add_near_block(pair);
      }
    }
    apply_interpolation();
    if (stats) {
      stats->near_blocks = near_blocks_;
      stats->far_blocks = far_blocks_ + interpolated_blocks_;
      stats->interpolated_blocks = interpolated_blocks_;
      stats->largest_rank = largest_rank_;
      stats->mean_rank = far_blocks_ > 0 ? static_cast<double>(rank_sum_) / far_blocks_ : 0.0;
      stats->setup_seconds = 0.0;
      stats->solve_seconds = seconds_since(t0);
    }
    return stresses_;
  }

 private:
  // The element-column values y of the boundary state (see the file comment).
  void element_values(const BoundarySolution& solution) {
    const auto n = static_cast<Eigen::Index>(geometry_.elements.size());
    values_.resize(kColumnsPerElement * n);
    for (Eigen::Index e = 0; e < n; ++e)
      for (int m = 0; m < 2; ++m)
        for (int j = 0; j < 2; ++j) {
          values_(kColumnsPerElement * e + 2 * m + j) =
              solution.traction[static_cast<std::size_t>(e)](j, m) / traction_scale_;
          values_(kColumnsPerElement * e + 4 + 2 * m + j) = solution.displacement((e + m) % n, j);
        }
  }

  // check_interior_point() through the tree: the even-odd count of crossings of the ray to +x, and the distance.
  void check_inside(const Eigen::Vector2d& x) const {
    const double tolerance = 1e-12 * geometry_.diameter;
    bool inside = false, on_boundary = false;
    const std::function<void(int)> visit = [&](int c) {
      const BoundingBox& box = source_boxes_[static_cast<std::size_t>(c)];
      const bool ray_hits = box.lo.y() <= x.y() && x.y() <= box.hi.y() && x.x() <= box.hi.x();
      if (!ray_hits && box.distance(x) > tolerance) return;
      const auto& cluster = sources_.clusters()[static_cast<std::size_t>(c)];
      if (!cluster.leaf()) {
        for (int child : cluster.children) visit(child);
        return;
      }
      for (int p = cluster.begin; p < cluster.end; ++p) {
        const BoundaryElement& el =
            geometry_.elements[static_cast<std::size_t>(sources_.order()[static_cast<std::size_t>(p)])];
        if (distance_to_segment(x, el.start, el.end) <= tolerance) on_boundary = true;
        if ((el.start.y() > x.y()) != (el.end.y() > x.y())) {
          const double crossing =
              el.start.x() + (x.y() - el.start.y()) / (el.end.y() - el.start.y()) * (el.end.x() - el.start.x());
          if (x.x() < crossing) inside = !inside;
        }
      }
    };
    if (!x.allFinite()) throw std::invalid_argument("bem: the interior point is not finite");
    visit(0);
    if (on_boundary || !inside) check_interior_point(geometry_, x);  // the exact test, for its message
  }

  StressColumns coefficients(int point, int element) const {
    return coefficients_at(points_[static_cast<std::size_t>(point)], element);
  }

  StressColumns coefficients_at(const Eigen::Vector2d& xi, int element) const {
    const BoundaryElement& el = geometry_.elements[static_cast<std::size_t>(element)];
    StressColumns out = StressColumns::Zero();
    integrate_adaptively(el.start, el.tangent, 0.0, el.length, xi, [&](double s, double w) {
      const Eigen::Vector2d r = el.start + s * el.tangent - xi;
      const Eigen::Matrix<double, 3, 2> d = kelvin_.stress_by_traction(r) * (w * traction_scale_);
      const Eigen::Matrix<double, 3, 2> sk = kelvin_.stress_by_displacement(r, el.normal) * (-w);
      const double n1 = s / el.length, n0 = 1.0 - n1;
      out.block<3, 2>(0, 0) += n0 * d;
      out.block<3, 2>(0, 2) += n1 * d;
      out.block<3, 2>(0, 4) += n0 * sk;
      out.block<3, 2>(0, 6) += n1 * sk;
    });
    return out;
  }

  int target_at(int position) const { return targets_.order()[static_cast<std::size_t>(position)]; }
  int element_at(int position) const { return sources_.order()[static_cast<std::size_t>(position)]; }
  Eigen::VectorXd cluster_values(const ClusterTree::Cluster& c) const {
    Eigen::VectorXd y(kColumnsPerElement * c.size());
    for (int p = c.begin; p < c.end; ++p)
      y.segment<kColumnsPerElement>(kColumnsPerElement * (p - c.begin)) =
          values_.segment<kColumnsPerElement>(kColumnsPerElement * element_at(p));
    return y;
  }

  void add_near_block(const BlockPair& pair) {
    const auto& rows = targets_.clusters()[static_cast<std::size_t>(pair.row_cluster)];
    const auto& columns = sources_.clusters()[static_cast<std::size_t>(pair.column_cluster)];
    for (int t = rows.begin; t < rows.end; ++t)
      for (int p = columns.begin; p < columns.end; ++p) {
        const int e = element_at(p);
        stresses_.row(target_at(t)) +=
            (coefficients(target_at(t), e) * values_.segment<kColumnsPerElement>(kColumnsPerElement * e)).transpose();
      }
    ++near_blocks_;
  }

  // Whether a far block is interpolated: enough points to repay the p x p nodes, and a points' box small against
  // its distance to the elements (the interpolation's condition, stricter than the partition's min(diam)).
  bool interpolates(const BlockPair& pair) const {
    const BoundingBox& box = target_boxes_[static_cast<std::size_t>(pair.row_cluster)];
    return repays_interpolation(pair) &&
           box.diameter() <= options_.eta * box.distance(source_boxes_[static_cast<std::size_t>(pair.column_cluster)]);
  }

  // A far block whose points' box is too large to interpolate over but would repay it: its point cluster's
  // children are tried instead (each pair stays admissible: a child's box is inside the parent's).
  bool splits_for_interpolation(const BlockPair& pair) const {
    return !targets_.clusters()[static_cast<std::size_t>(pair.row_cluster)].leaf() && repays_interpolation(pair);
  }

  // Interpolation costs ~p^2 E coefficient evaluations for E elements, ACA ~20 (P + E) for P points (rank and
  // samples; see add_far_block): worth it, and worth splitting for, only where the points outnumber the nodes
  // and p^2 E < 20 P (many points per element: the indicator's cell centres, not a few points per node).
  bool repays_interpolation(const BlockPair& pair) const {
    const int points = targets_.clusters()[static_cast<std::size_t>(pair.row_cluster)].size();
    const int elements = sources_.clusters()[static_cast<std::size_t>(pair.column_cluster)].size();
    return points > interpolation_.nodes() && static_cast<double>(interpolation_.nodes()) * elements < 20.0 * points;
  }

  // The far field of an admissible pair: interpolated where it can be, else by point-cluster children, else by
  // ACA or the exact sum.
  void add_far_field(const BlockPair& pair) {
    if (options_.cancelled && options_.cancelled()) throw Cancelled();
    if (interpolates(pair)) {
      for (const BlockPair& part : interpolation_blocks(pair)) add_interpolated_block(part);
    } else if (splits_for_interpolation(pair)) {
      for (int child : targets_.clusters()[static_cast<std::size_t>(pair.row_cluster)].children)
        add_far_field({child, pair.column_cluster, true});
    } else if (!add_far_block(pair)) {
      add_near_block(pair);
    }
  }

  // An interpolated block with more elements than its points' box has nodes is split into the column cluster's
  // descendants of at most that many elements (so one pass over a part's elements per node stays cheap to poll).
  std::vector<BlockPair> interpolation_blocks(const BlockPair& pair) const {
    std::vector<BlockPair> parts;
    const std::function<void(int)> visit = [&](int c) {
      const auto& cluster = sources_.clusters()[static_cast<std::size_t>(c)];
      if (cluster.leaf() || cluster.size() <= interpolation_.nodes()) {
        parts.push_back({pair.row_cluster, c, true});
        return;
      }
      for (int child : cluster.children) visit(child);
    };
    visit(pair.column_cluster);
    return parts;
  }

  // The block's stresses at the Chebyshev nodes of the points' box, added to that box's node values.
  void add_interpolated_block(const BlockPair& pair) {
    const auto& columns = sources_.clusters()[static_cast<std::size_t>(pair.column_cluster)];
    auto [it, fresh] = node_stresses_.try_emplace(pair.row_cluster);
    const std::vector<Eigen::Vector2d> nodes =
        interpolation_.nodes_in(target_boxes_[static_cast<std::size_t>(pair.row_cluster)]);
    if (fresh) it->second = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(nodes.size()), 3);
    for (std::size_t k = 0; k < nodes.size(); ++k)
      for (int p = columns.begin; p < columns.end; ++p) {
        const int e = element_at(p);
        it->second.row(static_cast<Eigen::Index>(k)) +=
            (coefficients_at(nodes[k], e) * values_.segment<kColumnsPerElement>(kColumnsPerElement * e)).transpose();
      }
    ++interpolated_blocks_;
  }

  // Every interpolating box's polynomial at its points, top down: a box passes its polynomial on to the nodes
  // of each child box that holds more points than nodes (the child's box lies inside, so the polynomial is valid
  // there; std::map visits the children, which have larger indices, after their parent), and is evaluated at the
  // points of the other children (or of its own, for a leaf). So every point costs one evaluation.
  void apply_interpolation() {
    const auto at_points = [&](int cluster, int from, const Eigen::MatrixX3d& values) {
      const auto& rows = targets_.clusters()[static_cast<std::size_t>(cluster)];
      const BoundingBox& box = target_boxes_[static_cast<std::size_t>(from)];
      for (int t = rows.begin; t < rows.end; ++t)
        stresses_.row(target_at(t)) += interpolation_.at(box, values, points_[static_cast<std::size_t>(target_at(t))]);
    };
    for (auto it = node_stresses_.begin(); it != node_stresses_.end(); ++it) {
      if (options_.cancelled && options_.cancelled()) throw Cancelled();
      const auto& cluster = targets_.clusters()[static_cast<std::size_t>(it->first)];
      if (cluster.leaf()) {
        at_points(it->first, it->first, it->second);
        continue;
      }
      for (int child : cluster.children) {
        if (targets_.clusters()[static_cast<std::size_t>(child)].size() <= interpolation_.nodes()) {
          at_points(child, it->first, it->second);
          continue;
        }
        const std::vector<Eigen::Vector2d> nodes =
            interpolation_.nodes_in(target_boxes_[static_cast<std::size_t>(child)]);
        auto [child_it, fresh] = node_stresses_.try_emplace(child);
        if (fresh) child_it->second = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(nodes.size()), 3);
        for (std::size_t k = 0; k < nodes.size(); ++k)
          child_it->second.row(static_cast<Eigen::Index>(k)) +=
              interpolation_.at(target_boxes_[static_cast<std::size_t>(it->first)], it->second, nodes[k]);
      }
    }
  }

  // ACA of the block (3 rows per point); false if it is not worth it or does not compress (then it is summed
  // exactly). ACA costs about (rank + samples) x (points + elements) coefficient evaluations (~20 x, rows and
  // columns cached per point and per element), the exact sum points x elements: options.break_even.
  bool add_far_block(const BlockPair& pair) {
    const auto& rows = targets_.clusters()[static_cast<std::size_t>(pair.row_cluster)];
    const auto& columns = sources_.clusters()[static_cast<std::size_t>(pair.column_cluster)];
    if (static_cast<double>(rows.size()) * columns.size() <= options_.break_even * (rows.size() + columns.size()))
      return false;
    const int m = 3 * rows.size(), n = kColumnsPerElement * columns.size();
    const int max_rank = std::min(m, n) / 2;
    // The 3 x 8 coefficients of a point with every element of the block (a row strip), and of an element with
    // every point (a column strip), computed once when first asked for.
    std::vector<Eigen::MatrixXd> row_strips(static_cast<std::size_t>(rows.size()));
    std::vector<Eigen::MatrixXd> column_strips(static_cast<std::size_t>(columns.size()));
    LowRank block = adaptive_cross_approximation(
        m, n,
        [&](int i, Eigen::Ref<Eigen::VectorXd> out) {
          Eigen::MatrixXd& strip = row_strips[static_cast<std::size_t>(i / 3)];
          if (strip.size() == 0) {
            strip.resize(3, n);
            for (int p = columns.begin; p < columns.end; ++p)
              strip.middleCols<kColumnsPerElement>(kColumnsPerElement * (p - columns.begin)) =
                  coefficients(target_at(rows.begin + i / 3), element_at(p));
          }
          out = strip.row(i % 3).transpose();
        },
        [&](int j, Eigen::Ref<Eigen::VectorXd> out) {
          Eigen::MatrixXd& strip = column_strips[static_cast<std::size_t>(j / kColumnsPerElement)];
          if (strip.size() == 0) {
            strip.resize(m, kColumnsPerElement);
            const int e = element_at(columns.begin + j / kColumnsPerElement);
            for (int t = 0; t < rows.size(); ++t)
              strip.middleRows<3>(3 * t) = coefficients(target_at(rows.begin + t), e);
          }
          out = strip.col(j % kColumnsPerElement);
        },
        options_.tolerance, max_rank);
    if (block.rank() >= max_rank) return false;
    const Eigen::VectorXd product = block.U * (block.V.transpose() * cluster_values(columns));
    for (int t = 0; t < rows.size(); ++t)
      stresses_.row(target_at(rows.begin + t)) += product.segment<3>(3 * t).transpose();
    ++far_blocks_;
    rank_sum_ += block.rank();
    largest_rank_ = std::max(largest_rank_, block.rank());
    return true;
  }

  BoundaryGeometry geometry_;
  const std::vector<Eigen::Vector2d>& points_;
  const HierarchicalOptions& options_;
  KelvinSolution kelvin_;
  double traction_scale_;
  ClusterTree sources_, targets_;
  std::vector<BoundingBox> source_boxes_, target_boxes_;
  ChebyshevGrid interpolation_;
  std::map<int, Eigen::MatrixX3d> node_stresses_;  // per interpolating target cluster: stresses at its nodes
  Eigen::VectorXd values_;
  Eigen::MatrixX3d stresses_;
  int near_blocks_ = 0, far_blocks_ = 0, interpolated_blocks_ = 0, largest_rank_ = 0;
  long rank_sum_ = 0;
};

}  // namespace

Eigen::MatrixX3d interior_stresses_hierarchical(const BoundaryProblem& problem, const BoundarySolution& solution,
                                                const std::vector<Eigen::Vector2d>& points,
                                                const HierarchicalOptions& options, HierarchicalStats* stats) {
  if (points.empty()) return Eigen::MatrixX3d(0, 3);
  return HierarchicalSomigliana(problem, solution, points, options).run(stats);
}

Eigen::MatrixX3d interior_stresses_auto(const BoundaryProblem& problem, const BoundarySolution& solution,
                                        const std::vector<Eigen::Vector2d>& points,
                                        const HierarchicalOptions& options) {
  const double pairs = static_cast<double>(problem.nodes.size()) * static_cast<double>(points.size());
  return problem.nodes.size() >= kHierarchicalFromNodes || pairs > kDenseInteriorPairs
             ? interior_stresses_hierarchical(problem, solution, points, options)
             : interior_stresses(problem, solution, points);
}

}  // namespace contact::bem

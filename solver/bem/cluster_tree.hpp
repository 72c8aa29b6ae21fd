// Cluster trees and block partitions for the hierarchical BEM (docs/bem.md, "Hierarchical BEM").
//
// A cluster tree orders a set of points (boundary nodes, or interior targets) so that every cluster is a
// contiguous range of the order; it is built by geometric bisection: the tight bounding box of a cluster's points
// is halved across its longest side until a cluster holds at most `leaf_size` points. The block partition of
// two trees pairs their clusters recursively: a pair is admissible (its interaction is smooth, so low-rank) when
//     min(diam(row box), diam(column box)) <= eta * dist(row box, column box),   dist > 0,
// and the boxes are those of what the clusters stand for (collocation points; elements), not of the tree's points.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <vector>

namespace contact::bem {

struct BoundingBox {
  Eigen::Vector2d lo{HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL};

  void extend(const Eigen::Vector2d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const BoundingBox& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool empty() const { return lo.x() > hi.x(); }
  double diameter() const { return empty() ? 0.0 : (hi - lo).norm(); }
  // Euclidean distance between the two boxes (0 if they overlap).
  double distance(const BoundingBox& b) const {
    const Eigen::Vector2d gap = (b.lo - hi).cwiseMax(lo - b.hi).cwiseMax(0.0);
    return gap.norm();
  }
  double distance(const Eigen::Vector2d& p) const { return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm(); }
};

class ClusterTree {
 public:
  struct Cluster {
    int begin = 0, end = 0;               // positions in order()
    std::array<int, 2> children{-1, -1};  // cluster indices; -1 for a leaf
    bool leaf() const { return children[0] < 0; }
    int size() const { return end - begin; }
  };

  // The tree of `points`; leaf_size >= 1. Cluster 0 is the root.
  ClusterTree(const std::vector<Eigen::Vector2d>& points, int leaf_size);

  const std::vector<Cluster>& clusters() const { return clusters_; }
  // order()[position] = the index of the point at that position; position()[point] the inverse.
  const std::vector<int>& order() const { return order_; }
  const std::vector<int>& position() const { return position_; }
  // Per cluster, the union of the boxes of its items (item_boxes indexed by point index).
  std::vector<BoundingBox> cluster_boxes(const std::vector<BoundingBox>& item_boxes) const;

 private:
  int build(const std::vector<Eigen::Vector2d>& points, int begin, int end, int leaf_size);

  std::vector<Cluster> clusters_;
  std::vector<int> order_, position_;
};

// A leaf of the block partition: the clusters (indices into their trees) and whether the pair is admissible
// (far field, compressed) or not (near field: both clusters are leaves, evaluated exactly).
struct BlockPair {
  int row_cluster = 0, column_cluster = 0;
  bool admissible = false;
};

std::vector<BlockPair> block_partition(const ClusterTree& rows, const std::vector<BoundingBox>& row_boxes,
                                       const ClusterTree& columns, const std::vector<BoundingBox>& column_boxes,
                                       double eta);

}  // namespace contact::bem

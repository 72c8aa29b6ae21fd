#include "cluster_tree.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <stdexcept>

namespace contact::bem {

ClusterTree::ClusterTree(const std::vector<Eigen::Vector2d>& points, int leaf_size) {
  if (leaf_size < 1) throw std::invalid_argument("cluster tree: the leaf size must be at least 1");
  if (points.empty()) throw std::invalid_argument("cluster tree: no points");
  order_.resize(points.size());
  std::iota(order_.begin(), order_.end(), 0);
  clusters_.reserve(4 * points.size() / static_cast<std::size_t>(leaf_size) + 2);
  build(points, 0, static_cast<int>(points.size()), leaf_size);
  position_.resize(points.size());
  for (std::size_t k = 0; k < order_.size(); ++k) position_[static_cast<std::size_t>(order_[k])] = static_cast<int>(k);
}

int ClusterTree::build(const std::vector<Eigen::Vector2d>& points, int begin, int end, int leaf_size) {
  const int index = static_cast<int>(clusters_.size());
  clusters_.push_back(Cluster{begin, end, {-1, -1}});
  if (end - begin <= leaf_size) return index;
  BoundingBox box;
  for (int k = begin; k < end; ++k) box.extend(points[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])]);
  const Eigen::Vector2d extent = box.hi - box.lo;
  const int axis = extent.x() >= extent.y() ? 0 : 1;
  if (!(extent(axis) > 0.0)) return index;  // coincident points: cannot be split, stays a (large) leaf
  const double middle = 0.5 * (box.lo(axis) + box.hi(axis));
  // Both halves are non-empty: the box is tight, so its two extreme points lie on either side of the middle.
  const auto split = std::partition(order_.begin() + begin, order_.begin() + end,
                                    [&](int p) { return points[static_cast<std::size_t>(p)](axis) < middle; });
  const int mid = static_cast<int>(split - order_.begin());
  const int left = build(points, begin, mid, leaf_size);
  const int right = build(points, mid, end, leaf_size);
  clusters_[static_cast<std::size_t>(index)].children = {left, right};
  return index;
}

std::vector<BoundingBox> ClusterTree::cluster_boxes(const std::vector<BoundingBox>& item_boxes) const {
  std::vector<BoundingBox> boxes(clusters_.size());
  // Children have larger indices than their parent (depth-first build): fill from the back.
  for (std::size_t c = clusters_.size(); c-- > 0;) {
    const Cluster& cluster = clusters_[c];
    if (cluster.leaf()) {
      for (int k = cluster.begin; k < cluster.end; ++k)
        boxes[c].extend(item_boxes[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])]);
    } else {
      for (int child : cluster.children) boxes[c].extend(boxes[static_cast<std::size_t>(child)]);
    }
  }
  return boxes;
}

std::vector<BlockPair> block_partition(const ClusterTree& rows, const std::vector<BoundingBox>& row_boxes,
                                       const ClusterTree& columns, const std::vector<BoundingBox>& column_boxes,
                                       double eta) {
  std::vector<BlockPair> blocks;
  const std::function<void(int, int)> visit = [&](int r, int c) {
    const BoundingBox& rb = row_boxes[static_cast<std::size_t>(r)];
    const BoundingBox& cb = column_boxes[static_cast<std::size_t>(c)];
    const double distance = rb.distance(cb);
    if (distance > 0.0 && std::min(rb.diameter(), cb.diameter()) <= eta * distance) {
      blocks.push_back({r, c, true});
      return;
    }
    const auto& rc = rows.clusters()[static_cast<std::size_t>(r)];
    const auto& cc = columns.clusters()[static_cast<std::size_t>(c)];
    if (rc.leaf() && cc.leaf()) {
      blocks.push_back({r, c, false});
    } else if (rc.leaf()) {
      for (int child : cc.children) visit(r, child);
    } else if (cc.leaf()) {
      for (int child : rc.children) visit(child, c);
    } else {
      for (int row_child : rc.children)
        for (int column_child : cc.children) visit(row_child, column_child);
    }
  };
  visit(0, 0);
  return blocks;
}

}  // namespace contact::bem

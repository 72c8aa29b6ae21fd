#include "hmatrix.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace contact::bem {

void HierarchicalMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y = Eigen::VectorXd::Zero(size_);
  Eigen::VectorXd local;
  for (const MatrixBlock& block : blocks_) {
    local.resize(static_cast<Eigen::Index>(block.columns.size()));
    for (std::size_t k = 0; k < block.columns.size(); ++k) local(static_cast<Eigen::Index>(k)) = x(block.columns[k]);
    if (block.low_rank())
      y.segment(block.row_begin, block.U.rows()).noalias() += block.U * (block.W * local);
    else
      y.segment(block.row_begin, block.dense.rows()).noalias() += block.dense * local;
  }
  for (const MatrixEntry& e : entries_) y(e.row) += e.value * x(e.column);
}

std::size_t HierarchicalMatrix::bytes() const {
  std::size_t total = entries_.size() * sizeof(MatrixEntry);
  for (const MatrixBlock& block : blocks_)
    total += sizeof(double) * static_cast<std::size_t>(block.dense.size() + block.U.size() + block.W.size()) +
             sizeof(int) * block.columns.size() + sizeof(MatrixBlock);
  return total;
}

void HierarchicalMatrix::factorize_diagonal(const std::vector<std::pair<int, int>>& ranges) {
  ranges_ = ranges;
  // Which range each row belongs to.
  std::vector<int> range_of(static_cast<std::size_t>(size_), -1);
  for (std::size_t r = 0; r < ranges.size(); ++r)
    for (int i = ranges[r].first; i < ranges[r].second; ++i)
      range_of[static_cast<std::size_t>(i)] = static_cast<int>(r);
  std::vector<Eigen::MatrixXd> diagonal(ranges.size());
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    const int n = ranges[r].second - ranges[r].first;
    diagonal[r] = Eigen::MatrixXd::Zero(n, n);
  }
  // Phase 1: gather the diagonal blocks from the dense blocks and the entries.
  for (const MatrixBlock& block : blocks_) {
    if (block.low_rank() || block.dense.rows() == 0) continue;
    const int r = range_of[static_cast<std::size_t>(block.row_begin)];
    if (r < 0) continue;
    const auto [begin, end] = ranges[static_cast<std::size_t>(r)];
    for (std::size_t k = 0; k < block.columns.size(); ++k) {
      const int column = block.columns[k];
      if (column < begin || column >= end) continue;
      diagonal[static_cast<std::size_t>(r)].block(block.row_begin - begin, column - begin, block.dense.rows(), 1) +=
          block.dense.col(static_cast<Eigen::Index>(k));
    }
  }
  for (const MatrixEntry& e : entries_) {
    const int r = range_of[static_cast<std::size_t>(e.row)];
    if (r < 0) continue;
    const int begin = ranges[static_cast<std::size_t>(r)].first;
    if (e.column >= begin && e.column < ranges[static_cast<std::size_t>(r)].second)
      diagonal[static_cast<std::size_t>(r)](e.row - begin, e.column - begin) += e.value;
  }
  // Phase 2: factorise.
  diagonal_.clear();
  diagonal_.reserve(ranges.size());
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    diagonal_.emplace_back(diagonal[r]);
    if (!(diagonal_.back().rcond() > 1e-14))
      throw std::runtime_error("bem: the near-field preconditioner block of unknowns " +
                               std::to_string(ranges[r].first) + ".." + std::to_string(ranges[r].second - 1) +
                               " is singular");
  }
}

void HierarchicalMatrix::precondition(const Eigen::VectorXd& y, Eigen::VectorXd& x) const {
  x = y;
  for (std::size_t r = 0; r < ranges_.size(); ++r) {
    const auto [begin, end] = ranges_[r];
    x.segment(begin, end - begin) = diagonal_[r].solve(y.segment(begin, end - begin));
  }
}

std::size_t HierarchicalMatrix::preconditioner_bytes() const {
  std::size_t total = 0;
  for (const auto& lu : diagonal_)
    total += sizeof(double) * static_cast<std::size_t>(lu.matrixLU().size()) + sizeof(int) * lu.permutationP().size();
  return total;
}

}  // namespace contact::bem

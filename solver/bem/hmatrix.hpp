// The hierarchically compressed collocation matrix of hierarchical_solve.cpp (docs/bem.md, "Hierarchical BEM"):
// a list of blocks, each on a contiguous range of rows (the equations of one row cluster, in the tree's order) and
// a list of columns (the unknowns its elements touch, also in the tree's order). Near-field blocks are dense,
// far-field blocks U W with U: rows x k, W: k x columns. Plus a sparse diagonal part (the rigid-body coefficients
// of the collocation nodes), and the block-diagonal preconditioner built from the near field.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cstddef>
#include <vector>

namespace contact::bem {

struct MatrixBlock {
  int row_begin = 0;
  std::vector<int> columns;
  Eigen::MatrixXd dense;  // near field: rows x columns
  Eigen::MatrixXd U, W;   // far field: rows x k, k x columns
  bool low_rank() const { return dense.size() == 0; }
  Eigen::Index rows() const { return low_rank() ? U.rows() : dense.rows(); }
};

struct MatrixEntry {
  int row, column;
  double value;
};

class HierarchicalMatrix {
 public:
  explicit HierarchicalMatrix(int size) : size_(size) {}

  void add(MatrixBlock block) { blocks_.push_back(std::move(block)); }
  void add(const MatrixEntry& entry) { entries_.push_back(entry); }
  int size() const { return size_; }
  const std::vector<MatrixBlock>& blocks() const { return blocks_; }

  // y = A x.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // Storage of the blocks and entries, in bytes.
  std::size_t bytes() const;

  // The preconditioner: the square diagonal blocks A[r, r] on the given ranges (the leaf clusters' equations and
  // unknowns: equal counts), taken from the dense blocks and the entries, factorised by partial-pivot LU.
  // Throws std::runtime_error naming the range if one is singular.
  void factorize_diagonal(const std::vector<std::pair<int, int>>& ranges);
  // x = (block-diagonal of A)^-1 y.
  void precondition(const Eigen::VectorXd& y, Eigen::VectorXd& x) const;
  std::size_t preconditioner_bytes() const;

 private:
  int size_;
  std::vector<MatrixBlock> blocks_;
  std::vector<MatrixEntry> entries_;
  std::vector<std::pair<int, int>> ranges_;
  std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> diagonal_;
};

}  // namespace contact::bem

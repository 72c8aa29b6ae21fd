// A sparse Cholesky factorisation A = P^T L L^T P of one body's reduced stiffness (CHOLMOD, supernodal), with
// an optional set of unknowns ordered after all others.
//
// Why the ordering matters: with the contact-interface unknowns Z last, the trailing block L_ZZ of the factor is
// the Cholesky factor of the Schur complement S = A_ZZ - A_ZI A_II^-1 A_IZ (S = L_ZZ L_ZZ^T). The interface
// compliance B A^-1 B^T of loads B^T that act on Z only is then (L_ZZ^-1 B_Z^T)^T (L_ZZ^-1 B_Z^T): a dense
// problem of the size of the interface, read off the factorisation that the body needs anyway, instead of one
// full back-substitution per interface unknown. The ordering is CHOLMOD's nested dissection with Z moved last;
// the dense trailing block costs |Z|^3 / 3 flops and |Z|^2 / 2 numbers, small next to the factorisation while
// |Z| is a few thousand.
//
// Each object owns its CHOLMOD workspace, so different objects may be used from different threads at once.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

struct cholmod_sparse_struct;
using cholmod_sparse = cholmod_sparse_struct;

namespace contact::fem {

class Cholesky {
 public:
  // Analyses and factorises A (symmetric positive definite; both triangles stored, the lower one is used).
  // `last` lists unknowns (indices into A, any order, no repeats) to be ordered after all others; empty = the
  // default fill-reducing ordering. Never throws for a matrix that is not positive definite: check ok().
  explicit Cholesky(const Eigen::SparseMatrix<double>& A, const std::vector<int>& last = {});
  ~Cholesky();
  Cholesky(const Cholesky&) = delete;
  Cholesky& operator=(const Cholesky&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  int size() const { return n_; }

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

  // The lower-triangular factor of the Schur complement on `last` (|last| x |last|); row and column i belong to
  // unknown trailing_order()[i]. Empty when no unknowns were ordered last.
  const Eigen::MatrixXd& trailing_factor() const { return trailing_; }
  const std::vector<int>& trailing_order() const { return trailing_order_; }

  // Numbers stored in L (supernodal storage, including the dense trailing block): the memory of the factor.
  double factor_entries() const { return factor_entries_; }

 private:
  // The constructor's phases: the ordering and symbolic analysis (with `last` behind everything else), the
  // numerical factorisation, the trailing block of the factor. The first two return false with error_ set.
  bool analyse(cholmod_sparse* a, const std::vector<int>& last);
  bool factorize_numerically(cholmod_sparse* a);
  void read_trailing_block(const std::vector<int>& last);

  struct Impl;
  std::unique_ptr<Impl> impl_;
  int n_ = 0;
  std::string error_;
  Eigen::MatrixXd trailing_;
  std::vector<int> trailing_order_;
  double factor_entries_ = 0.0;
};

}  // namespace contact::fem

#include "coarse_space.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>

namespace contact::ddm {

namespace {

// A factor of G G^T (or a face's G_F G_F^T), solved with once or twice per MPRGP iteration. CHOLMOD's supernodal
// solve calls BLAS once per supernode, and a wall's coarse matrix (three rows per brick, coupled to its few
// neighbours) has small supernodes: its simplicial solve is faster up to a few thousand rows (measured, coarse
// projections per run: 22 x 22 wall 0.139 -> 0.093 s, 32 x 32 0.357 -> 0.246 s; 64 x 64, 12,387 rows: 3.22 ->
// 3.43 s, supernodal still ahead), so the mode follows the size.
constexpr Eigen::Index kSimplicialUpTo = 6000;

void choose_mode(Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower>& llt, Eigen::Index rows) {
  llt.setMode(rows <= kSimplicialUpTo ? Eigen::CholmodSimplicialLLt : Eigen::CholmodSupernodalLLt);
  llt.cholmod().print = 0;  // reported by info(), not by CHOLMOD's text on stdout
}

// The floating bodies' rows whose block of G G^T is rank-deficient: no pressures on its contact nodes can balance
// every rigid motion of that body (a body with no contact, or contact at one point against a spin).
std::vector<Eigen::Index> dependent_rows(const InterfaceProblem& problem, const SparseMatrix& GGt) {
  std::vector<Eigen::Index> out;
  for (const auto& f : problem.floating()) {
    Eigen::MatrixXd block(f.count, f.count);
    for (Eigen::Index i = 0; i < f.count; ++i)
      for (Eigen::Index j = 0; j < f.count; ++j) block(i, j) = GGt.coeff(f.offset + i, f.offset + j);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(block);
    const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
    if (!(eig.eigenvalues().minCoeff() > 1e-12 * largest) || !(largest > 0))
      for (Eigen::Index i = 0; i < f.count; ++i) out.push_back(f.offset + i);
  }
  return out;
}

}  // namespace

struct CoarseSpace::Factor {
  Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower> llt;
};

CoarseSpace::CoarseSpace(const InterfaceProblem& problem, const Equalities& equilibrium)
    : problem_(problem),
      G_(equilibrium.G),
      Gt_(equilibrium.G.transpose()),
      e_(equilibrium.e),
      factor_(std::make_unique<Factor>()) {
  if (empty()) return;
  const SparseMatrix GGt = G_ * Gt_;
  unheld_ = dependent_rows(problem, GGt);
  if (!unheld_.empty()) return;
  choose_mode(factor_->llt, GGt.rows());
  factor_->llt.compute(GGt);
  if (factor_->llt.info() != Eigen::Success)  // dependent across bodies: name every floating body's rows
    for (Eigen::Index i = 0; i < G_.rows(); ++i) unheld_.push_back(i);
}

CoarseSpace::~CoarseSpace() = default;

Eigen::VectorXd CoarseSpace::range_part(const Eigen::VectorXd& x) const {
  if (empty()) return Eigen::VectorXd::Zero(x.size());
  // (both products as gathers, each entry of the result one sparse dot product: faster than scattering)
  const Eigen::VectorXd Gx = Gt_.transpose() * x;
  const Eigen::VectorXd y = factor_->llt.solve(Gx);
  return G_.transpose() * y;
}

Eigen::VectorXd CoarseSpace::project(const Eigen::VectorXd& x) const {
  if (empty()) return x;
  return x - range_part(x);
}

Eigen::VectorXd CoarseSpace::particular() const {
  if (empty()) return Eigen::VectorXd::Zero(G_.cols());
  return Gt_ * factor_->llt.solve(e_);
}

SparseMatrix CoarseSpace::columns_of(const std::vector<char>& columns) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j = 0; j < G_.outerSize(); ++j) {
    if (!columns[static_cast<size_t>(j)]) continue;
    for (SparseMatrix::InnerIterator it(G_, j); it; ++it) entries.emplace_back(it.row(), it.col(), it.value());
  }
  SparseMatrix GA(G_.rows(), G_.cols());
  GA.setFromTriplets(entries.begin(), entries.end());
  return GA;
}

std::vector<Eigen::Index> CoarseSpace::unheld_by(const std::vector<char>& columns) const {
  if (empty()) return {};
  const SparseMatrix GA = columns_of(columns);
  const SparseMatrix GAt = GA.transpose();
  return dependent_rows(problem_, GA * GAt);
}

Eigen::VectorXd CoarseSpace::solve_GGt(const Eigen::VectorXd& v) const {
  if (empty()) return Eigen::VectorXd();
  return factor_->llt.solve(v);
}

Eigen::VectorXd CoarseSpace::multipliers(const Eigen::VectorXd& r, const std::vector<char>& columns, bool indeterminate,
                                         const Eigen::VectorXd* prior) const {
  if (empty()) return Eigen::VectorXd();
  const SparseMatrix GA = columns_of(columns);
  const SparseMatrix GAt = GA.transpose();
  const SparseMatrix GAGAt = GA * GAt;
  const Eigen::VectorXd rhs = -(GA * r);
  // Singular with each body's block regular: a group of bodies held by nothing as a whole (two bricks joined by a
  // head joint on a slipping course); CHOLMOD says so by failing, quietly.
  const auto solve = [&](const SparseMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& alpha) {
    Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;
    llt.cholmod().print = 0;
    llt.compute(A);
    if (llt.info() != Eigen::Success) return false;
    alpha = llt.solve(b);
    return alpha.allFinite();
  };
  Eigen::VectorXd alpha;
  const bool dependent = !dependent_rows(problem_, GAGAt).empty();
  if (!dependent && solve(GAGAt, rhs, alpha)) return alpha;
  if (!indeterminate) return Eigen::VectorXd();
  const double eps = 1e-10 * std::max(GAGAt.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  SparseMatrix shift(GAGAt.rows(), GAGAt.cols());
  shift.setIdentity();
  const SparseMatrix regularised = GAGAt + eps * shift;
  // With a prior the unknown is the correction to it: the least one along the motions no column holds.
  if (prior && prior->size() == G_.rows()) {
    if (solve(regularised, Eigen::VectorXd(-(GA * (r + Gt_ * *prior))), alpha)) return *prior + alpha;
  } else if (solve(regularised, rhs, alpha)) {
    return alpha;
  }
  return Eigen::VectorXd();
}

struct CoarseSpace::Face::Factor {
  Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower> llt;
};

CoarseSpace::Face::~Face() = default;

std::unique_ptr<CoarseSpace::Face> CoarseSpace::face(const std::vector<char>& columns) const {
  std::unique_ptr<Face> f(new Face());
  f->factor_ = std::make_unique<Face::Factor>();
  if (empty()) return f;
  f->GF_ = columns_of(columns);
  f->GFt_ = f->GF_.transpose();
  const SparseMatrix GFGFt = f->GF_ * f->GFt_;
  if (!dependent_rows(problem_, GFGFt).empty()) return f;
  choose_mode(f->factor_->llt, GFGFt.rows());
  f->factor_->llt.compute(GFGFt);
  f->ok_ = f->factor_->llt.info() == Eigen::Success;
  return f;
}

Eigen::VectorXd CoarseSpace::Face::correction(const Eigen::VectorXd& r) const {
  if (GF_.rows() == 0) return Eigen::VectorXd::Zero(GF_.cols());
  const Eigen::VectorXd y = factor_->llt.solve(r);
  return GF_.transpose() * y;  // (as a gather: range_part)
}

Eigen::VectorXd CoarseSpace::Face::project(const Eigen::VectorXd& v) const {
  if (GF_.rows() == 0) return v;
  return v - correction(GFt_.transpose() * v);
}

Eigen::VectorXd CoarseSpace::Face::multipliers(const Eigen::VectorXd& h) const {
  if (GF_.rows() == 0) return Eigen::VectorXd();
  return -factor_->llt.solve(GFt_.transpose() * h);
}

}  // namespace contact::ddm

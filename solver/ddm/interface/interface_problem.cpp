#include "interface_problem.hpp"
#include "../../common/assert.hpp"

#include <numeric>
#include <stdexcept>

namespace contact::ddm {

namespace {

// One body's rows of B (sign +1: master, -1: slave), each a list of (full dof, value).
struct BodyRows {
  std::vector<Eigen::Index> rows;  // global row numbers
  std::vector<std::vector<std::pair<int, double>>> entries;
};

// Body a's rows of G and T over its own pairs (ContactSystem::pairs_of: a wall of 4,129 bricks asked every one of
// its 12,192 pairs for each body).
BodyRows body_rows(const ContactSystem& system, size_t a, const std::vector<Eigen::Index>& offset,
                   const std::vector<Eigen::Index>& tangential_offset) {
  BodyRows out;
  const auto& pairs = system.pairs();
  for (const size_t k : system.pairs_of(a)) {
    const auto& pair = pairs[k];
    auto add = [&](const mortar::SparseRows& G, double sign, Eigen::Index first) {
      for (int r = 0; r < G.outerSize(); ++r) {
        std::vector<std::pair<int, double>> e;
        for (mortar::SparseRows::InnerIterator it(G, r); it; ++it)
          e.emplace_back(static_cast<int>(it.col()), sign * it.value());
        out.rows.push_back(first + r);
        out.entries.push_back(std::move(e));
      }
    };
    const bool slave = static_cast<size_t>(pair.slave_body) == a, master = static_cast<size_t>(pair.master_body) == a;
    if (slave) add(pair.Gs, -1.0, offset[k]);
    if (master) add(pair.Gm, 1.0, offset[k]);
    if (tangential_offset[k] < 0) continue;
    if (slave) add(pair.Ts, -1.0, tangential_offset[k]);
    if (master) add(pair.Tm, 1.0, tangential_offset[k]);
  }
  return out;
}

}  // namespace

struct InterfaceProblem::BodyParts {
  BodyRows rows;
  Eigen::MatrixXd F, preconditioner, G;  // G: rigid modes x rows (floating bodies)
  Eigen::VectorXd g, e, diagonal;
};

// One body's share: its free response's gaps, its rigid modes' equilibrium rows, and its compliance (and
// preconditioner) block on its rows.
void InterfaceProblem::compute_body(size_t a, const fem::LoadPoint& at, BodyParts& out) const {
  const BodyRows& R = out.rows;
  const auto& body = system_.body(a);
  const Eigen::Index k = static_cast<Eigen::Index>(R.rows.size());
  if (body.floating()) {
    // G_a = (B_a R_a)^T over this body's rows, e_a = -R_a^T f_a.
    const Eigen::MatrixXd& modes = body.rigid_modes();
    out.G = Eigen::MatrixXd::Zero(modes.cols(), k);
    for (size_t i = 0; i < R.rows.size(); ++i)
      for (const auto& [dof, value] : R.entries[i])
        out.G.col(static_cast<Eigen::Index>(i)) += value * modes.row(dof).transpose();
    out.e = -modes.transpose() * body.external_load(at);
  }
  // Free response: the body under its own loads only.
  const Eigen::VectorXd u_free = body.solve(Eigen::VectorXd(), at);
  out.g = Eigen::VectorXd::Zero(k);
  for (size_t i = 0; i < R.rows.size(); ++i)
    for (const auto& [dof, value] : R.entries[i]) out.g[static_cast<Eigen::Index>(i)] += value * u_free[dof];
  if (R.rows.empty()) return;
  // B_Z^T in the trailing order of the factor: reduced rows (B T) restricted to Z.
  const auto& Z = body.interface_unknowns();
  const Eigen::MatrixXd& L = body.interface_factor();
  std::vector<Eigen::Index> position(static_cast<size_t>(body.n_free()), -1);
  for (size_t i = 0; i < Z.size(); ++i) position[static_cast<size_t>(Z[i])] = static_cast<Eigen::Index>(i);
  const Eigen::SparseMatrix<double, Eigen::RowMajor> T = body.constraints().T();
  Eigen::MatrixXd BzT = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(Z.size()), k);
  for (size_t i = 0; i < R.rows.size(); ++i)
    for (const auto& [dof, value] : R.entries[i])
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(T, dof); it; ++it) {
        const Eigen::Index p = position[static_cast<size_t>(it.col())];
        if (p < 0)
          throw std::logic_error("interface problem: a contact dof depends on an unknown outside the interface");
        BzT(p, static_cast<Eigen::Index>(i)) += value * it.value();
      }
  if (Z.empty()) {  // every contact dof of this body is prescribed: it adds no compliance
    out.F = Eigen::MatrixXd::Zero(k, k);
    out.diagonal = Eigen::VectorXd::Zero(k);
    if (options_.preconditioner != InterfacePreconditioner::none) out.preconditioner = Eigen::MatrixXd::Zero(k, k);
    return;
  }
  const Eigen::MatrixXd W = L.triangularView<Eigen::Lower>().solve(BzT);
  out.F = W.transpose() * W;
  out.diagonal = out.F.diagonal();
  if (options_.preconditioner == InterfacePreconditioner::dirichlet) {
    // S = L_ZZ L_ZZ^T (the Schur complement on Z): B S B^T = (L^T B_Z^T)^T (L^T B_Z^T).
    const Eigen::MatrixXd V = L.transpose().triangularView<Eigen::Upper>() * BzT;
    out.preconditioner = V.transpose() * V;
  } else if (options_.preconditioner == InterfacePreconditioner::lumped) {
    // K_ZZ: the reduced stiffness on Z alone (no interior elimination).
    const auto& K = body.reduced_stiffness();
    Eigen::MatrixXd Kzz =
        Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(Z.size()), static_cast<Eigen::Index>(Z.size()));
    for (size_t j = 0; j < Z.size(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, Z[j]); it; ++it) {
        const Eigen::Index p = position[static_cast<size_t>(it.row())];
        if (p >= 0) Kzz(p, static_cast<Eigen::Index>(j)) = it.value();
      }
    out.preconditioner = BzT.transpose() * Kzz * BzT;
  }
}

InterfaceProblem::InterfaceProblem(const ContactSystem& system, parallel::TaskRunner& runner, const Options& options,
                                   const fem::LoadPoint& at)
    : system_(system), options_(options) {
  const auto& pairs = system.pairs();
  offset_.assign(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) offset_[k + 1] = offset_[k] + pairs[k].n_rows();
  size_ = offset_.back();
  tangential_offset_.assign(pairs.size(), -1);
  for (size_t k = 0; k < pairs.size(); ++k)
    if (options.friction && pairs[k].has_friction()) {
      tangential_offset_[k] = size_;
      size_ += pairs[k].n_rows();
    }
  const Eigen::Index m = size_;
  D_.resize(m);
  gap0_ = Eigen::VectorXd::Zero(m);  // tangential rows: the slip origin is subtracted in free_gap()
  factor_ = at.value();
  for (size_t k = 0; k < pairs.size(); ++k) {
    D_.segment(offset_[k], pairs[k].n_rows()) = pairs[k].area;
    gap0_.segment(offset_[k], pairs[k].n_rows()) = pairs[k].gap0;
    if (tangential_offset_[k] >= 0) D_.segment(tangential_offset_[k], pairs[k].n_rows()) = pairs[k].area;
  }
  // The preconditioner's scaling (feti.hpp): with B_a ~ D on both sides of a contact node, F ~ D (S_s^-1 +
  // S_m^-1) D, whose inverse for S_s ~ S_m is (D^-2 / 2) (B_s S_s B_s^T + B_m S_m B_m^T) (D^-2 / 2).
  inverse_weight_ = (2.0 * D_.cwiseAbs2()).cwiseInverse();
  const size_t n_bodies = system.n_bodies();
  std::vector<BodyParts> parts(n_bodies);
  for (size_t a = 0; a < n_bodies; ++a) parts[a].rows = body_rows(system, a, offset_, tangential_offset_);
  // Each body's part on its owner; the blocks move to every process only when they are replicated.
  const bool replicate = options_.replicate_blocks;
  const parallel::BodyShare share{[&](size_t a, parallel::Packer& out) {
                                    out.put(replicate ? parts[a].F : Eigen::MatrixXd());
                                    out.put(replicate ? parts[a].preconditioner : Eigen::MatrixXd());
                                    out.put(parts[a].G);
                                    out.put(parts[a].g);
                                    out.put(parts[a].e);
                                    out.put(parts[a].diagonal);
                                  },
                                  [&](size_t a, parallel::Unpacker& in) {
                                    parts[a].F = in.get_matrix();
                                    parts[a].preconditioner = in.get_matrix();
                                    parts[a].G = in.get_matrix();
                                    parts[a].g = in.get_vector();
                                    parts[a].e = in.get_vector();
                                    parts[a].diagonal = in.get_vector();
                                  }};
  runner.run_bodies(
      n_bodies, [&](size_t a) { compute_body(a, at, parts[a]); }, share);
  g_loads_ = Eigen::VectorXd::Zero(m);
  diagonal_ = Eigen::VectorXd::Zero(m);
  blocks_.resize(n_bodies);
  for (size_t a = 0; a < n_bodies; ++a) {
    const BodyRows& R = parts[a].rows;
    for (size_t i = 0; i < R.rows.size(); ++i) {
      g_loads_[R.rows[i]] += parts[a].g[static_cast<Eigen::Index>(i)];
      if (parts[a].diagonal.size()) diagonal_[R.rows[i]] += parts[a].diagonal[static_cast<Eigen::Index>(i)];
    }
    blocks_[a].rows = R.rows;
    blocks_[a].F = std::move(parts[a].F);
    blocks_[a].preconditioner = std::move(parts[a].preconditioner);
  }
  assemble_equilibrium(parts);
}

void InterfaceProblem::assemble_equilibrium(const std::vector<BodyParts>& parts) {
  Eigen::Index r = 0;
  for (size_t a = 0; a < parts.size(); ++a)
    if (parts[a].G.rows() > 0) {
      floating_.push_back({a, r, parts[a].G.rows()});
      r += parts[a].G.rows();
    }
  std::vector<Eigen::Triplet<double>> entries;
  equilibrium_.e = Eigen::VectorXd::Zero(r);
  for (const auto& f : floating_) {
    const BodyParts& p = parts[f.body];
    for (size_t i = 0; i < p.rows.rows.size(); ++i)
      for (Eigen::Index q = 0; q < f.count; ++q)
        if (p.G(q, static_cast<Eigen::Index>(i)) != 0.0)
          entries.emplace_back(f.offset + q, p.rows.rows[i], p.G(q, static_cast<Eigen::Index>(i)));
    equilibrium_.e.segment(f.offset, f.count) = p.e;
  }
  equilibrium_.G = SparseMatrix(r, size());
  equilibrium_.G.setFromTriplets(entries.begin(), entries.end());
}

SparseMatrix InterfaceProblem::assemble() const {
  if (!options_.replicate_blocks) throw std::logic_error("interface problem: the blocks are not held here to assemble");
  std::vector<Eigen::Triplet<double>> entries;
  size_t count = 0;
  for (const auto& b : blocks_) count += b.rows.size() * b.rows.size();
  entries.reserve(count);
  for (const auto& b : blocks_)
    for (size_t j = 0; j < b.rows.size(); ++j)
      for (size_t i = 0; i < b.rows.size(); ++i)
        entries.emplace_back(b.rows[i], b.rows[j], b.F(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)));
  SparseMatrix F(size(), size());
  F.setFromTriplets(entries.begin(), entries.end());  // sums the two bodies' parts of a shared row
  return F;
}

InterfaceProblem::Split& InterfaceProblem::split(parallel::TaskRunner& runner, bool preconditioner) const {
  Split& s = split_[preconditioner ? 1 : 0];
  if (s.runner == &runner && s.concurrency == runner.concurrency()) return s;
  const auto matrix = [&](size_t a) -> const Eigen::MatrixXd& {
    return preconditioner ? blocks_[a].preconditioner : blocks_[a].F;
  };
  s = Split{&runner, runner.concurrency(), {}, {}, {}};
  std::vector<double> cost;  // entries read
  for (size_t a = 0; a < blocks_.size(); ++a) {
    if (matrix(a).rows() == 0 || (!options_.replicate_blocks && !runner.owns(a))) continue;
    s.blocks.push_back(a);
    cost.push_back(0.5 * static_cast<double>(matrix(a).rows() * matrix(a).rows()));
  }
  // Each of the process's threads applies a contiguous run of blocks of about equal cost into a vector of its own
  // (blocks share rows: a contact row belongs to its slave's and its master's block); the vectors are summed. On a
  // wall of thousands of bricks this product is a third of the iterative solver's time, and reading the blocks is
  // what costs (26 MB at 64 x 64 bricks), so 64 blocks (about 0.1 ms of work) per thread is the least worth a
  // thread's wake-up.
  const size_t chunks = std::max<size_t>(1, std::min<size_t>(runner.concurrency(), s.blocks.size() / 64));
  s.first.assign(chunks + 1, s.blocks.size());
  s.first[0] = 0;
  const double total = std::accumulate(cost.begin(), cost.end(), 0.0);
  double sum = 0.0;
  for (size_t i = 0, c = 1; i < s.blocks.size() && c < chunks; ++i) {
    sum += cost[i];
    while (c < chunks && sum >= total * static_cast<double>(c) / static_cast<double>(chunks)) s.first[c++] = i + 1;
  }
  s.parts.assign(chunks, Eigen::VectorXd(size()));
  return s;
}

bool InterfaceProblem::apply_blocks(const Eigen::VectorXd& x, Eigen::VectorXd& y, parallel::TaskRunner& runner,
                                    bool preconditioner) const {
  Split& s = split(runner, preconditioner);
  runner.run(s.parts.size(), [&](size_t c) {
    Eigen::VectorXd& out = s.parts[c];
    out.setZero();
    Eigen::VectorXd local, product;
    for (size_t i = s.first[c]; i < s.first[c + 1]; ++i) {
      const Block& b = blocks_[s.blocks[i]];
      const Eigen::MatrixXd& X = preconditioner ? b.preconditioner : b.F;
      const Eigen::Index k = static_cast<Eigen::Index>(b.rows.size());
      local.resize(k);
      for (Eigen::Index j = 0; j < k; ++j) local[j] = x[b.rows[static_cast<size_t>(j)]];
      product.noalias() = X.selfadjointView<Eigen::Lower>() * local;
      for (Eigen::Index j = 0; j < k; ++j) out[b.rows[static_cast<size_t>(j)]] += product[j];
    }
  });
  y = s.parts[0];
  for (size_t c = 1; c < s.parts.size(); ++c) y += s.parts[c];
  // Replicated blocks: every process has the whole product already (the sum would count it once per process);
  // the sum still runs, on zeros, to carry the cancel requests at the same point on every process.
  if (options_.replicate_blocks && runner.distributed()) {
    double nothing = 0.0;
    return runner.sum(&nothing, 1);
  }
  return runner.sum(y.data(), static_cast<size_t>(y.size()));
}

bool InterfaceProblem::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y, parallel::TaskRunner& runner) const {
  CONTACT_ASSERT_SIZE(x.size(), size(), "the interface vector");
  return apply_blocks(x, y, runner, false);
}

bool InterfaceProblem::apply_preconditioner(const Eigen::VectorXd& x, Eigen::VectorXd& y,
                                            parallel::TaskRunner& runner) const {
  CONTACT_ASSERT_SIZE(x.size(), size(), "the interface vector");
  const bool stop = apply_blocks(inverse_weight_.cwiseProduct(x), y, runner, true);
  y = inverse_weight_.cwiseProduct(y);
  return stop;
}

Eigen::VectorXd InterfaceProblem::free_gap(const RunState& state) const {
  Eigen::VectorXd g = gap0_ + (state.load.value() / factor_) * g_loads_;
  const auto& pairs = system_.pairs();
  for (size_t k = 0; k < pairs.size(); ++k)
    if (const Eigen::VectorXd* origin = state.slip_origin_of(k, pairs[k].n_rows());
        origin && tangential_offset_[k] >= 0)
      g.segment(tangential_offset_[k], pairs[k].n_rows()) -= *origin;
  return g;
}

void InterfaceProblem::refresh_loads(parallel::TaskRunner& runner, const fem::LoadPoint& at) {
  const size_t n_bodies = system_.n_bodies();
  std::vector<Eigen::VectorXd> g(n_bodies), e(n_bodies);
  const parallel::BodyShare share{[&](size_t a, parallel::Packer& out) {
                                    out.put(g[a]);
                                    out.put(e[a]);
                                  },
                                  [&](size_t a, parallel::Unpacker& in) {
                                    g[a] = in.get_vector();
                                    e[a] = in.get_vector();
                                  }};
  std::vector<BodyRows> rows(n_bodies);
  for (size_t a = 0; a < n_bodies; ++a) rows[a] = body_rows(system_, a, offset_, tangential_offset_);
  runner.run_bodies(
      n_bodies,
      [&](size_t a) {
        const auto& body = system_.body(a);
        const Eigen::VectorXd u_free = body.solve(Eigen::VectorXd(), at);
        g[a] = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows[a].rows.size()));
        for (size_t i = 0; i < rows[a].rows.size(); ++i)
          for (const auto& [dof, value] : rows[a].entries[i]) g[a][static_cast<Eigen::Index>(i)] += value * u_free[dof];
        if (body.floating()) e[a] = -body.rigid_modes().transpose() * body.external_load(at);
      },
      share);
  g_loads_.setZero();
  for (size_t a = 0; a < n_bodies; ++a)
    for (size_t i = 0; i < rows[a].rows.size(); ++i) g_loads_[rows[a].rows[i]] += g[a][static_cast<Eigen::Index>(i)];
  for (const auto& f : floating_) equilibrium_.e.segment(f.offset, f.count) = e[f.body];
  factor_ = at.value();
}

Equalities InterfaceProblem::equilibrium(const fem::LoadPoint& at) const {
  return Equalities{equilibrium_.G, (at.value() / factor_) * equilibrium_.e};
}

Pressures InterfaceProblem::split(const Eigen::VectorXd& stacked) const {
  Pressures out(offset_.size() - 1);
  for (size_t k = 0; k + 1 < offset_.size(); ++k) out[k] = stacked.segment(offset_[k], offset_[k + 1] - offset_[k]);
  return out;
}

Pressures InterfaceProblem::split_tangential(const Eigen::VectorXd& stacked) const {
  Pressures out(offset_.size() - 1);
  for (size_t k = 0; k + 1 < offset_.size(); ++k)
    if (tangential_offset_[k] >= 0) out[k] = stacked.segment(tangential_offset_[k], offset_[k + 1] - offset_[k]);
  return out;
}

Eigen::VectorXd InterfaceProblem::stack(const Pressures& per_pair) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(size_);
  for (size_t k = 0; k + 1 < offset_.size(); ++k) out.segment(offset_[k], offset_[k + 1] - offset_[k]) = per_pair[k];
  return out;
}

Displacements InterfaceProblem::displacements(const Eigen::VectorXd& z, const Eigen::VectorXd& alpha,
                                              const fem::LoadPoint& at) const {
  CONTACT_ASSERT_SIZE(z.size(), size(), "the interface multipliers");
  const Pressures q = split_tangential(z);
  Displacements u = system_.solve_bodies(system_.loads_from_pressures(split(z), &q), at);
  if (alpha.size() == equilibrium_.G.rows())
    for (const auto& f : floating_) u[f.body] += system_.body(f.body).rigid_modes() * alpha.segment(f.offset, f.count);
  return u;
}

}  // namespace contact::ddm

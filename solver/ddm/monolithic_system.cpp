#include "monolithic_system.hpp"

#include "friction_rows.hpp"

namespace contact::ddm::monolithic {

Stacked stack(const ContactSystem& system, const RunState& state, bool shift_by_multipliers) {
  Stacked s;
  s.at = state.load;
  const size_t n_bodies = system.n_bodies();
  s.offset.assign(n_bodies + 1, 0);
  for (size_t a = 0; a < n_bodies; ++a) s.offset[a + 1] = s.offset[a] + system.body(a).n_free();
  const Eigen::Index n = s.offset[n_bodies];
  std::vector<Eigen::Triplet<double>> tk;
  s.b.resize(n);
  for (size_t a = 0; a < n_bodies; ++a) {
    const auto& K = system.body(a).reduced_stiffness();
    for (int col = 0; col < K.outerSize(); ++col)
      for (SpMat::InnerIterator it(K, col); it; ++it)
        tk.emplace_back(s.offset[a] + it.row(), s.offset[a] + it.col(), it.value());
    s.b.segment(s.offset[a], system.body(a).n_free()) = system.body(a).reduced_rhs(s.at);
  }
  s.K.resize(n, n);
  s.K.setFromTriplets(tk.begin(), tk.end());

  const auto& pairs = system.pairs();
  s.row_offset.assign(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) s.row_offset[k + 1] = s.row_offset[k] + pairs[k].n_rows();
  Eigen::Index m = s.row_offset.back();
  s.tangential_offset.assign(pairs.size(), -1);
  for (size_t k = 0; k < pairs.size(); ++k)
    if (pairs[k].has_friction()) {
      s.tangential_offset[k] = m;
      m += pairs[k].n_rows();
    }
  s.g0.resize(m);
  s.D.resize(m);
  s.c.resize(m);
  s.row_pair.resize(static_cast<size_t>(m));
  s.row_index.resize(static_cast<size_t>(m));
  std::vector<Eigen::Triplet<double>> tb;
  const Problem& problem = system.problem();
  const double thickness = problem.model.plane == Plane::stress ? problem.model.thickness : 1.0;
  // Rows [first, first + rows) of B from a pair's slave and master operators (B = [-slave, +master]).
  auto add_rows = [&](size_t k, Eigen::Index first, const mortar::SparseRows& Gs, const mortar::SparseRows& Gm) {
    const auto& pair = pairs[k];
    const size_t sb = static_cast<size_t>(pair.slave_body), mb = static_cast<size_t>(pair.master_body);
    const SpMat Bs = SpMat(Gs) * system.body(sb).constraints().T(), Bm = SpMat(Gm) * system.body(mb).constraints().T();
    for (int col = 0; col < Bs.outerSize(); ++col)
      for (SpMat::InnerIterator it(Bs, col); it; ++it)
        tb.emplace_back(first + it.row(), s.offset[sb] + it.col(), -it.value());
    for (int col = 0; col < Bm.outerSize(); ++col)
      for (SpMat::InnerIterator it(Bm, col); it; ++it)
        tb.emplace_back(first + it.row(), s.offset[mb] + it.col(), it.value());
    const Eigen::VectorXd g = Gm * system.body(mb).prescribed(s.at) - Gs * system.body(sb).prescribed(s.at);
    s.g0.segment(first, pair.n_rows()) = g;
    s.D.segment(first, pair.n_rows()) = pair.area;
    // c = E' / h: a contact node's own stiffness scale (h its support length), for the active-set prediction.
    const double E = system.penalties()[k].E_pair;
    for (Eigen::Index r = 0; r < pair.n_rows(); ++r) {
      s.c[first + r] = E / (pair.area[r] / thickness);
      s.row_pair[static_cast<size_t>(first + r)] = static_cast<int>(k);
      s.row_index[static_cast<size_t>(first + r)] = static_cast<int>(r);
    }
  };
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto& pair = pairs[k];
    add_rows(k, s.row_offset[k], pair.Gs, pair.Gm);
    s.g0.segment(s.row_offset[k], pair.n_rows()) += pair.gap0;
    const Eigen::VectorXd* lambda = state.multipliers_of(k, pair.n_rows());
    if (shift_by_multipliers && lambda)  // the augmented Lagrangian's shifted gap
      s.g0.segment(s.row_offset[k], pair.n_rows()) -= pair.theta * pair.area.cwiseProduct(*lambda);
    if (s.tangential_offset[k] < 0) continue;
    add_rows(k, s.tangential_offset[k], pair.Ts, pair.Tm);
    if (const Eigen::VectorXd* origin = state.slip_origin_of(k, pair.n_rows()))
      s.g0.segment(s.tangential_offset[k], pair.n_rows()) -= *origin;
  }
  s.B.resize(m, n);
  s.B.setFromTriplets(tb.begin(), tb.end());
  // Friction rows (friction_rows.hpp), but not where both sides' tangential motion is prescribed (a symmetry line):
  // the row of B is zero there and the node cannot slip (q = 0; its traction goes into the supports).
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows_of_B = s.B;
  s.friction = friction_rows(
      system, [&](size_t k) { return s.row_offset[k]; }, [&](size_t k) { return s.tangential_offset[k]; },
      [&](Eigen::Index t) { return rows_of_B.row(t).norm() > 0; });
  return s;
}

Displacements to_bodies(const ContactSystem& system, const Stacked& s, const Eigen::VectorXd& x) {
  Displacements u(system.n_bodies());
  for (size_t a = 0; a < u.size(); ++a)
    u[a] = system.body(a).expand(x.segment(s.offset[a], system.body(a).n_free()), s.at);
  return u;
}

Pressures split_rows(const ContactSystem& system, const Stacked& s, const Eigen::VectorXd& rows) {
  Pressures z(system.pairs().size());
  for (size_t k = 0; k < z.size(); ++k) z[k] = rows.segment(s.row_offset[k], s.row_offset[k + 1] - s.row_offset[k]);
  return z;
}

Pressures split_tangential(const ContactSystem& system, const Stacked& s, const Eigen::VectorXd& rows) {
  Pressures q(system.pairs().size());
  for (size_t k = 0; k < q.size(); ++k)
    if (s.tangential_offset[k] >= 0) q[k] = rows.segment(s.tangential_offset[k], s.row_offset[k + 1] - s.row_offset[k]);
  return q;
}

}  // namespace contact::ddm::monolithic

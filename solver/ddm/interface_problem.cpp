#include "interface_problem.hpp"

#include <stdexcept>

namespace contact::ddm {

namespace {

// One body's rows of B (sign +1: master, -1: slave), each a list of (full dof, value).
struct BodyRows {
  std::vector<Eigen::Index> rows;  // global row numbers
  std::vector<std::vector<std::pair<int, double>>> entries;
};

BodyRows body_rows(const ContactSystem& system, size_t a, const std::vector<Eigen::Index>& offset) {
  BodyRows out;
  const auto& pairs = system.pairs();
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto& pair = pairs[k];
    auto add = [&](const mortar::SparseRows& G, double sign) {
      for (int r = 0; r < G.outerSize(); ++r) {
        std::vector<std::pair<int, double>> e;
        for (mortar::SparseRows::InnerIterator it(G, r); it; ++it) e.emplace_back(static_cast<int>(it.col()), sign * it.value());
        out.rows.push_back(offset[k] + r);
        out.entries.push_back(std::move(e));
      }
    };
    if (static_cast<size_t>(pair.slave_body) == a) add(pair.Gs, -1.0);
    if (static_cast<size_t>(pair.master_body) == a) add(pair.Gm, 1.0);
  }
  return out;
}

}  // namespace

InterfaceProblem::InterfaceProblem(const ContactSystem& system, TaskRunner& runner) : system_(system) {
  const auto& pairs = system.pairs();
  offset_.assign(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) offset_[k + 1] = offset_[k] + pairs[k].n_rows();
  const Eigen::Index m = offset_.back();
  D_.resize(m);
  gap0_.resize(m);
  g_loads_ = Eigen::VectorXd::Zero(m);
  factor_ = system.load_factor();
  for (size_t k = 0; k < pairs.size(); ++k) {
    D_.segment(offset_[k], pairs[k].n_rows()) = pairs[k].area;
    gap0_.segment(offset_[k], pairs[k].n_rows()) = pairs[k].gap0;
  }
  const size_t n_bodies = system.n_bodies();
  std::vector<BodyRows> rows(n_bodies);
  std::vector<Eigen::MatrixXd> F_body(n_bodies), G_body(n_bodies);
  std::vector<Eigen::VectorXd> g_body(n_bodies), e_body(n_bodies);
  for (size_t a = 0; a < n_bodies; ++a) rows[a] = body_rows(system, a, offset_);
  // Each body's part on its owner; F_a (|rows| squared numbers) is what moves between processes.
  const BodyShare share{[&](size_t a, Packer& out) {
                          out.put(F_body[a]);
                          out.put(G_body[a]);
                          out.put(g_body[a]);
                          out.put(e_body[a]);
                        },
                        [&](size_t a, Unpacker& in) {
                          F_body[a] = in.get_matrix();
                          G_body[a] = in.get_matrix();
                          g_body[a] = in.get_vector();
                          e_body[a] = in.get_vector();
                        }};
  runner.run_bodies(n_bodies, [&](size_t a) {
    const BodyRows& R = rows[a];
    const auto& body = system.body(a);
    if (body.floating()) {
      // G_a = (B_a R_a)^T over this body's rows, e_a = -R_a^T f_a.
      const Eigen::MatrixXd& modes = body.rigid_modes();
      G_body[a] = Eigen::MatrixXd::Zero(modes.cols(), static_cast<Eigen::Index>(R.rows.size()));
      for (size_t i = 0; i < R.rows.size(); ++i)
        for (const auto& [dof, value] : R.entries[i]) G_body[a].col(static_cast<Eigen::Index>(i)) += value * modes.row(dof).transpose();
      e_body[a] = -modes.transpose() * body.external_load();
    }
    // Free response: the body under its own loads only.
    const Eigen::VectorXd u_free = body.solve(Eigen::VectorXd());
    g_body[a] = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(R.rows.size()));
    for (size_t i = 0; i < R.rows.size(); ++i)
      for (const auto& [dof, value] : R.entries[i]) g_body[a][static_cast<Eigen::Index>(i)] += value * u_free[dof];
    if (R.rows.empty()) return;
    // B_Z^T in the trailing order of the factor: reduced rows (B T) restricted to Z.
    const auto& Z = body.interface_unknowns();
    const Eigen::MatrixXd& L = body.interface_factor();
    std::vector<Eigen::Index> position(static_cast<size_t>(body.n_free()), -1);
    for (size_t i = 0; i < Z.size(); ++i) position[static_cast<size_t>(Z[i])] = static_cast<Eigen::Index>(i);
    const Eigen::SparseMatrix<double, Eigen::RowMajor> T = body.constraints().T();
    Eigen::MatrixXd BzT = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(Z.size()), static_cast<Eigen::Index>(R.rows.size()));
    for (size_t i = 0; i < R.rows.size(); ++i)
      for (const auto& [dof, value] : R.entries[i])
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(T, dof); it; ++it) {
          const Eigen::Index p = position[static_cast<size_t>(it.col())];
          if (p < 0) throw std::logic_error("interface problem: a contact dof depends on an unknown outside the interface");
          BzT(p, static_cast<Eigen::Index>(i)) += value * it.value();
        }
    if (Z.empty()) {  // every contact dof of this body is prescribed: it adds no compliance
      F_body[a] = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(R.rows.size()), static_cast<Eigen::Index>(R.rows.size()));
      return;
    }
    const Eigen::MatrixXd W = L.triangularView<Eigen::Lower>().solve(BzT);
    F_body[a] = W.transpose() * W;
  }, share);
  F_ = Eigen::MatrixXd::Zero(m, m);
  Eigen::Index r = 0;
  for (size_t a = 0; a < n_bodies; ++a) {
    const BodyRows& R = rows[a];
    for (size_t i = 0; i < R.rows.size(); ++i) {
      g_loads_[R.rows[i]] += g_body[a][static_cast<Eigen::Index>(i)];
      for (size_t j = 0; j < R.rows.size(); ++j)
        F_(R.rows[i], R.rows[j]) += F_body[a](static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
    if (G_body[a].rows() > 0) {
      floating_.push_back({a, r, G_body[a].rows()});
      r += G_body[a].rows();
    }
  }
  equilibrium_.G = Eigen::MatrixXd::Zero(r, m);
  equilibrium_.e = Eigen::VectorXd::Zero(r);
  for (const auto& f : floating_) {
    const BodyRows& R = rows[f.body];
    for (size_t i = 0; i < R.rows.size(); ++i) equilibrium_.G.block(f.offset, R.rows[i], f.count, 1) = G_body[f.body].col(static_cast<Eigen::Index>(i));
    equilibrium_.e.segment(f.offset, f.count) = e_body[f.body];
  }
}

Eigen::VectorXd InterfaceProblem::free_gap() const {
  return gap0_ + (system_.load_factor() / factor_) * g_loads_;
}

Equalities InterfaceProblem::equilibrium() const {
  return Equalities{equilibrium_.G, (system_.load_factor() / factor_) * equilibrium_.e};
}

Pressures InterfaceProblem::split(const Eigen::VectorXd& stacked) const {
  Pressures out(offset_.size() - 1);
  for (size_t k = 0; k + 1 < offset_.size(); ++k) out[k] = stacked.segment(offset_[k], offset_[k + 1] - offset_[k]);
  return out;
}

Eigen::VectorXd InterfaceProblem::stack(const Pressures& per_pair) const {
  Eigen::VectorXd out(offset_.back());
  for (size_t k = 0; k + 1 < offset_.size(); ++k) out.segment(offset_[k], offset_[k + 1] - offset_[k]) = per_pair[k];
  return out;
}

Displacements InterfaceProblem::displacements(const Eigen::VectorXd& z, const Eigen::VectorXd& alpha,
                                              TaskRunner& runner) const {
  Displacements u = system_.solve_bodies(system_.loads_from_pressures(split(z)), runner);
  if (alpha.size() == equilibrium_.G.rows())
    for (const auto& f : floating_) u[f.body] += system_.body(f.body).rigid_modes() * alpha.segment(f.offset, f.count);
  return u;
}

}  // namespace contact::ddm

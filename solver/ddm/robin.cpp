// The Robin-type variant (docs/algorithm.md, "Robin variant"; reconstructed from the authors' later papers):
//   a_a(u~_a, v) + int psi u~_an v_n = l_a(v) + int psi u_an^k v_n + (1/theta) int (d - u_1n^k - u_2n^k)^- v_n,
// then the same relaxation as the Neumann scheme. psi = 0 is the paper's scheme. Discretely the Robin term is
// Psi_a = sum over the pairs of body a of G_a^T diag(psi_r / D_r) G_a (G_a = G_s or G_m: the penalty's own
// stiffness when psi = 1/theta), added to the stiffness.
// With a constant psi each body is factorised once; with psi = 1/theta on the current active set ("active_set")
// a body is refactorised only when the active set of one of its pairs changes.
#include "fixed_point.hpp"

#include <Eigen/CholmodSupport>

#include <memory>
#include <sstream>

namespace contact::ddm {

namespace {

using Factor = Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower>;  // refactorised often

class RobinMap final : public BodyMap {
 public:
  RobinMap(const ContactSystem& system, const RunState& state, const SolverSettings& settings,
           parallel::TaskRunner& runner)
      : system_(system),
        state_(state),
        settings_(settings),
        runner_(runner),
        psi_(system.n_bodies()),
        factor_(system.n_bodies()),
        remote_(system.n_bodies(), 0),
        active_(system.pairs().size()) {}

  std::string error;

  Displacements apply(const Displacements& u) override {
    update_weights(u);
    const Displacements contact = system_.contact_loads(u, state_);
    Displacements out(u.size());
    runner_.run_bodies(
        u.size(),
        [&](size_t a) {
          const auto& body = system_.body(a);
          const auto& c = body.constraints();
          const Eigen::VectorXd load = psi_[a] * (u[a] - body.prescribed(state_.load)) + contact[a];
          out[a] = body.expand(solve(a, body.reduced_rhs(state_.load) + c.T().transpose() * load), state_.load);
        },
        share_vectors(out));
    return out;
  }

  Displacements linear_response(const Displacements& du) override {
    update_weights(du, /*all_active=*/true);
    const Displacements loads = system_.loads_from_pressures(linear_pressures(system_, du));
    Displacements out(du.size());
    runner_.run_bodies(
        du.size(),
        [&](size_t a) {
          const auto& c = system_.body(a).constraints();
          out[a] = c.T() * solve(a, c.T().transpose() * (psi_[a] * du[a] + loads[a]));
        },
        share_vectors(out));
    return out;
  }

  int factorizations() const override { return factorizations_; }

 private:
  Eigen::VectorXd solve(size_t a, const Eigen::VectorXd& rhs) const {
    if (rhs.size() == 0) return rhs;
    return factor_[a]->solve(rhs);
  }

  // Psi per body for the active set of u (or every point, for the gamma estimate with a stationary psi);
  // refactorises the bodies whose weights changed.
  void update_weights(const Displacements& u, bool all_active = false) {
    const auto& pairs = system_.pairs();
    std::vector<char> changed(system_.n_bodies(), 0);
    for (size_t k = 0; k < pairs.size(); ++k) {
      const auto& pair = pairs[k];
      std::vector<char> now(static_cast<size_t>(pair.n_rows()), 1);
      if (settings_.robin.active_set && !all_active) {
        const Eigen::VectorXd p = pair.penalty_pressure(
            pair.nodal_gap(u[static_cast<size_t>(pair.slave_body)], u[static_cast<size_t>(pair.master_body)]),
            state_.multipliers_of(k, pair.n_rows()));
        for (Eigen::Index q = 0; q < p.size(); ++q) now[static_cast<size_t>(q)] = p[q] > 0 ? 1 : 0;
      }
      const size_t sb = static_cast<size_t>(pair.slave_body);
      if (now != active_[k] || (!factor_[sb] && !remote_[sb])) {
        active_[k] = std::move(now);
        changed[static_cast<size_t>(pair.slave_body)] = changed[static_cast<size_t>(pair.master_body)] = 1;
      }
    }
    for (size_t a = 0; a < system_.n_bodies(); ++a)
      if (!factor_[a] && !remote_[a]) changed[a] = 1;
    std::vector<size_t> todo;
    for (size_t a = 0; a < changed.size(); ++a)
      if (changed[a]) todo.push_back(a);
    if (todo.empty()) return;
    // Each owner refactorises its bodies; the others only note that the weights changed (a failure throws on the
    // owner, and run_bodies throws it everywhere).
    runner_.run_bodies(
        todo,
        [&](size_t a) {
          refactorize(a);
          if (factor_[a]->info() != Eigen::Success)
            throw std::runtime_error("robin: the stiffness of body '" + system_.problem().bodies[a].name +
                                     "' plus the Robin term could not be factorised");
        },
        parallel::BodyShare{[](size_t, parallel::Packer&) {},
                            [this](size_t a, parallel::Unpacker&) {
                              psi_[a].resize(0, 0);
                              remote_[a] = 1;
                            }});
    factorizations_ += static_cast<int>(todo.size());
  }

  void refactorize(size_t a) {
    const auto& body = system_.body(a);
    const int n = body.n_dofs();
    Eigen::SparseMatrix<double> Psi(n, n);
    for (size_t k = 0; k < system_.pairs().size(); ++k) {
      const auto& pair = system_.pairs()[k];
      const bool slave = static_cast<size_t>(pair.slave_body) == a, master = static_cast<size_t>(pair.master_body) == a;
      if (!slave && !master) continue;
      Eigen::VectorXd w = Eigen::VectorXd::Zero(pair.n_rows());
      for (Eigen::Index q = 0; q < w.size(); ++q)
        if (active_[k][static_cast<size_t>(q)])
          w[q] = (settings_.robin.active_set ? 1.0 / pair.theta : settings_.robin.psi) / pair.area[q];
      const auto& G = slave ? pair.Gs : pair.Gm;
      Psi += Eigen::SparseMatrix<double>(G.transpose() * w.asDiagonal() * G);
    }
    psi_[a] = Psi;
    const auto& T = body.constraints().T();
    const Eigen::SparseMatrix<double> A =
        body.reduced_stiffness() + Eigen::SparseMatrix<double>(T.transpose() * Psi * T);
    auto f = std::make_unique<Factor>();
    f->cholmod().print = 0;  // a failed factorisation is reported by info(), not by CHOLMOD's text on stdout
    f->compute(A);
    factor_[a] = std::move(f);
  }

  const ContactSystem& system_;
  const RunState& state_;
  const SolverSettings& settings_;
  parallel::TaskRunner& runner_;
  std::vector<Eigen::SparseMatrix<double>> psi_;
  std::vector<std::unique_ptr<Factor>> factor_;
  std::vector<char> remote_;  // set up by another process (its factor_ stays empty here)
  std::vector<std::vector<char>> active_;
  int factorizations_ = 0;
};

}  // namespace

void run_robin(const ContactSystem& system, RunFrame& frame) {
  int initial_solves = 0;
  Displacements u0 = initial_iterate(system, frame, initial_solves);
  RobinMap map(system, frame.state(), frame.settings(), frame.runner());
  run_fixed_point(system, frame, map, std::move(u0));
  MethodOutcome& out = frame.outcome();
  out.subdomain_solves += initial_solves;
  std::ostringstream os;
  os << "; " << map.factorizations() << " Robin factorisations";
  out.message += os.str();
}

}  // namespace contact::ddm

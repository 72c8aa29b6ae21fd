#include "contact_system.hpp"

#include "../common/scoped_timer.hpp"
#include "../fem/blas_threads.hpp"

#include <algorithm>

namespace contact::ddm {

double relative_change(const Eigen::VectorXd& now, const Eigen::VectorXd& before) {
  const double scale = std::max(now.norm(), before.norm());
  return scale > 0 ? (now - before).norm() / scale : 0.0;
}

namespace {

void append_error(std::string& errors, const std::string& e) {
  if (!e.empty()) errors += (errors.empty() ? "" : "; ") + e;
}

// The errors of the bodies that failed, the first few in full and the others by name (a wall of a hundred
// bricks must not give a hundred copies of one message).
std::string body_errors(const std::vector<std::pair<std::string, std::string>>& failed) {
  constexpr size_t kInFull = 3;
  std::string out;
  for (size_t k = 0; k < failed.size() && k < kInFull; ++k) append_error(out, failed[k].second);
  if (failed.size() > kInFull) {
    constexpr size_t kNamed = 20;
    std::string names;
    for (size_t k = kInFull; k < failed.size() && k < kInFull + kNamed; ++k)
      names += (k == kInFull ? "'" : ", '") + failed[k].first + "'";
    if (failed.size() > kInFull + kNamed) names += ", ...";
    out += "; " + std::to_string(failed.size() - kInFull) + " more bodies failed too: " + names;
  }
  return out;
}

}  // namespace

ContactSystem::ContactSystem(const Problem& problem, parallel::TaskRunner& runner, Factorization factorization,
                             std::function<bool()> stop)
    : problem_(problem), factorization_(factorization), runner_(runner) {
  ScopedTimer timer(setup_seconds_);
  fem::limit_blas_threads();
  discretize_pairs();
  bodies_.resize(problem.bodies.size());
  std::vector<size_t> all(bodies_.size());
  for (size_t a = 0; a < all.size(); ++a) all[a] = a;
  build_bodies(all, stop);
}

std::unique_ptr<fem::BodySolver> ContactSystem::make_body(size_t a, bool local,
                                                          const std::function<bool()>& stop) const {
  auto b = std::make_unique<fem::BodySolver>(problem_.bodies[a], problem_.model, factorization_ != Factorization::none,
                                             interface_dofs(a), may_float(a), local, stop);
  return b;
}

void ContactSystem::build_bodies(const std::vector<size_t>& todo, const std::function<bool()>& stop) {
  runner_.run_bodies(
      todo,
      [&](size_t a) {
        bodies_[a].reset();  // free the old factorisation first
        bodies_[a] = make_body(a, true, stop);
      },
      body_outcome_share());
  std::vector<std::pair<std::string, std::string>> failed;
  for (size_t a : todo) {
    if (bodies_[a]->was_cancelled())
      cancelled_ = true;  // not an error: the caller sees its token
    else if (!bodies_[a]->ok())
      failed.emplace_back(problem_.bodies[a].name, bodies_[a]->error());
    factorization_seconds_ += bodies_[a]->factorization_seconds();
  }
  append_error(error_, body_errors(failed));
}

parallel::BodyShare ContactSystem::body_outcome_share() {
  // The owner's outcome (an error such as a singular stiffness, the factorisation time); the other processes set
  // up the body's constraints and rigid modes themselves (the same on every process).
  return {[this](size_t a, parallel::Packer& out) {
            out.put(bodies_[a]->error());
            out.put(bodies_[a]->factorization_seconds());
          },
          [this](size_t a, parallel::Unpacker& in) {
            bodies_[a] = make_body(a, false);
            const std::string error = in.get_string();
            bodies_[a]->adopt_outcome(error, in.get_double());
          }};
}

void ContactSystem::discretize_pairs() {
  // Each pair from the problem alone (its two bodies' meshes, read only), so on the process's threads: a wall of
  // 12,192 pairs took a second on one. Every process discretizes every pair.
  const size_t n = problem_.contacts.size();
  pairs_.assign(n, mortar::PairDiscretization{});
  penalties_.assign(n, mortar::PenaltyChoice{});
  const mortar::ContactIndex index(problem_);
  runner_.run(n, [&](size_t k) {
    penalties_[k] = mortar::choose_penalty(problem_, static_cast<int>(k));
    pairs_[k] = mortar::discretize_pair(problem_, static_cast<int>(k), penalties_[k].theta, &index);
  });
  for (size_t k = 0; k < n; ++k) {
    if (!(penalties_[k].theta > 0))
      append_error(error_, "contact '" + pairs_[k].name + "': the penalty theta is not positive");
    // The job reader refuses such a pair (job/read_contacts.cpp, check_pairs_face); a problem built in code, or a
    // job past the reader's budget for that check, is told here, before it is solved as a pair that carries nothing.
    if (!(pairs_[k].covered_length > 0))
      append_error(error_, "contact '" + pairs_[k].name +
                               "': its edges never face each other (no part of the slave edge lies opposite the "
                               "master edge along its normal, with their outward normals opposed), so it could "
                               "never carry a force; name the edges that meet");
  }
  check_some_row();
  // Each body's pairs: what a body asks of the pairs (its interface unknowns, its rows of G) without going over
  // every pair of the job (a wall of 4,129 bricks has 12,192).
  pairs_of_body_.assign(problem_.bodies.size(), {});
  for (size_t k = 0; k < n; ++k) {
    const auto s = static_cast<size_t>(pairs_[k].slave_body), m = static_cast<size_t>(pairs_[k].master_body);
    pairs_of_body_[s].push_back(k);
    if (m != s) pairs_of_body_[m].push_back(k);
  }
}

// Pairs that face each other but of which not one slave node carries a multiplier (each is a crosspoint: its
// displacement along the contact normal prescribed, as on a clamped slave edge; or barely covered): the interface
// problem is empty, and the solve would report a contact that carries nothing as converged. One such pair among
// others is a corner of a model (a short head joint between two bed joints); all of them is a modelling mistake.
void ContactSystem::check_some_row() {
  if (pairs_.empty() || !error_.empty()) return;
  for (const auto& pair : pairs_)
    if (pair.n_rows() > 0) return;
  std::string detail;
  for (size_t k = 0; k < pairs_.size() && k < 3; ++k) {
    const auto& status = pairs_[k].status;
    const auto count = [&](mortar::NodeStatus s) { return std::count(status.begin(), status.end(), s); };
    detail += (k ? "; '" : "'") + pairs_[k].name + "': " + std::to_string(status.size()) + " slave nodes, " +
              std::to_string(count(mortar::NodeStatus::crosspoint)) +
              " with their displacement along the contact normal prescribed, " +
              std::to_string(count(mortar::NodeStatus::barely_covered) + count(mortar::NodeStatus::uncovered)) +
              " not (or hardly) opposite the master";
  }
  if (pairs_.size() > 3) detail += "; and " + std::to_string(pairs_.size() - 3) + " more";
  append_error(error_, "no contact pair has a slave node that can carry a force (" + detail +
                           "): a slave edge whose displacement is prescribed cannot press on anything; make the "
                           "supported edge the master (swap slave and master) or remove the support from the "
                           "contact edge");
}

bool ContactSystem::may_float(size_t a) const {
  if (factorization_ == Factorization::plain) return false;  // the fixed-point schemes solve every body alone
  return !pairs_of_body_[a].empty();
}

std::vector<int> ContactSystem::interface_dofs(size_t a) const {
  std::vector<int> dofs;
  if (factorization_ != Factorization::interface) return dofs;
  auto collect = [&](const mortar::SparseRows& G) {
    for (int r = 0; r < G.outerSize(); ++r)
      for (mortar::SparseRows::InnerIterator it(G, r); it; ++it) dofs.push_back(static_cast<int>(it.col()));
  };
  for (const size_t k : pairs_of_body_[a]) {
    const auto& pair = pairs_[k];
    if (static_cast<size_t>(pair.slave_body) == a) collect(pair.Gs);
    if (static_cast<size_t>(pair.master_body) == a) collect(pair.Gm);
    if (pair.has_friction() && static_cast<size_t>(pair.slave_body) == a) collect(pair.Ts);
    if (pair.has_friction() && static_cast<size_t>(pair.master_body) == a) collect(pair.Tm);
  }
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  return dofs;
}

void ContactSystem::rebuild(const std::vector<char>& changed, RunState& state, const std::function<bool()>& stop) {
  discretize_pairs();
  state.drop_pair_values();
  std::vector<size_t> todo;
  for (size_t a = 0; a < bodies_.size(); ++a)
    if (changed[a] || (factorization_ == Factorization::interface && interface_dofs(a) != bodies_[a]->interface_dofs()))
      todo.push_back(a);
  build_bodies(todo, stop);
}

Pressures ContactSystem::penalty_pressures(const Displacements& u, const RunState& state) const {
  Pressures z(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    z[k] = pair.penalty_pressure(
        pair.nodal_gap(u[static_cast<size_t>(pair.slave_body)], u[static_cast<size_t>(pair.master_body)]),
        state.multipliers_of(k, pair.n_rows()));
  }
  return z;
}

Displacements ContactSystem::loads_from_pressures(const Pressures& z, const Pressures* q) const {
  Displacements f(bodies_.size());
  for (size_t a = 0; a < bodies_.size(); ++a) f[a] = Eigen::VectorXd::Zero(bodies_[a]->n_dofs());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& p = pairs_[k];
    p.add_forces(z[k], f[static_cast<size_t>(p.slave_body)], f[static_cast<size_t>(p.master_body)]);
    if (q && k < q->size())
      p.add_tangential_forces((*q)[k], f[static_cast<size_t>(p.slave_body)], f[static_cast<size_t>(p.master_body)]);
  }
  return f;
}

bool ContactSystem::has_histories() const {
  for (const auto& b : bodies_)
    if (b->has_histories()) return true;
  for (const auto& body : problem_.bodies) {  // bodies of other processes are not assembled here
    if (!body.body_force_history.empty() || body.body_force_live) return true;
    for (const auto& bc : body.boundary)
      if (!bc.history.empty() || bc.live) return true;
  }
  return false;
}

Pressures ContactSystem::tangential_jumps(const Displacements& u) const {
  Pressures w(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k)
    if (pairs_[k].has_friction())
      w[k] = pairs_[k].weighted_jump(u[static_cast<size_t>(pairs_[k].slave_body)],
                                     u[static_cast<size_t>(pairs_[k].master_body)]);
  return w;
}

Displacements ContactSystem::contact_loads(const Displacements& u, const RunState& state, Pressures* pressures) const {
  Pressures z = penalty_pressures(u, state);
  Displacements f = loads_from_pressures(z);
  if (pressures) *pressures = std::move(z);
  return f;
}

Eigen::VectorXd ContactSystem::zone_normals(size_t a, const Eigen::VectorXd& u_a) const {
  std::vector<Eigen::VectorXd> parts;
  for (const auto& pair : pairs_) {
    // u_1n = nu . u_1 at the slave node, u_2n = -(mortar projection of u_2) . nu (the paper's normals).
    if (static_cast<size_t>(pair.slave_body) == a) parts.push_back((pair.Gs * u_a).cwiseQuotient(pair.area));
    if (static_cast<size_t>(pair.master_body) == a) parts.push_back(-(pair.Gm * u_a).cwiseQuotient(pair.area));
  }
  Eigen::Index n = 0;
  for (const auto& v : parts) n += v.size();
  Eigen::VectorXd out(n);
  Eigen::Index at = 0;
  for (const auto& v : parts) {
    out.segment(at, v.size()) = v;
    at += v.size();
  }
  return out;
}

Displacements ContactSystem::solve_bodies(const Displacements& loads, const fem::LoadPoint& at) const {
  Displacements u(bodies_.size());
  runner_.run_bodies(
      bodies_.size(), [&](size_t a) { u[a] = bodies_[a]->solve(loads[a], at); }, share_vectors(u));
  return u;
}

parallel::BodyShare share_vectors(std::vector<Eigen::VectorXd>& v) {
  return {[&v](size_t a, parallel::Packer& out) { out.put(v[a]); },
          [&v](size_t a, parallel::Unpacker& in) { v[a] = in.get_vector(); }};
}

Displacements ContactSystem::elastic_layer_guess(const fem::LoadPoint& at) const {
  // Each body's response to its own loads with free contact zones; where the rigid approach (the overlap of
  // these free responses) exceeds the gap, each layer of height h_a under uniaxial strain (modulus M_a)
  // carries the pressure (approach - d) / (h_1/M_1 + h_2/M_2); the initial displacements are each body's
  // response to that pressure.
  const Displacements free_u = solve_bodies(Displacements(bodies_.size()), at);
  auto M = [&](int body) {
    const Material& m = problem_.bodies[static_cast<size_t>(body)].material;
    if (problem_.model.plane == Plane::strain) return m.E * (1 - m.nu) / ((1 + m.nu) * (1 - 2 * m.nu));
    return m.E / (1 - m.nu * m.nu);
  };
  Pressures z(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    const double compliance =
        penalties_[k].slave_height / M(pair.slave_body) + penalties_[k].master_height / M(pair.master_body);
    const Eigen::VectorXd g =
        pair.nodal_gap(free_u[static_cast<size_t>(pair.slave_body)], free_u[static_cast<size_t>(pair.master_body)]);
    z[k] = (-g).cwiseMax(0.0) / compliance;
  }
  return solve_bodies(loads_from_pressures(z), at);
}

Pressures ContactSystem::nodal_gaps(const Displacements& u) const {
  Pressures g(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k)
    g[k] = pairs_[k].nodal_gap(u[static_cast<size_t>(pairs_[k].slave_body)],
                               u[static_cast<size_t>(pairs_[k].master_body)]);
  return g;
}

}  // namespace contact::ddm
